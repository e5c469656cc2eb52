// sc_da_dot: 5-tap dot product by LUT distributed arithmetic (mirrors convolver.rs `da_sum`,
// `da_row`, `da_column`; table of taps.rs `da_lut`). Combinational, no multiplier on the pixel
// path: for every bit plane b = 0..IW-1 the five sample bits form a 5-bit address into a
// 32-entry ROM of partial products (entry m = sum of the taps j whose bit j of m is set), and
// the IW partial products are added with a shift of b. The sum is then rounded half up by SH
// bits: y = (acc + 2^(SH-1)) >> SH, or y = acc exactly when SH = 0.
//
// One module for both stages of the separable Gaussian, so that the pair equals the direct
// 2-D convolution with the outer product of the quantized taps exactly (one rounding, after
// both passes):
//   row stage    IW = 16 (u16 Q8.8 samples), SH = 0:  y = sum tap*s, 26 bits (Q8.18);
//   column stage IW = 26 (row-stage sums),   SH = 20: y = (sum tap*r + 2^19) >> 20, u16 Q8.8.
//
// Widths: taps 10 bits, sum 1024 (TAPS[j*10 +: 10] = tap j, j = 0..4); ROM entry <= 1024
// (11 bits); acc IW + 10 bits: the exact sum is <= 1024 * (2^IW - 1) < 2^(IW+10). With SH > 0
// the rounding constant must fit too: the column stage's samples are row-stage sums
// <= 1024 * 65535, so acc <= 2^20 * 65535 + 2^19 < 2^36, and y <= 65535 (unity DC gain).
// Output IW + 10 - SH bits.
`default_nettype none

module sc_da_dot #(
    parameter [49:0] TAPS = {10'd35, 10'd244, 10'd466, 10'd244, 10'd35},
    parameter        IW   = 16,  // sample width (bit planes)
    parameter        SH   = 0    // rounding shift: 0 = exact sum
) (
    input  wire [5*IW-1:0]      s,  // sample j at [j*IW +: IW]
    output wire [IW+9-SH:0]     y   // (sum tap*s + 2^(SH-1)) >> SH, or the exact sum (SH = 0)
);

    localparam AW = IW + 10;  // accumulator bits
    localparam [AW-1:0] ONE = 1;
    localparam [AW-1:0] RND = (SH > 0) ? (ONE << ((SH > 0) ? SH - 1 : 0)) : {AW{1'b0}};

    // Partial-product table entry m.
    function [10:0] lut;
        input integer m;
        integer j;
        begin
            lut = 11'd0;
            for (j = 0; j < 5; j = j + 1)
                if (m[j]) lut = lut + {1'b0, TAPS[j*10 +: 10]};
        end
    endfunction

    wire [10:0]      rom [0:31];
    wire [IW*11-1:0] pp;  // partial product of bit plane b at [b*11 +: 11]

    genvar m, b;
    generate
        for (m = 0; m < 32; m = m + 1) begin : g_rom
            assign rom[m] = lut(m);
        end
        for (b = 0; b < IW; b = b + 1) begin : g_plane
            assign pp[b*11 +: 11] = rom[{s[4*IW + b], s[3*IW + b], s[2*IW + b], s[1*IW + b], s[b]}];
        end
    endgenerate

    reg [AW-1:0] acc;  // see the widths above
    integer k;
    always @* begin
        acc = RND;
        for (k = 0; k < IW; k = k + 1)
            acc = acc + ({{(IW-1){1'b0}}, pp[k*11 +: 11]} << k);
    end

    assign y = acc[AW-1:SH];

endmodule

`default_nettype wire
