// sc_col_conv: vertical 5-tap Gaussian stage (mirrors convolver.rs `ColumnConvolver`).
// Four line memories (sc_linebuf, N = 4, 26-bit words) hold the rows y-1..y-4 of the row-stage
// output; with the incoming sample they give the column col[d] = row y - d (d = 0..4) at
// column x. The output centre is row yc = y - 2; tap k reads row clamp(yc + k - 2, height - 1)
// = col[y - row] through border multiplexers (replicated border).
//
// Clocking as sc_row_conv: the output register is consumed on every enabled edge; samples are
// taken when valid, or as phantoms (value 0, never selected) once `total` were taken and fewer
// than `total` outputs emitted. The output of (x, yc) is registered when (x, yc + 2) arrives:
// latency 2*width + 1 enabled clocks (column_latency).
//
// Widths: samples are the row stage's exact sums, 26 bits (Q8.18, <= 1024 * 65535), and the line
// memories hold all 26 bits; the output is rounded once, (sum tap*r + 2^19) >> 20 (round half up,
// 36-bit accumulator), u16 Q8.8 (unity DC gain: <= 65535). Rounding once, after both passes,
// makes the separable pair equal the direct 2-D convolution with the outer product of the same
// quantized taps exactly. x < width <= W (AW bits); y <= height + 1 (16 bits, as the model's
// u16 row counter); total = width * height < 2^32.
`default_nettype none

module sc_col_conv #(
    parameter W = 1280,                                                   // line length
    parameter [49:0] TAPS = {10'd35, 10'd244, 10'd466, 10'd244, 10'd35}  // tap j at [j*10 +: 10]
) (
    input  wire        clk,
    input  wire        start,     // new frame: clear counters and the output register
    input  wire        en,        // enabled clock
    input  wire [15:0] width,     // frame width (<= W), stable from the clock after `start`
    input  wire [15:0] height,    // frame height, likewise
    input  wire [31:0] total,     // width * height, likewise
    input  wire        in_valid,
    input  wire [25:0] in_data,   // row-stage sum, Q8.18
    output reg         out_valid,
    output reg  [15:0] out_data   // u16 Q8.8
);

    localparam AW = $clog2(W);

    reg [AW-1:0] x;        // column of the next sample, < width
    reg [15:0]   y;        // row of the next sample, <= height + 1
    reg [31:0]   taken;    // samples (real or phantom) taken
    reg [31:0]   emitted;  // outputs produced

    wire more    = emitted < total;
    wire phantom = !in_valid && taken >= total && more;
    wire take    = in_valid || phantom;
    wire [25:0] sample = in_valid ? in_data : 26'd0;
    wire emit    = take && y >= 16'd2 && more;

    wire [16:0] x1    = {{(17-AW){1'b0}}, x} + 17'd1;
    wire        x_end = x1 == {1'b0, width};  // last column of the row
    wire [AW-1:0] x_next = x_end ? {AW{1'b0}} : x1[AW-1:0];

    wire [4*26-1:0] rows;  // rows y-1..y-4 at column x, [(d-1)*26 +: 26]
    sc_linebuf #(.DW(26), .N(4), .W(W), .AW(AW)) u_lines (
        .clk(clk), .start(start), .en(en),
        .raddr(start ? {AW{1'b0}} : (en && take) ? x_next : x),
        .we(en && take), .waddr(x), .wdata(sample),
        .row_done(en && take && x_end),
        .rdata(rows));
    wire [25:0] c1 = rows[0*26 +: 26];
    wire [25:0] c2 = rows[1*26 +: 26];
    wire [25:0] c3 = rows[2*26 +: 26];
    wire [25:0] c4 = rows[3*26 +: 26];

    // Border multiplexers (yc = y - 2 <= height - 1 while emitting).
    // tap 0: row max(y-4, 0): col[4], or col[2] (y = 2) / col[3] (y = 3)
    wire [25:0] w0 = (y == 16'd2) ? c2 : (y == 16'd3) ? c3 : c4;
    // tap 1: row max(y-3, 0): col[3], or col[2] (y = 2)
    wire [25:0] w1 = (y == 16'd2) ? c2 : c3;
    // tap 2: the centre row y-2
    wire [25:0] w2 = c2;
    // tap 3: row min(y-1, last): col[1], or col[2] (y = height + 1)
    wire [25:0] w3 = (y <= height) ? c1 : c2;
    // tap 4: row min(y, last): col[0], or col[1] (y = height) / col[2] (y = height + 1)
    wire [25:0] w4 = (y < height) ? sample : (y == height) ? c1 : c2;

    wire [15:0] dot;
    sc_da_dot #(.TAPS(TAPS), .IW(26), .SH(20)) u_dot (.s({w4, w3, w2, w1, w0}), .y(dot));

    always @(posedge clk) begin
        if (start) begin
            x         <= {AW{1'b0}};
            y         <= 16'd0;
            taken     <= 32'd0;
            emitted   <= 32'd0;
            out_valid <= 1'b0;
        end else if (en) begin
            out_valid <= emit;
            if (emit) begin
                out_data <= dot;
                emitted  <= emitted + 32'd1;
            end
            if (take) begin
                taken <= taken + 32'd1;
                x     <= x_next;
                if (x_end) y <= y + 16'd1;
            end
        end
    end

endmodule

`default_nettype wire
