// sc_refine: sub-pixel / sub-scale refinement of an extremum, = refine::refine, pipelined over
// REFINE_LATENCY = 18 enabled clocks (refine.rs) at one candidate per clock.
//
// Stages (one register each; `en` advances all of them, `start` clears the valid bits):
//   1      gradient and Hessian sums (2g, 4H)                  adders only
//   2      the six cofactors of 4H                              20x20-bit products
//   3      det(4H) and the three dot products adj(4H) (2g)      20x39 / 39x17-bit products
//   4      |det|, |num| + |det|/2, overflow test, sign; divider step 14
//   5..17  divider steps 13..1, one per stage (SPS = 1 step per stage)
//   18     divider step 0, sign, limit: the output register (= octave.rs refine_reg)
// Why 18: the single-clock version was 144.7 ns of logic (yosys `sta`, iCE40 HX cells), the
// one path keeping the octave below 9.73 MHz (640x240 at 60 Hz). Each stage above is one
// product level or one of the 15 dependent 59-bit compare/subtract steps of the restoring
// divider (about 8 ns each), aiming at the convolvers' depth (~10 ns). Longest stage
// (yosys `sta` after `synth_ice40 -top sc_refine`, iCE40 HX cell delays, logic only): 13.7 ns,
// stage 3 (det: a 20x39-bit product and the 3-term sum; stage 4 is about as long, the divider
// stages about 9.5 ns), <= 72.9 MHz before routing; 3 divider steps per stage gave 29.6 ns.
// The price is the divider's pipeline registers (about 380 bits per stage).
//
// Candidates that refine() rejects (det == 0, |o_i| > max_offset) travel through stages 1..17
// with their valid bit set and are dropped when entering the output register: `busy` (any
// valid bit, output register included) is what octave.rs `done()` tests (its in-flight slots
// hold rejected candidates too). max_offset is the configuration, stable during a frame.
//
// Arithmetic: fit a quadratic to the DoG cube and solve 4H o = -2 (2g) with central
// differences:
//   2g = (c(1,1,2) - c(1,1,0), c(1,2,1) - c(1,0,1), c(2,1,1) - c(0,1,1))
//   4H diagonal: hxx = 4 (c(1,1,2) + c(1,1,0) - 2 c0), hyy, hss alike (c0 = c(1,1,1))
//   4H off-diagonal: hxy = c(1,2,2) - c(1,2,0) - c(1,0,2) + c(1,0,0), hxs, hys alike
//   o_i = round(-2 * dot_i * 2^13 / det), dot_i = sum_j adj(4H)[i][j] (2g)_j, det = det(4H),
// rounded to nearest with ties away from zero: q = (|num| + floor(|det| / 2)) / |det|, sign
// of num * det. Rejected when det == 0 or any |q_i| > min(max_offset, 32767).
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
// the overflow test holds (no X from a division by zero) and the candidate is dropped anyway.
//
// Element (s,y,x) of `cube` is at bits [((s*3+y)*3+x)*16 +: 16].
`default_nettype none

module sc_refine (
    input  wire             clk,
    input  wire             en,          // the octave's enable
    input  wire             start,       // clears every valid bit
    input  wire             in_valid,    // a candidate (octave.rs edge_reg)
    input  wire [15:0]      in_x,
    input  wire [15:0]      in_y,
    // The eight corners c(0|2, 0|2, 0|2) have no term in the fit.
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire [27*16-1:0] cube,
    /* verilator lint_on UNUSEDSIGNAL */
    input  wire [15:0]      max_offset,  // raw Q2.13
    output reg              out_valid,   // output register: an accepted point
    output reg  [15:0]      out_x,
    output reg  [15:0]      out_y,
    output reg  [15:0]      out_dog,     // c(1,1,1)
    output reg  [15:0]      dx,          // Q2.13 raw bits
    output reg  [15:0]      dy,
    output reg  [15:0]      ds,
    output wire             busy         // a candidate in some stage (output register too)
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

    // ---- stage 1: sums ----
    wire [15:0] c0  = cube[13*16 +: 16];   // (1,1,1)
    wire [15:0] cxp = cube[14*16 +: 16];   // (1,1,2)
    wire [15:0] cxm = cube[12*16 +: 16];   // (1,1,0)
    wire [15:0] cyp = cube[16*16 +: 16];   // (1,2,1)
    wire [15:0] cym = cube[10*16 +: 16];   // (1,0,1)
    wire [15:0] csp = cube[22*16 +: 16];   // (2,1,1)
    wire [15:0] csm = cube[ 4*16 +: 16];   // (0,1,1)

    wire [17:0] c0x2 = s18(c0) << 1;
    wire [17:0] sxx  = s18(cxp) + s18(cxm) - c0x2;
    wire [17:0] syy  = s18(cyp) + s18(cym) - c0x2;
    wire [17:0] sss  = s18(csp) + s18(csm) - c0x2;

    reg               v1;
    reg        [15:0] x1, y1, dog1;
    reg signed [16:0] gx1, gy1, gs1;       // 2g, 17 bits
    reg signed [19:0] hxx1, hyy1, hss1;    // diagonal of 4H, 20 bits
    reg signed [17:0] hxy1, hxs1, hys1;    // off-diagonal of 4H, 18 bits
    always @(posedge clk) begin
        if (en) begin
            v1   <= in_valid;
            x1   <= in_x;
            y1   <= in_y;
            dog1 <= c0;
            gx1  <= s17(cxp) - s17(cxm);
            gy1  <= s17(cyp) - s17(cym);
            gs1  <= s17(csp) - s17(csm);
            hxx1 <= {sxx, 2'b00};
            hyy1 <= {syy, 2'b00};
            hss1 <= {sss, 2'b00};
            hxy1 <= s18(cube[17*16 +: 16]) - s18(cube[15*16 +: 16])    // (1,2,2) (1,2,0)
                  - s18(cube[11*16 +: 16]) + s18(cube[ 9*16 +: 16]);   // (1,0,2) (1,0,0)
            hxs1 <= s18(cube[23*16 +: 16]) - s18(cube[21*16 +: 16])    // (2,1,2) (2,1,0)
                  - s18(cube[ 5*16 +: 16]) + s18(cube[ 3*16 +: 16]);   // (0,1,2) (0,1,0)
            hys1 <= s18(cube[25*16 +: 16]) - s18(cube[19*16 +: 16])    // (2,2,1) (2,0,1)
                  - s18(cube[ 7*16 +: 16]) + s18(cube[ 1*16 +: 16]);   // (0,2,1) (0,0,1)
        end
        if (start) v1 <= 1'b0;
    end

    // ---- stage 2: adjugate (cofactors of the symmetric 4H), as refine.rs writes them ----
    reg               v2;
    reg        [15:0] x2, y2, dog2;
    reg signed [16:0] gx2, gy2, gs2;
    reg signed [19:0] hxx2;
    reg signed [17:0] hxy2, hxs2;
    reg signed [38:0] a00, a11, a22;
    reg signed [37:0] a01, a02, a12;
    always @(posedge clk) begin
        if (en) begin
            v2   <= v1;
            x2   <= x1;
            y2   <= y1;
            dog2 <= dog1;
            gx2  <= gx1;
            gy2  <= gy1;
            gs2  <= gs1;
            hxx2 <= hxx1;
            hxy2 <= hxy1;
            hxs2 <= hxs1;
            a00  <= hyy1 * hss1 - hys1 * hys1;
            a01  <= hxs1 * hys1 - hxy1 * hss1;
            a02  <= hxy1 * hys1 - hxs1 * hyy1;
            a11  <= hxx1 * hss1 - hxs1 * hxs1;
            a12  <= hxs1 * hxy1 - hxx1 * hys1;
            a22  <= hxx1 * hyy1 - hxy1 * hxy1;
        end
        if (start) v2 <= 1'b0;
    end

    // ---- stage 3: determinant and dot products ----
    reg               v3;
    reg        [15:0] x3, y3, dog3;
    reg signed [58:0] det3;
    reg signed [55:0] dot0, dot1, dot2;
    always @(posedge clk) begin
        if (en) begin
            v3   <= v2;
            x3   <= x2;
            y3   <= y2;
            dog3 <= dog2;
            det3 <= hxx2 * a00 + hxy2 * a01 + hxs2 * a02;
            dot0 <= a00 * gx2 + a01 * gy2 + a02 * gs2;
            dot1 <= a01 * gx2 + a11 * gy2 + a12 * gs2;
            dot2 <= a02 * gx2 + a12 * gy2 + a22 * gs2;
        end
        if (start) v3 <= 1'b0;
    end

    // ---- stages 4..18: magnitudes and the restoring divider ----
    localparam SPS = 1;  // divider steps per stage (a register after steps k % SPS == 0, k > 0)
    // Divider state after each step, SW bits: {per offset i at [107 + i*90 +: 90]:
    // {neg, ovf, nlo[14:0], q[14:0], r[57:0]}, det_mag[57:0] at [49 +: 58], dog, y, x, valid}.
    localparam SW = 1 + 48 + 58 + 3 * 90;

    // |det| < 2^58: the negation of det[57:0] is exact modulo 2^58.
    wire [57:0] det_mag = det3[58] ? -det3[57:0] : det3[57:0];
    wire [3*56-1:0] dots = {dot2, dot1, dot0};
    wire [SW-1:0] prep;
    assign prep[0 +: 107] = {det_mag, dog3, y3, x3, v3};
    wire [14:0] stv;  // valid bit of the register after step k (0 where none)
    genvar i, k;
    generate
        for (i = 0; i < 3; i = i + 1) begin : g_prep
            wire signed [55:0] dot = dots[i*56 +: 56];
            // |dot| < 2^55.
            wire [54:0] dot_mag = dot[55] ? -dot[54:0] : dot[54:0];
            wire [68:0] n   = {dot_mag, 14'd0} + {12'd0, det_mag[57:1]};
            wire        ovf = {4'd0, n[68:15]} >= det_mag;
            // num = -2^14 dot < 0 iff dot > 0; q is negative iff the signs of num and det differ.
            wire        neg = (!dot[55] && dot[54:0] != 55'd0) != det3[58];
            // Step 14 takes n[68:15] as its partial remainder (below |det| unless ovf).
            assign prep[107 + i*90 +: 90] = {neg, ovf, n[14:0], 15'd0, 4'd0, n[68:15]};
        end

        // Step k brings down n[k]; a register after steps 14..1 (stages 4..17).
        for (k = 14; k >= 0; k = k - 1) begin : g_step
            wire [SW-1:0] si;
            wire [SW-1:0] sc;
            wire [SW-1:0] so;
            if (k == 14) begin : g_first
                assign si = prep;
            end else begin : g_next
                assign si = g_step[k+1].so;
            end
            assign sc[0 +: 107] = si[0 +: 107];
            for (i = 0; i < 3; i = i + 1) begin : g_off
                wire [89:0] st  = si[107 + i*90 +: 90];
                wire [58:0] t   = {st[57:0], st[73 + k]};
                wire        qb  = t >= {1'b0, si[49 +: 58]};
                wire [14:0] qo  = st[72:58] | ({14'd0, qb} << k);
                // Below |det| < 2^58: t - |det| is exact in 58 bits.
                wire [57:0] ro  = qb ? t[57:0] - si[49 +: 58] : t[57:0];
                assign sc[107 + i*90 +: 90] = {st[89:73], qo, ro};
            end
            if (k % SPS == 0 && k > 0) begin : g_reg
                reg [SW-1:0] sr;
                always @(posedge clk) begin
                    if (en) sr <= sc;
                    if (start) sr[0] <= 1'b0;
                end
                assign so = sr;
                assign stv[k] = sr[0];
            end else begin : g_comb
                assign so = sc;
                assign stv[k] = 1'b0;
            end
        end
    endgenerate

    // ---- stage 18 tail: sign, limit, the output register ----
    // The remainders after step 0 are not needed.
    /* verilator lint_off UNUSEDSIGNAL */
    wire [SW-1:0] fin = g_step[0].so;
    /* verilator lint_on UNUSEDSIGNAL */
    wire [14:0] limit = max_offset[15] ? 15'h7fff : max_offset[14:0];
    wire [2:0]  pass;
    wire [47:0] offs;
    generate
        for (i = 0; i < 3; i = i + 1) begin : g_out
            wire [14:0] q   = fin[107 + i*90 + 58 +: 15];
            wire        ovf = fin[107 + i*90 + 88];
            wire        neg = fin[107 + i*90 + 89];
            assign offs[i*16 +: 16] = neg ? -{1'b0, q} : {1'b0, q};
            assign pass[i] = !ovf && q <= limit;
        end
    endgenerate
    wire ok = fin[49 +: 58] != 58'd0 && pass == 3'b111;

    always @(posedge clk) begin
        if (en) begin
            out_valid <= fin[0] && ok;
            if (fin[0] && ok) begin
                {out_dog, out_y, out_x} <= fin[1 +: 48];
                dx <= offs[0 +: 16];
                dy <= offs[16 +: 16];
                ds <= offs[32 +: 16];
            end
        end
        if (start) out_valid <= 1'b0;
    end

    assign busy = v1 || v2 || v3 || stv != 15'd0 || out_valid;
endmodule

`default_nettype wire
