// sc_row_conv: horizontal 5-tap Gaussian stage (mirrors convolver.rs `RowConvolver`).
// A 5-sample shift register (sh0 newest) feeds sc_da_dot through border multiplexers: the tap
// k of centre column xc reads column clamp(xc + k - 2, width - 1), i.e. shift register entry
// 2 - (col - xc); out of the frame the nearest edge sample is replicated.
//
// Clocking (rtl_spec.md): one enabled clock = one Rust `clock`; `out_valid/out_data` is the
// output register before the edge, consumed on every enabled edge. A sample is taken when
// `in_valid`, or, once `total` samples were taken and fewer than `total` outputs emitted, as a
// phantom (value 0, never selected: the borders clamp). The output of centre xc is registered
// when the sample of xc + 2 arrives: latency ROW_LATENCY = 3 enabled clocks.
//
// Widths: samples u16 Q8.8. Output: the exact dot product sum tap*s, unrounded, 26 bits (Q8.18:
// 1024 * 65535 < 2^26). The column stage rounds once, after both passes, so that the pair
// equals the direct 2-D convolution with the outer product of the same quantized taps exactly
// (rounding here too would make the result depend on the pass order by up to one code).
// width <= 65535; total = width * height < 2^32 (taken may run two phantoms past it, still
// < 2^32 for width <= 65535); centre column < width.
`default_nettype none

module sc_row_conv #(
    parameter [49:0] TAPS = {10'd35, 10'd244, 10'd466, 10'd244, 10'd35}  // tap j at [j*10 +: 10]
) (
    input  wire        clk,
    input  wire        start,     // new frame: clear counters and the output register
    input  wire        en,        // enabled clock
    input  wire [15:0] width,     // frame width, stable from the clock after `start`
    input  wire [31:0] total,     // width * height, likewise
    input  wire        in_valid,
    input  wire [15:0] in_data,   // u16 Q8.8
    output reg         out_valid,
    output reg  [25:0] out_data   // sum tap*s, exact (Q8.18)
);

    // Shift register, sh0 newest. The model's fifth entry is only read after the shift, when
    // it holds the old sh3, so four registers suffice.
    reg [15:0] sh0, sh1, sh2, sh3;
    reg [31:0] taken;                    // samples (real or phantom) taken
    reg [31:0] emitted;                  // outputs produced
    reg [15:0] xc;                       // column of the next output, < width

    wire more    = emitted < total;
    wire phantom = !in_valid && taken >= total && more;
    wire take    = in_valid || phantom;
    wire [15:0] sample = in_valid ? in_data : 16'd0;
    wire emit    = take && taken >= 32'd2 && more;  // taken + 1 >= 3 after this sample

    // Shift register after this edge: n0 = sample, n1 = sh0, n2 = sh1, n3 = sh2, n4 = sh3.
    wire [16:0] xc1 = {1'b0, xc} + 17'd1;
    wire [16:0] xc2 = {1'b0, xc} + 17'd2;
    wire left0  = xc == 16'd0;
    wire left1  = xc == 16'd1;
    wire fits1  = xc1 < {1'b0, width};  // xc + 1 <= width - 1
    wire fits2  = xc2 < {1'b0, width};  // xc + 2 <= width - 1
    // tap 0: col max(xc-2, 0): n4, or n2 (xc = 0) / n3 (xc = 1)
    wire [15:0] w0 = left0 ? sh1 : left1 ? sh2 : sh3;
    // tap 1: col max(xc-1, 0): n3, or n2 (xc = 0)
    wire [15:0] w1 = left0 ? sh1 : sh2;
    // tap 2: the centre n2
    wire [15:0] w2 = sh1;
    // tap 3: col min(xc+1, last): n1, or n2 (xc = last)
    wire [15:0] w3 = fits1 ? sh0 : sh1;
    // tap 4: col min(xc+2, last): n0, or n1 (xc = last - 1) / n2 (xc = last)
    wire [15:0] w4 = fits2 ? sample : fits1 ? sh0 : sh1;

    wire [25:0] dot;
    sc_da_dot #(.TAPS(TAPS), .IW(16), .SH(0)) u_dot (.s({w4, w3, w2, w1, w0}), .y(dot));

    always @(posedge clk) begin
        if (start) begin
            taken     <= 32'd0;
            emitted   <= 32'd0;
            xc        <= 16'd0;
            out_valid <= 1'b0;
        end else if (en) begin
            out_valid <= emit;
            if (take) begin
                {sh3, sh2, sh1, sh0} <= {sh2, sh1, sh0, sample};
                taken <= taken + 32'd1;
            end
            if (emit) begin
                out_data <= dot;
                xc       <= fits1 ? xc1[15:0] : 16'd0;
                emitted  <= emitted + 32'd1;
            end
        end
    end

endmodule

`default_nettype wire
