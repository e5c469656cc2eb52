// sc_line_fifo: bounded FIFO of DEPTH entries in one circular memory (mirrors fifo.rs
// `LineFifo`; the octave's alignment FIFOs have DEPTH = 7, 5, 3 lines of W). Within one clock
// the pop happens first, then the push (octave.rs): a pop frees its entry for the push of the
// same clock, and a push into an empty FIFO is popped on a later clock only.
//
// Synchronous read: `pop_data` is the memory's read register holding the entry at head (loaded
// on every edge from the next head; write-first, so a value written to that entry on the same
// edge is the one loaded), so the memory (sc_ram) maps to block RAM. A pop from an empty FIFO and a push into a full one do nothing but raise
// `pop_err` / `push_err` (the model's align_errors; zero when the octave is right).
//
// Widths: DW-bit entries; head < DEPTH (AW bits), len <= DEPTH (LW bits).
`default_nettype none

module sc_line_fifo #(
    parameter DW    = 16,
    parameter DEPTH = 7 * 1280
) (
    input  wire          clk,
    input  wire          start,      // new frame: empty
    input  wire          pop,        // remove the oldest entry (pop_data) this clock
    input  wire          push,       // append push_data this clock (after the pop)
    input  wire [DW-1:0] push_data,
    output wire [DW-1:0] pop_data,   // the oldest entry, valid when pop_ok
    output wire          pop_ok,     // not empty
    output wire          pop_err,    // pop from an empty FIFO
    output wire          push_err    // push into a full FIFO
);

    localparam AW = $clog2(DEPTH);
    localparam LW = $clog2(DEPTH + 1);
    localparam [31:0] DEPTH32 = DEPTH;
    localparam [AW:0] CAP = DEPTH32[AW:0];

    reg [AW-1:0] head;             // < DEPTH
    reg [LW-1:0] len;              // <= DEPTH
    wire [DW-1:0] rd;              // the entry at head

    assign pop_ok = len != {LW{1'b0}};
    wire do_pop   = pop && pop_ok;
    wire [LW-1:0] len_p = len - {{(LW-1){1'b0}}, do_pop};  // after the pop
    wire do_push  = push && len_p != CAP[LW-1:0];
    assign pop_err  = pop && !pop_ok;
    assign push_err = push && !do_push;

    wire [AW:0] head1 = {1'b0, head} + 1'b1;
    wire [AW-1:0] head_n = !do_pop ? head : (head1 == CAP) ? {AW{1'b0}} : head1[AW-1:0];
    // Write index head + len (mod DEPTH); head + len < 2 * DEPTH.
    wire [AW+1:0] tail  = {2'b00, head} + {{(AW+2-LW){1'b0}}, len};
    wire [AW-1:0] waddr = (tail >= {1'b0, CAP}) ? tail[AW-1:0] - CAP[AW-1:0] : tail[AW-1:0];

    sc_ram #(.DW(DW), .DEPTH(DEPTH), .WRITE_FIRST(1), .AW(AW)) entries (
        .clk(clk), .we(do_push), .wa(waddr), .wd(push_data), .re(1'b1), .ra(head_n), .q(rd)
    );

    always @(posedge clk) begin
        if (start) begin
            head <= {AW{1'b0}};
            len  <= {LW{1'b0}};
        end else begin
            head <= head_n;
            len  <= len_p + {{(LW-1){1'b0}}, do_push};
        end
    end

    assign pop_data = rd;

endmodule

`default_nettype wire
