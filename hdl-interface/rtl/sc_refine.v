// sc_refine: sub-pixel / sub-scale refinement of an extremum, = refine::refine
// (combinational; the octave holds the refine register, REFINE_LATENCY = 1).
//
// Fit a quadratic to the DoG cube and solve 4H o = -2 (2g) with central differences:
//   2g = (c(1,1,2) - c(1,1,0), c(1,2,1) - c(1,0,1), c(2,1,1) - c(0,1,1))
//   4H diagonal: hxx = 4 (c(1,1,2) + c(1,1,0) - 2 c0), hyy, hss alike (c0 = c(1,1,1))
//   4H off-diagonal: hxy = c(1,2,2) - c(1,2,0) - c(1,0,2) + c(1,0,0), hxs, hys alike
//   o_i = round(-2 * dot_i * 2^13 / det), dot_i = sum_j adj(4H)[i][j] (2g)_j, det = det(4H),
// rounded to nearest with ties away from zero: q = (|num| + floor(|det| / 2)) / |det|, sign
// of num * det. ok = 0 when det == 0 or any |q_i| > min(max_offset, 32767).
//
// Exact widths (samples i16 in [-32768, 32767]; D = 524280, O = 131070):
//   (2g)_j in [-65535, 65535]                                   17-bit signed
//   diagonal sums c + c' - 2 c0 in [-131070, 131070]            18-bit signed
//   hxx, hyy, hss = 4 * that, |.| <= D < 2^19                   20-bit signed
//   hxy, hxs, hys |.| <= O < 2^17                               18-bit signed
//   a00 = hyy hss - hys^2 (a11, a22 alike): hyy hss <= D^2 = 274869518400 < 2^38; hyy and
//     hss share c0, so hyy hss >= -16 * 65535^2 and a00 >= -(16 * 65535^2 + O^2) > -2^37
//                                                                39-bit signed
//   a01 = hxs hys - hxy hss (a02, a12 alike; the four terms use disjoint samples):
//     |.| <= O^2 + O D = 85897724500 < 2^37                      38-bit signed
//   det = hxx a00 + hxy a01 + hxs a02: |.| <= D * 274869518400 + 2 O * 85897724500
//     = 1.667e17 < 2^58                                          59-bit signed
//   dot_i: |.| <= 65535 * (274869518400 + 2 * 85897724500) = 2.927e16 < 2^55
//                                                                56-bit signed
//   |num| = |dot| * 2^14 < 4.80e20; n = |num| + floor(|det| / 2) < 4.81e20 < 2^69
//                                                                69-bit unsigned
// The quotient is needed only up to 2^15 - 1 (anything larger is rejected, the limit being at
// most 32767), so the divider is a 15-step restoring divider on the 58-bit |det|:
//   overflow  <=>  q >= 2^15  <=>  n >= |det| * 2^15  <=>  n[68:15] >= |det|
// and otherwise the partial remainder stays below |det| < 2^58 at every step. With det == 0
// the overflow test holds (no X from a division by zero) and ok is 0 anyway.
// dx, dy, ds are meaningful only when ok.
//
// Element (s,y,x) of `cube` is at bits [((s*3+y)*3+x)*16 +: 16].
`default_nettype none

module sc_refine (
    // The eight corners c(0|2, 0|2, 0|2) have no term in the fit.
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire [27*16-1:0] cube,
    /* verilator lint_on UNUSEDSIGNAL */
    input  wire [15:0]      max_offset,
    output wire             ok,
    output wire [15:0]      dx,
    output wire [15:0]      dy,
    output wire [15:0]      ds
);
    // Sample (s,y,x) sign-extended to 17 and 18 bits.
    function [16:0] s17;
        input [15:0] v;
        s17 = {v[15], v};
    endfunction
    function [17:0] s18;
        input [15:0] v;
        s18 = {{2{v[15]}}, v};
    endfunction

    wire [15:0] c0  = cube[13*16 +: 16];   // (1,1,1)
    wire [15:0] cxp = cube[14*16 +: 16];   // (1,1,2)
    wire [15:0] cxm = cube[12*16 +: 16];   // (1,1,0)
    wire [15:0] cyp = cube[16*16 +: 16];   // (1,2,1)
    wire [15:0] cym = cube[10*16 +: 16];   // (1,0,1)
    wire [15:0] csp = cube[22*16 +: 16];   // (2,1,1)
    wire [15:0] csm = cube[ 4*16 +: 16];   // (0,1,1)

    // 2g, 17 bits.
    wire signed [16:0] gx = s17(cxp) - s17(cxm);
    wire signed [16:0] gy = s17(cyp) - s17(cym);
    wire signed [16:0] gs = s17(csp) - s17(csm);

    // Diagonal of 4H: 18-bit sums (two's complement, exact), times 4.
    wire [17:0] c0x2 = s18(c0) << 1;
    wire [17:0] sxx  = s18(cxp) + s18(cxm) - c0x2;
    wire [17:0] syy  = s18(cyp) + s18(cym) - c0x2;
    wire [17:0] sss  = s18(csp) + s18(csm) - c0x2;
    wire signed [19:0] hxx = {sxx, 2'b00};
    wire signed [19:0] hyy = {syy, 2'b00};
    wire signed [19:0] hss = {sss, 2'b00};

    // Off-diagonal of 4H, 18 bits.
    wire signed [17:0] hxy = s18(cube[17*16 +: 16]) - s18(cube[15*16 +: 16])    // (1,2,2) (1,2,0)
                           - s18(cube[11*16 +: 16]) + s18(cube[ 9*16 +: 16]);   // (1,0,2) (1,0,0)
    wire signed [17:0] hxs = s18(cube[23*16 +: 16]) - s18(cube[21*16 +: 16])    // (2,1,2) (2,1,0)
                           - s18(cube[ 5*16 +: 16]) + s18(cube[ 3*16 +: 16]);   // (0,1,2) (0,1,0)
    wire signed [17:0] hys = s18(cube[25*16 +: 16]) - s18(cube[19*16 +: 16])    // (2,2,1) (2,0,1)
                           - s18(cube[ 7*16 +: 16]) + s18(cube[ 1*16 +: 16]);   // (0,2,1) (0,0,1)

    // Adjugate (cofactors of the symmetric 4H), as refine.rs writes them.
    wire signed [38:0] a00 = hyy * hss - hys * hys;
    wire signed [37:0] a01 = hxs * hys - hxy * hss;
    wire signed [37:0] a02 = hxy * hys - hxs * hyy;
    wire signed [38:0] a11 = hxx * hss - hxs * hxs;
    wire signed [37:0] a12 = hxs * hxy - hxx * hys;
    wire signed [38:0] a22 = hxx * hyy - hxy * hxy;

    wire signed [58:0] det = hxx * a00 + hxy * a01 + hxs * a02;

    wire signed [55:0] dot0 = a00 * gx + a01 * gy + a02 * gs;
    wire signed [55:0] dot1 = a01 * gx + a11 * gy + a12 * gs;
    wire signed [55:0] dot2 = a02 * gx + a12 * gy + a22 * gs;
    wire [3*56-1:0] dots = {dot2, dot1, dot0};

    // |det| < 2^58: the negation of det[57:0] is exact modulo 2^58.
    wire [57:0] det_mag = det[58] ? -det[57:0] : det[57:0];
    wire [14:0] limit   = max_offset[15] ? 15'h7fff : max_offset[14:0];

    wire [2:0]  pass;
    wire [47:0] offs;
    genvar i, k;
    generate
        for (i = 0; i < 3; i = i + 1) begin : g_off
            wire signed [55:0] dot = dots[i*56 +: 56];
            // |dot| < 2^55.
            wire [54:0] dot_mag = dot[55] ? -dot[54:0] : dot[54:0];
            wire [68:0] n   = {dot_mag, 14'd0} + {12'd0, det_mag[57:1]};
            wire        ovf = {4'd0, n[68:15]} >= det_mag;

            // Restoring division, quotient bits 14..0. Step k takes the partial remainder
            // r_in (k = 14: n[68:15], below |det| unless ovf) and brings down n[k].
            wire [14:0] q;
            for (k = 14; k >= 0; k = k - 1) begin : g_step
                wire [57:0] r_in;
                if (k == 14) begin : g_first
                    assign r_in = {4'd0, n[68:15]};
                end else begin : g_next
                    assign r_in = g_step[k+1].g_rem.r_out;
                end
                wire [58:0] t = {r_in, n[k]};
                assign q[k] = t >= {1'b0, det_mag};
                if (k > 0) begin : g_rem
                    // Below |det| < 2^58: t - |det| is exact in 58 bits.
                    wire [57:0] r_out = q[k] ? t[57:0] - det_mag : t[57:0];
                end
            end

            // num = -2^14 dot < 0 iff dot > 0; q is negative iff the signs of num and det differ.
            wire neg = (!dot[55] && dot[54:0] != 55'd0) != det[58];
            assign offs[i*16 +: 16] = neg ? -{1'b0, q} : {1'b0, q};
            assign pass[i] = !ovf && q <= limit;
        end
    endgenerate

    assign ok = det_mag != 58'd0 && pass == 3'b111;
    assign dx = offs[0 +: 16];
    assign dy = offs[16 +: 16];
    assign ds = offs[32 +: 16];
endmodule

`default_nettype wire
