// sc_octave: one octave of the fabric (mirrors octave.rs `Octave`, thesis fig. 4.5).
// Base image G0 (octave 0: the input filter, a row + column convolver; octaves >= 1: the input,
// i.e. the previous octave's subsampled G3, unfiltered), the cascade G1..G3, alignment FIFOs
// for G0..G2, the DoG register, the DoG window, the detector chain (detect_reg: interior test
// and sc_extrema; edge_reg: sc_edge on the middle DoG plane; sc_refine: the refinement
// pipelined over REFINE_LATENCY = 18 clocks, its last stage the refine register, rejected
// candidates dropped there), the Sobel window on G[cfg_sobel_scale] with gradient_reg
// (sc_sobel) and sc_cordic, and the subsampler feeding the next octave.
//
// Clocking (rtl_spec.md): all stages share `en = in_valid || flushing` with
// `flushing = taken == total && !done` (only while `active` and `ce`, never on `start`).
// `ce` is the pixel-clock enable of a fabric whose clock runs faster than its camera
// (sc_fabric's pix_ce): with `ce` low nothing advances, so the outputs are the same sequence
// whatever the ratio. Every stage
// sees its upstream stage's output register of the same clock; the outputs (g, DoG, point,
// Sobel pixel, subsampled sample) are the output registers before the edge, valid only while
// `en` is high. `done` is octave.rs `done()`.
//
// Alignment: G_i leaves its convolver (3 - i)(2w + 4) enabled clocks before G3 of the same
// pixel; G0..G2 are pushed into FIFOs of 7, 5, 3 lines of W and popped when G3 is valid (pop
// first, then push, as octave.rs). A failed pop drops the DoG sample; `align_err` (sticky until
// `start`) is the model's align_errors != 0.
//
// Widths: scale images u16 Q8.8; DoG i16 Q8.8; Sobel 19-bit signed; offsets Q2.13 (16 bits);
// magnitude u8; orientation 6 bits; octave size <= 65535 x 65535 (width <= W),
// total = width * height < 2^32.
`default_nettype none

module sc_octave #(
    parameter W     = 1280,  // line length (>= 12, >= the octave's width)
    parameter INDEX = 0      // octave number: 0 has the input filter G0
) (
    input  wire         clk,
    input  wire         start,            // new frame: load dims, clear counters and valid bits
    input  wire [15:0]  dim_w,            // octave width (geometry.rs octave_dims), at `start`
    input  wire [15:0]  dim_h,            // octave height, at `start`
    input  wire [15:0]  cfg_contrast,     // Q8.8, stable from the clock after `start`
    input  wire [7:0]   cfg_edge_ratio,   // likewise
    input  wire [1:0]   cfg_sobel_scale,  // likewise
    input  wire [15:0]  cfg_max_offset,   // raw Q2.13, likewise
    input  wire         active,           // the octave is configured (k < cfg_octaves)
    input  wire         ce,               // pixel-clock enable: the octave may advance only now
    input  wire         in_valid,         // an input sample this clock
    input  wire [15:0]  in_data,          // u16 Q8.8
    output wire         en,               // the octave advances on this clock
    output wire         done,             // every output of the frame has left
    output wire [3:0]   g_valid,          // bit i: G_i valid
    output wire [63:0]  g_data,           // [i*16 +: 16] G_i, u16 Q8.8
    output wire         dog_valid,        // the DoG register (input of the DoG window)
    output wire [47:0]  dog_data,         // [j*16 +: 16] D_j, i16 Q8.8
    output wire         sub_valid,        // subsampler output = next octave's input
    output wire [15:0]  sub_data,
    output wire         pt_valid,         // refine register = a point for the point FIFO
    output wire [95:0]  pt_data,          // {dog, ds, dy, dx, y, x}, 16 bits each
    output wire         sb_valid,         // CORDIC output = a Sobel pixel for the Sobel FIFO
    output wire [45:0]  sb_data,          // {ori[5:0], mag[7:0], y[15:0], x[15:0]}
    output reg          align_err         // an alignment FIFO under- or overflowed
);

    // GAUSS_TAPS (taps.rs): kernel i at [i*50 +: 50], tap j at [j*10 +: 10].
    localparam [199:0] TAPS = {
        10'd130, 10'd238, 10'd288, 10'd238, 10'd130,  // G3
        10'd57,  10'd249, 10'd412, 10'd249, 10'd57,   // G2
        10'd18,  10'd229, 10'd530, 10'd229, 10'd18,   // G1
        10'd35,  10'd244, 10'd466, 10'd244, 10'd35    // G0
    };

    // ---- frame geometry and enable ----
    reg [15:0] width, height;
    reg [31:0] total;  // width * height (one multiplier, used on `start` only)
    reg [31:0] taken;  // input samples taken, <= total

    wire flushing = taken == total && !done;
    assign en = ce && !start && active && (in_valid || flushing);

    always @(posedge clk) begin
        if (start) begin
            width  <= dim_w;
            height <= dim_h;
            total  <= {16'd0, dim_w} * {16'd0, dim_h};
            taken  <= 32'd0;
        end else if (en && in_valid) begin
            taken <= taken + 32'd1;
        end
    end

    // ---- Gaussian cascade ----
    // Each Gaussian is a row stage (exact 26-bit sums, no rounding) and a column stage that
    // rounds once to u16 Q8.8, so that it equals the direct 2-D convolution exactly.
    wire [3:0]  gv;  // output registers of the convolvers (G0 of octaves >= 1: the input)
    wire [63:0] gd;

    genvar i;
    generate
        if (INDEX == 0) begin : g_base
            wire        rv;
            wire [25:0] rd;  // row-stage sum, unrounded (Q8.18)
            sc_row_conv #(.TAPS(TAPS[0 +: 50])) u_row (
                .clk(clk), .start(start), .en(en), .width(width), .total(total),
                .in_valid(in_valid), .in_data(in_data), .out_valid(rv), .out_data(rd));
            sc_col_conv #(.W(W), .TAPS(TAPS[0 +: 50])) u_col (
                .clk(clk), .start(start), .en(en), .width(width), .height(height),
                .total(total), .in_valid(rv), .in_data(rd),
                .out_valid(gv[0]), .out_data(gd[0 +: 16]));
        end else begin : g_base
            assign gv[0]        = in_valid;
            assign gd[0 +: 16]  = in_data;
        end
        for (i = 1; i < 4; i = i + 1) begin : g_scale
            wire        rv;
            wire [25:0] rd;  // row-stage sum, unrounded (Q8.18)
            sc_row_conv #(.TAPS(TAPS[i*50 +: 50])) u_row (
                .clk(clk), .start(start), .en(en), .width(width), .total(total),
                .in_valid(gv[i-1]), .in_data(gd[(i-1)*16 +: 16]),
                .out_valid(rv), .out_data(rd));
            sc_col_conv #(.W(W), .TAPS(TAPS[i*50 +: 50])) u_col (
                .clk(clk), .start(start), .en(en), .width(width), .height(height),
                .total(total), .in_valid(rv), .in_data(rd),
                .out_valid(gv[i]), .out_data(gd[i*16 +: 16]));
        end
    endgenerate

    // ---- Sobel branch: window on G[s] -> gradient_reg -> CORDIC ----
    wire          sw_valid, sw_done;
    wire [15:0]   sw_x, sw_y;
    wire [143:0]  sw_w;
    sc_window3 #(.DW(16), .W(W)) u_sobel_window (
        .clk(clk), .start(start), .en(en), .width(width), .height(height), .total(total),
        .in_valid(gv[cfg_sobel_scale]), .in_data(gd[cfg_sobel_scale*16 +: 16]),
        .out_valid(sw_valid), .out_x(sw_x), .out_y(sw_y), .out_w(sw_w), .done(sw_done));

    wire signed [18:0] sx, sy;
    sc_sobel u_sobel (.p(sw_w), .sx(sx), .sy(sy));

    reg                grad_valid;
    reg [15:0]         grad_x, grad_y;
    reg signed [18:0]  grad_sx, grad_sy;
    always @(posedge clk) begin
        if (start) begin
            grad_valid <= 1'b0;
        end else if (en) begin
            grad_valid <= sw_valid;
            if (sw_valid) begin
                grad_x  <= sw_x;
                grad_y  <= sw_y;
                grad_sx <= sx;
                grad_sy <= sy;
            end
        end
    end

    wire        cor_valid, cor_empty;
    wire [15:0] cor_x, cor_y;
    wire [7:0]  cor_mag;
    wire [5:0]  cor_ori;
    sc_cordic u_cordic (
        .clk(clk), .en(en), .start(start),
        .in_valid(grad_valid), .in_x(grad_x), .in_y(grad_y), .in_sx(grad_sx), .in_sy(grad_sy),
        .out_valid(cor_valid), .out_x(cor_x), .out_y(cor_y), .out_mag(cor_mag),
        .out_ori(cor_ori), .empty(cor_empty));

    assign sb_valid = en && cor_valid;
    assign sb_data  = {cor_ori, cor_mag, cor_y, cor_x};

    // ---- alignment FIFOs and the DoG register ----
    wire        g3_now = en && gv[3];
    wire [47:0] al_data;
    wire [2:0]  al_ok, al_pop_err, al_push_err;
    sc_line_fifo #(.DW(16), .DEPTH(7 * W)) u_align0 (
        .clk(clk), .start(start), .pop(g3_now), .push(en && gv[0]), .push_data(gd[0 +: 16]),
        .pop_data(al_data[0 +: 16]), .pop_ok(al_ok[0]),
        .pop_err(al_pop_err[0]), .push_err(al_push_err[0]));
    sc_line_fifo #(.DW(16), .DEPTH(5 * W)) u_align1 (
        .clk(clk), .start(start), .pop(g3_now), .push(en && gv[1]), .push_data(gd[16 +: 16]),
        .pop_data(al_data[16 +: 16]), .pop_ok(al_ok[1]),
        .pop_err(al_pop_err[1]), .push_err(al_push_err[1]));
    sc_line_fifo #(.DW(16), .DEPTH(3 * W)) u_align2 (
        .clk(clk), .start(start), .pop(g3_now), .push(en && gv[2]), .push_data(gd[32 +: 16]),
        .pop_data(al_data[32 +: 16]), .pop_ok(al_ok[2]),
        .pop_err(al_pop_err[2]), .push_err(al_push_err[2]));

    wire [47:0] dog3;  // D_j = G_{j+1} - G_j
    sc_dog u_dog0 (.a(al_data[0 +: 16]),  .b(al_data[16 +: 16]), .d(dog3[0 +: 16]));
    sc_dog u_dog1 (.a(al_data[16 +: 16]), .b(al_data[32 +: 16]), .d(dog3[16 +: 16]));
    sc_dog u_dog2 (.a(al_data[32 +: 16]), .b(gd[48 +: 16]),      .d(dog3[32 +: 16]));

    reg        dog_v;
    reg [47:0] dog_d;
    always @(posedge clk) begin
        if (start) begin
            dog_v     <= 1'b0;
            align_err <= 1'b0;
        end else if (en) begin
            dog_v <= gv[3] && (&al_ok);
            if (gv[3]) dog_d <= dog3;
            if ((|al_pop_err) || (|al_push_err)) align_err <= 1'b1;
        end
    end

    // ---- detector: DoG window -> detect_reg -> edge_reg -> sc_refine (18 stages) ----
    wire          dw_valid, dw_done;
    wire [15:0]   dw_x, dw_y;
    wire [431:0]  dw_w;  // element (y, x) at [(y*3+x)*48 +: 48], D_s at [s*16 +: 16] in it
    sc_window3 #(.DW(48), .W(W)) u_dog_window (
        .clk(clk), .start(start), .en(en), .width(width), .height(height), .total(total),
        .in_valid(dog_v), .in_data(dog_d),
        .out_valid(dw_valid), .out_x(dw_x), .out_y(dw_y), .out_w(dw_w), .done(dw_done));

    wire [431:0] cube;  // (s, y, x) at [((s*3+y)*3+x)*16 +: 16]
    genvar s, e;
    generate
        for (s = 0; s < 3; s = s + 1) begin : g_cube_s
            for (e = 0; e < 9; e = e + 1) begin : g_cube_e
                assign cube[(s*9 + e)*16 +: 16] = dw_w[e*48 + s*16 +: 16];
            end
        end
    endgenerate

    wire is_ext;
    sc_extrema u_extrema (.cube(cube), .threshold(cfg_contrast), .is_ext(is_ext));

    // Interior: 1 <= x, 1 <= y, x + 2 <= width, y + 2 <= height.
    wire interior = dw_x != 16'd0 && dw_y != 16'd0
                 && {1'b0, dw_x} + 17'd2 <= {1'b0, width}
                 && {1'b0, dw_y} + 17'd2 <= {1'b0, height};

    reg          det_valid;
    reg [15:0]   det_x, det_y;
    reg [431:0]  det_cube;
    wire edge_pass;
    sc_edge u_edge (.d(det_cube[144 +: 144]), .ratio(cfg_edge_ratio), .pass(edge_pass));

    reg          edge_valid;
    reg [15:0]   edge_x, edge_y;
    reg [431:0]  edge_cube;

    // sc_refine: REFINE_LATENCY = 18 stages, its last one the refine register (ref_valid).
    wire         ref_valid, ref_busy;
    wire [15:0]  ref_x, ref_y, ref_dog, ref_dx, ref_dy, ref_ds;
    sc_refine u_refine (
        .clk(clk), .en(en), .start(start),
        .in_valid(edge_valid), .in_x(edge_x), .in_y(edge_y), .cube(edge_cube),
        .max_offset(cfg_max_offset),
        .out_valid(ref_valid), .out_x(ref_x), .out_y(ref_y), .out_dog(ref_dog),
        .dx(ref_dx), .dy(ref_dy), .ds(ref_ds), .busy(ref_busy));

    always @(posedge clk) begin
        if (start) begin
            det_valid  <= 1'b0;
            edge_valid <= 1'b0;
        end else if (en) begin
            edge_valid <= det_valid && edge_pass;
            if (det_valid && edge_pass) begin
                edge_x    <= det_x;
                edge_y    <= det_y;
                edge_cube <= det_cube;
            end
            det_valid <= dw_valid && interior && is_ext;
            if (dw_valid && interior && is_ext) begin
                det_x    <= dw_x;
                det_y    <= dw_y;
                det_cube <= cube;
            end
        end
    end

    assign pt_valid = en && ref_valid;
    assign pt_data  = {ref_dog, ref_ds, ref_dy, ref_dx, ref_y, ref_x};

    // ---- subsampler ----
    wire sub_v, sub_done;
    sc_subsample u_subsample (
        .clk(clk), .start(start), .en(en), .width(width), .total(total),
        .in_valid(gv[3]), .in_data(gd[48 +: 16]),
        .out_valid(sub_v), .out_data(sub_data), .done(sub_done));
    assign sub_valid = en && sub_v;

    // ---- observation and completion ----
    assign g_valid   = en ? gv : 4'd0;
    assign g_data    = gd;
    assign dog_valid = en && dog_v;
    assign dog_data  = dog_d;

    assign done = taken == total && sub_done && sw_done && !grad_valid && cor_empty
               && dw_done && !dog_v && !det_valid && !edge_valid && !ref_busy;

endmodule

`default_nettype wire
