// sc_window3: 3x3 window former (mirrors window.rs `WindowFormer`, thesis fig. 4.7). Two line
// memories (sc_linebuf, N = 2) give the rows y-2 and y-1 of column x; with the incoming sample
// they form a column vector, and a 3-deep shift register of columns (col0 newest) gives the
// horizontal neighbours. Borders are replicated by the read multiplexers, so a window exists
// for every pixel.
//
// Clocking: the output register (window, centre x, y) is consumed on every enabled edge.
// Samples are taken when valid, or, once `total` were taken and fewer than `total` windows
// emitted, as a phantom repeating col0's newest entry (the model's `cols[0][2]`; never selected
// by the multiplexers). The window of centre (xc, yc) is registered when sample (xc+1, yc+1)
// arrives, i.e. after more than width + 1 samples: latency width + 2 (window_latency).
//
// Widths: DW-bit elements; element (r, c) of out_w at [(r*3 + c)*DW +: DW], centre (1, 1);
// x < width <= W (AW bits); centre x, y < 65536; total = width * height < 2^32.
`default_nettype none

module sc_window3 #(
    parameter DW = 16,    // element width
    parameter W  = 1280   // line length
) (
    input  wire          clk,
    input  wire          start,     // new frame: clear counters and the output register
    input  wire          en,        // enabled clock
    input  wire [15:0]   width,     // frame width (<= W), stable from the clock after `start`
    input  wire [15:0]   height,    // frame height, likewise
    input  wire [31:0]   total,     // width * height, likewise
    input  wire          in_valid,
    input  wire [DW-1:0] in_data,
    output reg           out_valid,
    output reg  [15:0]   out_x,     // centre column
    output reg  [15:0]   out_y,     // centre row
    output reg  [9*DW-1:0] out_w,   // the window
    output wire          done       // every window emitted and the output register empty
);

    localparam AW = $clog2(W);

    reg [AW-1:0] x;        // column of the next sample, < width
    reg [15:0]   xc, yc;   // centre of the next window
    reg [31:0]   taken;    // samples (real or phantom) taken
    reg [31:0]   emitted;  // windows produced
    // Column vectors [row y-2, y-1, y], col0 newest: colK_R = row entry R of column K. The
    // model's third column is only read after the shift, when it holds the old col1, so two
    // registered columns suffice.
    reg [DW-1:0] col0_0, col0_1, col0_2, col1_0, col1_1, col1_2;

    wire more    = emitted < total;
    wire phantom = !in_valid && taken >= total && more;
    wire take    = in_valid || phantom;
    wire [DW-1:0] sample = in_valid ? in_data : col0_2;
    wire emit    = take && taken >= {16'd0, width} + 32'd1 && more;  // taken + 1 > width + 1

    wire [16:0] x1    = {{(17-AW){1'b0}}, x} + 17'd1;
    wire        x_end = x1 == {1'b0, width};
    wire [AW-1:0] x_next = x_end ? {AW{1'b0}} : x1[AW-1:0];

    wire [2*DW-1:0] rows;  // [0 +: DW] row y-1, [DW +: DW] row y-2, at column x
    sc_linebuf #(.DW(DW), .N(2), .W(W), .AW(AW)) u_lines (
        .clk(clk), .start(start), .en(en),
        .raddr(start ? {AW{1'b0}} : take ? x_next : x),
        .we(en && take), .waddr(x), .wdata(sample),
        .row_done(en && take && x_end),
        .rdata(rows));

    // Columns after this edge: N0 = {rows y-2, y-1, sample}, N1 = col0, N2 = col1.
    // Window column c reads column clamp(xc + c - 1, last), formed xc + 1 - cx samples ago:
    //   c = 0: N2, or N1 at xc = 0;  c = 1: N1;  c = 2: N0, or N1 at xc = last.
    // Window row r reads row clamp(yc + r - 1, last) = entry row - yc + 1:
    //   r = 0: entry 0, or 1 at yc = 0;  r = 1: entry 1;  r = 2: entry 2, or 1 at yc = last.
    wire [16:0] xc1 = {1'b0, xc} + 17'd1;
    wire [16:0] yc1 = {1'b0, yc} + 17'd1;
    wire lft = xc == 16'd0;
    wire rgt = xc1 == {1'b0, width};
    wire top = yc == 16'd0;
    wire bot = yc1 == {1'b0, height};

    wire [DW-1:0] n0_0 = rows[DW +: DW], n0_1 = rows[0 +: DW], n0_2 = sample;
    // column c = 0 (entries 0, 1, 2)
    wire [DW-1:0] a0 = lft ? col0_0 : col1_0;
    wire [DW-1:0] a1 = lft ? col0_1 : col1_1;
    wire [DW-1:0] a2 = lft ? col0_2 : col1_2;
    // column c = 2
    wire [DW-1:0] b0 = rgt ? col0_0 : n0_0;
    wire [DW-1:0] b1 = rgt ? col0_1 : n0_1;
    wire [DW-1:0] b2 = rgt ? col0_2 : n0_2;
    // rows: r = 0 entry (top ? 1 : 0), r = 1 entry 1, r = 2 entry (bot ? 1 : 2)
    wire [9*DW-1:0] win = {
        bot ? b1 : b2,         bot ? col0_1 : col0_2, bot ? a1 : a2,     // r = 2: c = 2, 1, 0
        b1,                    col0_1,                a1,                // r = 1
        top ? b1 : b0,         top ? col0_1 : col0_0, top ? a1 : a0      // r = 0
    };

    always @(posedge clk) begin
        if (start) begin
            x         <= {AW{1'b0}};
            xc        <= 16'd0;
            yc        <= 16'd0;
            taken     <= 32'd0;
            emitted   <= 32'd0;
            out_valid <= 1'b0;
        end else if (en) begin
            out_valid <= emit;
            if (take) begin
                {col0_0, col0_1, col0_2} <= {n0_0, n0_1, n0_2};
                {col1_0, col1_1, col1_2} <= {col0_0, col0_1, col0_2};
                taken <= taken + 32'd1;
                x     <= x_next;
            end
            if (emit) begin
                out_x   <= xc;
                out_y   <= yc;
                out_w   <= win;
                emitted <= emitted + 32'd1;
                if (rgt) begin
                    xc <= 16'd0;
                    yc <= yc + 16'd1;
                end else begin
                    xc <= xc1[15:0];
                end
            end
        end
    end

    assign done = emitted == total && !out_valid;

endmodule

`default_nettype wire
