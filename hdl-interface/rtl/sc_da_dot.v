// sc_da_dot: 5-tap dot product by LUT distributed arithmetic (mirrors convolver.rs `da_dot`,
// table of taps.rs `da_lut`). Combinational, no multiplier on the pixel path: for every bit
// plane b = 0..15 the five sample bits form a 5-bit address into a 32-entry ROM of partial
// products (entry m = sum of the taps j whose bit j of m is set), and the 16 partial products
// are added with a shift of b. The sum is rounded back to Q8.8: (acc + 512) >> 10.
//
// Widths: samples u16 Q8.8; taps 10 bits, sum 1024 (TAPS[j*10 +: 10] = tap j, j = 0..4);
// ROM entry <= 1024 (11 bits); acc <= 65535 * 1024 < 2^26 (26 bits, also after + 512);
// result <= max sample (unity DC gain), 16 bits.
`default_nettype none

module sc_da_dot #(
    parameter [49:0] TAPS = {10'd35, 10'd244, 10'd466, 10'd244, 10'd35}
) (
    input  wire [79:0] s,  // sample j (u16 Q8.8) at [j*16 +: 16]
    output wire [15:0] y   // rounded dot product, u16 Q8.8
);

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

    wire [10:0]     rom [0:31];
    wire [16*11-1:0] pp;  // partial product of bit plane b at [b*11 +: 11]

    genvar m, b;
    generate
        for (m = 0; m < 32; m = m + 1) begin : g_rom
            assign rom[m] = lut(m);
        end
        for (b = 0; b < 16; b = b + 1) begin : g_plane
            assign pp[b*11 +: 11] = rom[{s[4*16 + b], s[3*16 + b], s[2*16 + b], s[1*16 + b], s[b]}];
        end
    endgenerate

    reg [25:0] acc;  // <= 65535 * 1024 + 512 < 2^26
    integer k;
    always @* begin
        acc = 26'd512;
        for (k = 0; k < 16; k = k + 1)
            acc = acc + ({15'd0, pp[k*11 +: 11]} << k);
    end

    assign y = acc[25:10];

endmodule

`default_nettype wire
