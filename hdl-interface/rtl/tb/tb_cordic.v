// Vector testbench of sc_cordic against a clock-by-clock trace of cordic::CordicPipeline
// (run.sh). One record per clock, most significant field first:
//   {empty(4), ori(8), mag(8), out_y(16), out_x(16), out_valid(4),
//    sy(20), sx(20), in_y(16), in_x(16), {start, en, in_valid}(4)}
// The expected outputs are the output register before the edge; out_valid and empty are
// checked on every clock from the second (the first record is a start: before it the
// registers are unknown), the data when out_valid. Parameter N: records; file from +cordic=.
`default_nettype none

module tb_cordic;
    parameter N = 1;

    reg [131:0] vc [0:N-1];

    reg         clk = 1'b0, en = 1'b0, start = 1'b0, in_valid = 1'b0;
    reg  [15:0] in_x = 16'd0, in_y = 16'd0;
    reg  signed [18:0] in_sx = 19'd0, in_sy = 19'd0;
    wire        out_valid, empty;
    wire [15:0] out_x, out_y;
    wire [7:0]  out_mag;
    wire [5:0]  out_ori;

    sc_cordic dut (.clk(clk), .en(en), .start(start), .in_valid(in_valid), .in_x(in_x),
                   .in_y(in_y), .in_sx(in_sx), .in_sy(in_sy), .out_valid(out_valid),
                   .out_x(out_x), .out_y(out_y), .out_mag(out_mag), .out_ori(out_ori),
                   .empty(empty));

    reg [1023:0] fname;
    reg [131:0]  r;
    integer i, bad, outs;

    initial begin
        if (!$value$plusargs("cordic=%s", fname)) begin
            $display("FAIL: +cordic=<file> missing");
            $finish;
        end
        $readmemh(fname, vc);
        bad = 0;
        outs = 0;
        for (i = 0; i < N; i = i + 1) begin
            r = vc[i];
            {start, en, in_valid} = r[2:0];
            {in_sy, in_sx, in_y, in_x} = {r[74:56], r[54:36], r[35:4]};
            #1;
            if (i > 0 && (out_valid !== r[76] || empty !== r[128]
                          || (out_valid && {out_ori, out_mag, out_y, out_x} !== r[125:80]))) begin
                bad = bad + 1;
                if (bad <= 5)
                    $display("cordic clock %0d: got v=%b e=%b %h %h %h %h want v=%b e=%b %h", i,
                             out_valid, empty, out_x, out_y, out_mag, out_ori, r[76], r[128],
                             r[127:80]);
            end
            if (en && out_valid) outs = outs + 1;
            #4 clk = 1'b1;
            #5 clk = 1'b0;
        end
        $display("sc_cordic: %0d clocks, %0d outputs, %0d mismatches", N, outs, bad);
        if (bad == 0) $display("PASS");
        else $display("FAIL: %0d mismatches", bad);
        $finish;
    end
endmodule

`default_nettype wire
