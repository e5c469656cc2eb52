// sc_frontend: the fabric's front end (mirrors pipeline.rs `RegisterFrontEnd` without the
// output FIFOs and the frame counter): four sc_octave in cascade, octave k + 1 fed by the
// subsampler output register of octave k. One camera pixel per clock at most; octave 0 takes
// it as Q8.8 (`pixel << 8`).
//
// `start` (one clock, no pixel on it) latches cfg_* and resets every octave (= start_frame):
// octave k's size is geometry.rs octave_dims(cfg_width, cfg_height, k) = ceil(w / 2^k) x
// ceil(h / 2^k) (repeated ceil-halving equals one ceil division by 2^k). Octaves
// k >= cfg_octaves are never enabled and do not count for `done`.
//
// Line memories: octave k has Wk-sample lines; W1 >= ceil(W0/2), W2 >= ceil(W1/2),
// W3 >= ceil(W2/2), every Wk >= 12, as pipeline.rs checks at compile time; cfg_width <= W0
// and the last octave at least 3 x 3 are the configuration's business (config.rs validate).
//
// Widths: pixels u8; scale images u16 Q8.8; DoG i16 Q8.8; offsets Q2.13; positions 16 bits
// in the octave's grid. Observation ports per octave k: see rtl_spec.md.
`default_nettype none

module sc_frontend #(
    parameter W0 = 1280,
    parameter W1 = 640,
    parameter W2 = 320,
    parameter W3 = 160
) (
    input  wire         clk,
    input  wire         start,
    input  wire         ce,              // pixel-clock enable (sc_octave): advance only now
    input  wire [15:0]  cfg_width,
    input  wire [15:0]  cfg_height,
    input  wire [2:0]   cfg_octaves,     // 1..4
    input  wire [15:0]  cfg_contrast,    // Q8.8
    input  wire [7:0]   cfg_edge_ratio,
    input  wire [1:0]   cfg_sobel_scale,
    input  wire [15:0]  cfg_max_offset,  // raw Q2.13
    input  wire         pix_valid,
    input  wire [7:0]   pix_data,
    output wire         done,
    output wire [3:0]   oct_en,
    output wire [15:0]  g_valid,
    output wire [255:0] g_data,
    output wire [3:0]   dog_valid,
    output wire [191:0] dog_data,
    output wire [3:0]   sub_valid,
    output wire [63:0]  sub_data,
    output wire [3:0]   pt_valid,
    output wire [383:0] pt_data,
    output wire [3:0]   sb_valid,
    output wire [183:0] sb_data
);

    // Configuration latched on `start` (Config of start_frame).
    reg [2:0]  octaves;
    reg [15:0] contrast, max_offset;
    reg [7:0]  edge_ratio;
    reg [1:0]  sobel_scale;
    always @(posedge clk) begin
        if (start) begin
            octaves     <= cfg_octaves;
            contrast    <= cfg_contrast;
            edge_ratio  <= cfg_edge_ratio;
            sobel_scale <= cfg_sobel_scale;
            max_offset  <= cfg_max_offset;
        end
    end

    // octave_dims: ceil(n / 2^k) = (n >> k) + (any of the k low bits set), 16 bits.
    wire [15:0] dw1 = (cfg_width  >> 1) + {15'd0, |cfg_width[0]};
    wire [15:0] dh1 = (cfg_height >> 1) + {15'd0, |cfg_height[0]};
    wire [15:0] dw2 = (cfg_width  >> 2) + {15'd0, |cfg_width[1:0]};
    wire [15:0] dh2 = (cfg_height >> 2) + {15'd0, |cfg_height[1:0]};
    wire [15:0] dw3 = (cfg_width  >> 3) + {15'd0, |cfg_width[2:0]};
    wire [15:0] dh3 = (cfg_height >> 3) + {15'd0, |cfg_height[2:0]};
    wire [63:0] dim_w = {dw3, dw2, dw1, cfg_width};
    wire [63:0] dim_h = {dh3, dh2, dh1, cfg_height};

    wire [3:0]  oct_done, align_err;
    wire [3:0]  in_valid;
    wire [63:0] in_data;
    assign in_valid = {sub_valid[2:0], pix_valid};
    assign in_data  = {sub_data[47:0], pix_data, 8'd0};

    genvar k;
    generate
        for (k = 0; k < 4; k = k + 1) begin : g_oct
            localparam WK = (k == 0) ? W0 : (k == 1) ? W1 : (k == 2) ? W2 : W3;
            sc_octave #(.W(WK), .INDEX(k)) u_octave (
                .clk(clk), .start(start),
                .dim_w(dim_w[k*16 +: 16]), .dim_h(dim_h[k*16 +: 16]),
                .cfg_contrast(contrast), .cfg_edge_ratio(edge_ratio),
                .cfg_sobel_scale(sobel_scale), .cfg_max_offset(max_offset),
                .active(octaves > k), .ce(ce),
                .in_valid(in_valid[k]), .in_data(in_data[k*16 +: 16]),
                .en(oct_en[k]), .done(oct_done[k]),
                .g_valid(g_valid[k*4 +: 4]), .g_data(g_data[k*64 +: 64]),
                .dog_valid(dog_valid[k]), .dog_data(dog_data[k*48 +: 48]),
                .sub_valid(sub_valid[k]), .sub_data(sub_data[k*16 +: 16]),
                .pt_valid(pt_valid[k]), .pt_data(pt_data[k*96 +: 96]),
                .sb_valid(sb_valid[k]), .sb_data(sb_data[k*46 +: 46]),
                .align_err(align_err[k]));
        end
    endgenerate

    assign done = oct_done[0] && (octaves < 3'd2 || oct_done[1])
               && (octaves < 3'd3 || oct_done[2]) && (octaves < 3'd4 || oct_done[3]);

    /* verilator lint_off UNUSED */
    // The model's align_errors (zero by construction): read hierarchically by simulations
    // (g_oct[k].u_octave.align_err), no port in the fixed interface.
    wire unused_align_err = |align_err;
    /* verilator lint_on UNUSED */

endmodule

`default_nettype wire
