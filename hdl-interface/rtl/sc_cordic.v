// sc_cordic: vectoring CORDIC on a Sobel vector with its pixel position carried along,
// = cordic::CordicPipeline register for register (CORDIC_LATENCY = 7).
//
// Registers (each loads on an enabled clock, `valid` = the Rust Option):
//   s0: quadrant fold into x > 0, y >= 0 (zero vector: 0, 0, z = 0)
//   s1: fixed -45 deg rotation (step 0: y >= 0 always holds after the fold)
//   s2..s5: steps 1..4, rotation by atan 2^-i toward the x axis, direction from sign(y)
//   out: magnitude code min(255, ((x >> 1) + (x >> 3) + 512) >> 10) and the 6-bit bin
//        ((z + 512) >> 10) & 63, 0 for x == 0.
// Outputs are the output register, i.e. before the edge (the octave qualifies them with
// its `en`); `start` empties the pipeline (valid bits only: no reset on data); `empty` =
// CordicPipeline::is_empty.
//
// Widths (in_sx, in_sy any 19-bit signed value, [-2^18, 2^18 - 1]):
//   z: 1/65536 turn, 16 bits wrapping; after the fold only the quadrant (2 bits) and after
//      step 0 quadrant + 8192, so s0/s1 keep just the quadrant.
//   x: the fold gives 0 <= x <= 2^18 (19-bit unsigned). Every step adds |y >> i| (y >= 0:
//      floor, y < 0: x - floor(y / 2^i) = x + ceil(|y| / 2^i)), so x never decreases nor
//      goes negative, and with |y| <= 2^18 (below): x1 <= 2^19, x2 <= 655360,
//      x3 <= 720896, x4 <= 753664, x5 <= 770048 < 2^20 (20-bit unsigned).
//   y: the fold gives 0 <= y <= 2^18 with x >= 1 unless both are 0, so y1 = y0 - x0 is in
//      [-2^18, 2^18 - 1]. A step with d = x >> i maps y >= 0 into [-d, y] and y < 0 into
//      [y, d - 1]; d <= 2^19 >> 1 = 2^18 at step 1 and less later, so y stays in
//      [-2^18, 2^18 - 1]: 19-bit signed. x >> i (<= 2^18) is added to or subtracted from y
//      modulo 2^19, exact because the result is in range. s5 keeps no y (finish ignores it).
//   magnitude: (x >> 1) + (x >> 3) <= 481280, + 512 < 2^19 (20-bit unsigned); the code
//      saturates at 255 iff the sum >= 256 * 1024 (x >= 0, so no clamp at 0).
`default_nettype none

module sc_cordic (
    input  wire               clk,
    input  wire               en,
    input  wire               start,
    input  wire               in_valid,
    input  wire [15:0]        in_x,
    input  wire [15:0]        in_y,
    input  wire signed [18:0] in_sx,
    input  wire signed [18:0] in_sy,
    output wire               out_valid,
    output wire [15:0]        out_x,
    output wire [15:0]        out_y,
    output wire [7:0]         out_mag,
    output wire [5:0]         out_ori,
    output wire               empty
);
    // atan(2^-i), i = 1..4, in 1/65536 turn (i = 0, 8192, is folded into s1's quadrant).
    localparam [15:0] ATAN1 = 16'd4836;
    localparam [15:0] ATAN2 = 16'd2555;
    localparam [15:0] ATAN3 = 16'd1297;
    localparam [15:0] ATAN4 = 16'd651;

    // Valid bits: s0..s5 and the output register.
    reg  [5:0]  v;
    reg         o_v;
    // Pixel positions, stage k at [k*16 +: 16].
    reg  [95:0] px, py;

    // ---- Fold (19-bit signed in, magnitudes up to 2^18).
    wire [18:0] neg_sx = -in_sx;    // 2^18 for in_sx = -2^18: as unsigned it is exact
    wire [18:0] neg_sy = -in_sy;
    wire sx_pos = !in_sx[18] && in_sx != 19'd0;
    wire sy_pos = !in_sy[18] && in_sy != 19'd0;
    wire sx_neg = in_sx[18];
    wire sy_neg = in_sy[18];
    reg  [18:0] f_x, f_y;
    reg  [1:0]  f_q;
    always @* begin
        if (sx_pos && !sy_neg) begin          // x > 0, y >= 0
            f_x = in_sx;  f_y = in_sy;  f_q = 2'd0;
        end else if (!sx_pos && sy_pos) begin // x <= 0, y > 0: rotate by -90
            f_x = in_sy;  f_y = neg_sx; f_q = 2'd1;
        end else if (sx_neg && !sy_pos) begin // x < 0, y <= 0: rotate by 180
            f_x = neg_sx; f_y = neg_sy; f_q = 2'd2;
        end else if (!sx_neg && sy_neg) begin // x >= 0, y < 0: rotate by +90
            f_x = neg_sy; f_y = in_sx;  f_q = 2'd3;
        end else begin                        // zero vector
            f_x = 19'd0;  f_y = 19'd0;  f_q = 2'd0;
        end
    end

    reg  [18:0]        s0_x, s0_y;  // both in [0, 2^18]
    reg  [1:0]         s0_q;
    reg  [19:0]        s1_x;
    reg  signed [18:0] s1_y;
    reg  [1:0]         s1_q;        // z1 = s1_q * 16384 + 8192
    reg  [19:0]        s2_x, s3_x, s4_x, s5_x;
    reg  signed [18:0] s2_y, s3_y, s4_y;
    reg  [15:0]        s2_z, s3_z, s4_z, s5_z;
    reg  [15:0]        o_x, o_y;
    reg  [7:0]         o_mag;
    reg  [5:0]         o_ori;

    // ---- Steps 1..4: y < 0 rotates up (x - (y >>> i), y + (x >> i), z - atan), else down.
    // x >> i is formed as x[19:1] >> (i - 1), 19 bits.
    wire [15:0]        z1   = {s1_q, 14'h2000};
    wire signed [19:0] ysh1 = $signed({s1_y[18], s1_y}) >>> 1;
    wire signed [19:0] ysh2 = $signed({s2_y[18], s2_y}) >>> 2;
    wire signed [19:0] ysh3 = $signed({s3_y[18], s3_y}) >>> 3;
    wire signed [19:0] ysh4 = $signed({s4_y[18], s4_y}) >>> 4;
    wire [18:0]        xsh1 = s1_x[19:1];
    wire [18:0]        xsh2 = s2_x[19:1] >> 1;
    wire [18:0]        xsh3 = s3_x[19:1] >> 2;

    // ---- Finish.
    wire [19:0] mag512 = {1'b0, s5_x[19:1]} + {3'b000, s5_x[19:3]} + 20'd512;
    // z rounded to the nearest 1/64 turn: bits 9:0 are the fraction dropped.
    /* verilator lint_off UNUSEDSIGNAL */
    wire [15:0] z_rnd  = s5_z + 16'd512;
    /* verilator lint_on UNUSEDSIGNAL */

    always @(posedge clk) begin
        if (start) begin
            v   <= 6'd0;
            o_v <= 1'b0;
        end else if (en) begin
            v   <= {v[4:0], in_valid};
            o_v <= v[5];
        end
    end

    always @(posedge clk) begin
        if (en) begin
            px    <= {px[79:0], in_x};
            py    <= {py[79:0], in_y};

            s0_x  <= f_x;
            s0_y  <= f_y;
            s0_q  <= f_q;

            s1_x  <= {1'b0, s0_x} + {1'b0, s0_y};
            s1_y  <= s0_y - s0_x;
            s1_q  <= s0_q;

            s2_x  <= s1_y[18] ? s1_x - ysh1 : s1_x + ysh1;
            s2_y  <= s1_y[18] ? s1_y + xsh1 : s1_y - xsh1;
            s2_z  <= s1_y[18] ? z1 - ATAN1 : z1 + ATAN1;

            s3_x  <= s2_y[18] ? s2_x - ysh2 : s2_x + ysh2;
            s3_y  <= s2_y[18] ? s2_y + xsh2 : s2_y - xsh2;
            s3_z  <= s2_y[18] ? s2_z - ATAN2 : s2_z + ATAN2;

            s4_x  <= s3_y[18] ? s3_x - ysh3 : s3_x + ysh3;
            s4_y  <= s3_y[18] ? s3_y + xsh3 : s3_y - xsh3;
            s4_z  <= s3_y[18] ? s3_z - ATAN3 : s3_z + ATAN3;

            s5_x  <= s4_y[18] ? s4_x - ysh4 : s4_x + ysh4;
            s5_z  <= s4_y[18] ? s4_z - ATAN4 : s4_z + ATAN4;

            o_x   <= px[95:80];
            o_y   <= py[95:80];
            o_mag <= mag512 >= 20'd262144 ? 8'd255 : mag512[17:10];
            o_ori <= s5_x == 20'd0 ? 6'd0 : z_rnd[15:10];
        end
    end

    assign out_valid = o_v;
    assign out_x     = o_x;
    assign out_y     = o_y;
    assign out_mag   = o_mag;
    assign out_ori   = o_ori;
    assign empty     = !o_v && v == 6'd0;
endmodule

`default_nettype wire
