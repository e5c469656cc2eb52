// sc_subsample: keeps the even columns of the even rows of G3 as the next octave's input
// (mirrors subsample.rs `Subsampler`). One output register, consumed on every enabled edge:
// latency SUBSAMPLE_LATENCY = 1. Output size ceil(w/2) x ceil(h/2).
//
// Widths: samples u16 Q8.8; x < width (16 bits); only the parity of the row is needed;
// taken <= total = width * height < 2^32.
`default_nettype none

module sc_subsample (
    input  wire        clk,
    input  wire        start,     // new frame: clear counters and the output register
    input  wire        en,        // enabled clock
    input  wire [15:0] width,     // input width, stable from the clock after `start`
    input  wire [31:0] total,     // width * height, likewise
    input  wire        in_valid,
    input  wire [15:0] in_data,   // G3, u16 Q8.8
    output reg         out_valid,
    output reg  [15:0] out_data,  // next octave's input, u16 Q8.8
    output wire        done       // every input taken and the output register empty
);

    reg [15:0] x;      // column of the next input, < width
    reg        y_odd;  // row parity of the next input
    reg [31:0] taken;  // inputs taken

    wire [16:0] x1    = {1'b0, x} + 17'd1;
    wire        x_end = x1 == {1'b0, width};
    wire        keep  = in_valid && !x[0] && !y_odd;

    always @(posedge clk) begin
        if (start) begin
            x         <= 16'd0;
            y_odd     <= 1'b0;
            taken     <= 32'd0;
            out_valid <= 1'b0;
        end else if (en) begin
            out_valid <= keep;
            if (keep) out_data <= in_data;
            if (in_valid) begin
                taken <= taken + 32'd1;
                x     <= x_end ? 16'd0 : x1[15:0];
                if (x_end) y_odd <= !y_odd;
            end
        end
    end

    assign done = taken == total && !out_valid;

endmodule

`default_nettype wire
