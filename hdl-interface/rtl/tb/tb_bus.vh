// One-clock cycles on the simple synchronous register bus of sc_regs (bus_we / bus_re strobes,
// registered bus_rdata), driven between edges. Included inside a testbench module that has
// `clk`, `bus_addr`, `bus_wdata`, `bus_we`, `bus_re` and `bus_rdata`; shared by sc_regs_tb and
// sc_fabric_tb.

task write(input [7:0] addr, input [31:0] data);
    begin
        @(negedge clk);
        bus_addr = addr; bus_wdata = data; bus_we = 1'b1;
        @(negedge clk);
        bus_we = 1'b0; bus_wdata = 32'h0;
    end
endtask

task read(input [7:0] addr, output [31:0] data);
    begin
        @(negedge clk);
        bus_addr = addr; bus_re = 1'b1;
        @(negedge clk);
        bus_re = 1'b0;
        data = bus_rdata;
    end
endtask
