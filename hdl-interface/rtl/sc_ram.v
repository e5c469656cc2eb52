// sc_ram: the fabric's one memory primitive, a simple dual-port RAM: a write port and a read
// port whose data `q` follows its address by a clock (loaded on clocks with `re`). It is the
// form every target maps to block RAM (a 7 Series' RAMB18/36, an iCE40's SB_RAM40_4K), so a
// module that keeps its memories in sc_ram keeps them out of logic.
//
// A read of the address written on the same clock gives the old word, or with WRITE_FIRST = 1
// the word written (the block RAMs' write-first mode, and what a FIFO whose head is the entry
// being pushed needs).
//
// Widths: DW-bit words, DEPTH of them, AW-bit addresses (AW = clog2(DEPTH) unless given).
`default_nettype none

module sc_ram #(
    parameter DW          = 8,
    parameter DEPTH       = 16,
    parameter WRITE_FIRST = 0,
    parameter AW          = $clog2(DEPTH)
) (
    input  wire          clk,
    input  wire          we,
    input  wire [AW-1:0] wa,
    input  wire [DW-1:0] wd,
    input  wire          re,
    input  wire [AW-1:0] ra,
    output reg  [DW-1:0] q
);

    reg [DW-1:0] mem [0:DEPTH-1];  // power-up content: no user's output depends on it

    always @(posedge clk) begin
        if (we) mem[wa] <= wd;
        if (re) q <= (WRITE_FIRST != 0 && we && wa == ra) ? wd : mem[ra];
    end

endmodule

`default_nettype wire
