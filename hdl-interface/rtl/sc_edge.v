// sc_edge: edge-response rejection on the middle DoG plane, = edge::passes_edge_test
// (combinational; the octave holds the edge register, EDGE_LATENCY = 1).
//
// Keep the point iff r == 0, or Det > 0 and Tr^2 * r < (r+1)^2 * Det, with the Hessian
// scaled by 4 so that everything is an exact integer:
//   dxx4 = 4 (d12 + d10 - 2 d11), dyy4 = 4 (d21 + d01 - 2 d11), dxy4 = d22 - d20 - d02 + d00
//   tr = dxx4 + dyy4, det = dxx4 dyy4 - dxy4^2.
//
// Widths (d i16 in [-32768, 32767]):
//   d12 + d10 - 2 d11 in [-131070, 131070]          18-bit signed; dxx4, dyy4 |.| <= 524280,
//                                                    20-bit signed (2^19 = 524288)
//   dxy4 in [-131070, 131070]                        18-bit signed
//   tr   |.| <= 1048560 < 2^20                       21-bit signed
//   det  <= 524280^2 = 274869518400 < 2^38; dxx4 and dyy4 share d11, so
//        dxx4 dyy4 >= -16 * 65535^2 and det >= -(16 * 65535^2 + 131070^2) > -2^37
//                                                    39-bit signed
//   tr^2 <= 1048560^2 < 2^40                         40-bit unsigned (|tr| is 20 bits)
//   tr^2 r < 2^40 * 255 < 2^48                       48-bit unsigned
//   (r+1)^2 <= 65536                                 17-bit unsigned
//   (r+1)^2 det, taken only when det > 0: det < 2^38, product <= 2^16 det < 2^54
//                                                    54-bit unsigned
// Element (y,x) of `d` is at bits [(y*3+x)*16 +: 16].
`default_nettype none

module sc_edge (
    input  wire [9*16-1:0] d,
    input  wire [7:0]      ratio,
    output wire            pass
);
    // i16 sample k sign-extended to 18 bits.
    function [17:0] s18;
        input [15:0] v;
        s18 = {{2{v[15]}}, v};
    endfunction

    wire [17:0] d00 = s18(d[0*16 +: 16]);
    wire [17:0] d01 = s18(d[1*16 +: 16]);
    wire [17:0] d02 = s18(d[2*16 +: 16]);
    wire [17:0] d10 = s18(d[3*16 +: 16]);
    wire [17:0] d11 = s18(d[4*16 +: 16]);
    wire [17:0] d12 = s18(d[5*16 +: 16]);
    wire [17:0] d20 = s18(d[6*16 +: 16]);
    wire [17:0] d21 = s18(d[7*16 +: 16]);
    wire [17:0] d22 = s18(d[8*16 +: 16]);

    // Two's complement sums in 18 bits are exact within the bounds above.
    wire [17:0] xx = d12 + d10 - (d11 << 1);
    wire [17:0] yy = d21 + d01 - (d11 << 1);
    wire signed [19:0] dxx4 = {xx, 2'b00};
    wire signed [19:0] dyy4 = {yy, 2'b00};
    wire signed [17:0] dxy4 = d22 - d20 - d02 + d00;

    wire signed [20:0] tr  = {dxx4[19], dxx4} + {dyy4[19], dyy4};
    wire signed [38:0] det = dxx4 * dyy4 - dxy4 * dxy4;

    // |tr| < 2^20: tr[20] is the sign, the negation of tr[19:0] is exact modulo 2^20.
    wire [19:0] tr_mag = tr[20] ? -tr[19:0] : tr[19:0];
    wire [39:0] tr2    = tr_mag * tr_mag;
    wire [47:0] lhs    = tr2 * ratio;
    wire [8:0]  r1     = {1'b0, ratio} + 9'd1;
    wire [16:0] r1sq   = r1 * r1;
    // det[38] = 0 whenever det > 0, and then det < 2^38.
    wire [53:0] rhs    = r1sq * det[37:0];

    wire det_pos = !det[38] && det[37:0] != 38'd0;

    assign pass = ratio == 8'd0 || (det_pos && {6'd0, lhs} < rhs);
endmodule

`default_nettype wire
