// sc_sobel: Sobel gradient of a 3x3 window of a Q8.8 scale image, = sobel::sobel
// (combinational; the octave holds the gradient register, SOBEL_LATENCY = 1).
//
//   Sx = (p02 + 2 p12 + p22) - (p00 + 2 p10 + p20)
//   Sy = (p20 + 2 p21 + p22) - (p00 + 2 p01 + p02)      (x to the right, y down)
//
// Widths: p u16; each weighted sum <= 4 * 65535 = 262140 < 2^18 (18-bit unsigned); the
// differences are within +-262140, 19-bit signed. Element (row,col) of `p` is at bits
// [(row*3+col)*16 +: 16].
`default_nettype none

module sc_sobel (
    // The centre p11 has no weight in either kernel.
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire [9*16-1:0]    p,
    /* verilator lint_on UNUSEDSIGNAL */
    output wire signed [18:0] sx,
    output wire signed [18:0] sy
);
    wire [17:0] p00 = {2'b00, p[0*16 +: 16]};
    wire [17:0] p01 = {2'b00, p[1*16 +: 16]};
    wire [17:0] p02 = {2'b00, p[2*16 +: 16]};
    wire [17:0] p10 = {2'b00, p[3*16 +: 16]};
    wire [17:0] p12 = {2'b00, p[5*16 +: 16]};
    wire [17:0] p20 = {2'b00, p[6*16 +: 16]};
    wire [17:0] p21 = {2'b00, p[7*16 +: 16]};
    wire [17:0] p22 = {2'b00, p[8*16 +: 16]};

    wire [17:0] right  = p02 + (p12 << 1) + p22;
    wire [17:0] left   = p00 + (p10 << 1) + p20;
    wire [17:0] bottom = p20 + (p21 << 1) + p22;
    wire [17:0] top    = p00 + (p01 << 1) + p02;

    assign sx = $signed({1'b0, right})  - $signed({1'b0, left});
    assign sy = $signed({1'b0, bottom}) - $signed({1'b0, top});
endmodule

`default_nettype wire
