// sc_linebuf: N line memories of W samples used as a circular buffer (mirrors linebuffer.rs).
// The row written d rows ago (d = 1..N) sits in slot (current - d) mod N; `current` advances
// when a row is complete and is cleared by `start`.
//
// Read-before-write as in the model, with block-RAM friendly synchronous reads: the owner
// gives on every enabled clock (and on `start`) the column `raddr` it will read at its next
// enabled clock; the read register loads all N memories at that column at this edge. The owner
// writes at most one column per clock (its current column) and `raddr` is the next column, so
// a read never hits the column written on the same edge (rows are at least 3 samples wide);
// between the prefetch and the use no write reaches `raddr` (the owner writes only at its own
// column, and its next write is the use itself). Hence `rdata` equals the model's
// `read(x, d)` on the enabled clock that uses it.
//
// Widths: DW-bit samples; AW-bit column address, AW = clog2(W).
`default_nettype none

module sc_linebuf #(
    parameter DW = 16,
    parameter N  = 4,
    parameter W  = 1280,
    parameter AW = $clog2(W)
) (
    input  wire            clk,
    input  wire            start,     // new frame: slot 0 is current
    input  wire            en,        // owner's enabled clock: load the read register
    input  wire [AW-1:0]   raddr,     // column read at the owner's next enabled clock
    input  wire            we,        // write wdata at waddr of the current row
    input  wire [AW-1:0]   waddr,
    input  wire [DW-1:0]   wdata,
    input  wire            row_done,  // the current row is complete (advance the slot)
    output wire [N*DW-1:0] rdata      // [(d-1)*DW +: DW]: column written d rows ago, d = 1..N
);

    localparam SW = (N > 1) ? $clog2(N) : 1;  // slot index width
    localparam [31:0]   LAST32 = N - 1;
    localparam [SW-1:0] LAST = LAST32[SW-1:0];
    localparam [SW:0]   NN   = N;

    reg  [SW-1:0]   current;  // 0..N-1
    wire [N*DW-1:0] q;        // read register of slot i at [i*DW +: DW]

    always @(posedge clk) begin
        if (start)
            current <= {SW{1'b0}};
        else if (row_done)
            current <= (current == LAST) ? {SW{1'b0}} : current + 1'b1;
    end

    genvar i, d;
    generate
        for (i = 0; i < N; i = i + 1) begin : g_slot
            localparam [SW-1:0] ID = i;
            // Power-up content is never selected (the borders clamp).
            sc_ram #(.DW(DW), .DEPTH(W), .AW(AW)) line (
                .clk(clk), .we(we && current == ID), .wa(waddr), .wd(wdata),
                .re(start || en), .ra(raddr), .q(q[i*DW +: DW])
            );
        end
        for (d = 1; d <= N; d = d + 1) begin : g_delay
            // slot (current - d) mod N = (current + N - d) mod N
            localparam [SW:0] OFF = N - d;
            wire [SW:0]   sum  = {1'b0, current} + OFF;
            wire [SW-1:0] slot = (sum >= NN) ? sum[SW-1:0] - NN[SW-1:0] : sum[SW-1:0];
            assign rdata[(d-1)*DW +: DW] = q[slot*DW +: DW];
        end
    endgenerate

endmodule

`default_nettype wire
