// sc_out_fifo: a multi-lane output FIFO of DEPTH entries of DW bits that takes up to 4 entries
// per clock (one per octave) and gives 1 per pop; sc_fabric's point FIFO (88 bits, 512 entries)
// and Sobel FIFO (48 bits, 3 x W0 entries) are two of it.
//
// Why: the four octaves may each push an item on the same clock, and the model
// (RegisterFrontEnd::clock) pushes them one after the other in octave order o0, o1, o2, o3
// (octave k's items inside octave k's clock, octave 0 first). Taking all of them in one clock,
// in that order, keeps the FIFO contents and the overflow count equal to the model's entry for
// entry, with no skid buffer and no stall (the datapath has no back-pressure, as the model).
//
// Layout: 4 banks of DEPTH / 4 rows; slot i is bank i % 4, row i / 4. Item k takes the write
// slot (wrow, wlane) + rank_k (rank_k = valid items of octaves below k), so the items of one
// clock land in distinct banks. With f free slots before the edge and n arrivals, the first
// min(n, f) in octave order are kept and the rest counted (`dropped`, saturating at
// 2^32 - 1; `dropping` on the clock), as the model's pushes one after the other. A pop on the
// same edge frees its slot for the next clock (the model's driver pops between clocks), not
// for this clock's arrivals. A pop of an empty FIFO is ignored.
//
// Reads: each bank reads the head's row every clock, so `head` (the head bank's word) is the
// FIFO head from the clock after a push or pop; a write to the row being read is passed
// through. `head` is meaningful only while `nonempty`. The memories are never reset: `clear`
// (synchronous) empties the FIFO and zeroes `dropped`.
//
// Snapshots (the stream engine, docs/STREAM_ENGINE.md): `mark` hands every entry held before
// the edge to the engine (`owed`; the engine pops them, one per pop). DEPTH then bounds the
// entries not owed, so the drops equal those of the model, whose engine takes the FIFO whole
// at each line time; the owed entries use SPARE more slots. An item refused only for want of
// a spare slot is counted as a drop and flagged on `overrun` (the engine fell behind: it did
// not pop a snapshot's entries before the next ones needed their room). Without marks
// (`owed` 0) the FIFO is the plain one of DEPTH entries.
//
// DEPTH + SPARE: a multiple of 4, at most 65535 (`level` is 16 bits).
`default_nettype none

module sc_out_fifo #(
    parameter DW = 88,                   // entry width
    parameter DEPTH = 512,               // entries not owed to the engine
    parameter SPARE = 0                  // more slots for owed entries
) (
    input  wire          clk,
    input  wire          clear,          // synchronous: empties the FIFO, zeroes `dropped`
    input  wire [3:0]    in_valid,       // item k (octave k) arrives on this clock
    input  wire [4*DW-1:0] in_data,      // item k at [k*DW +: DW]
    input  wire          pop,            // remove the head (ignored when empty)
    input  wire          mark,           // every entry held before the edge becomes owed
    output wire [DW-1:0] head,           // the oldest entry (valid while nonempty)
    output wire          nonempty,
    output wire [15:0]   level,          // entries held and not owed, 0..DEPTH
    output wire [31:0]   dropped,        // items not kept since `clear`, saturating
    output wire          dropping,       // an item is not kept on this clock
    output wire          overrun         // ... for want of a spare slot
);

    localparam PHYS = DEPTH + SPARE;
    localparam ROWS = PHYS / 4;
    localparam AW   = (ROWS > 1) ? $clog2(ROWS) : 1;    // row address bits
    localparam LW   = $clog2(PHYS + 1);                  // count: 0..PHYS
    localparam integer  FULL_I = DEPTH;
    localparam [LW-1:0] FULL = FULL_I[LW-1:0];
    localparam integer  PFULL_I = PHYS;
    localparam [LW-1:0] PFULL = PFULL_I[LW-1:0];
    localparam integer  LAST_I = ROWS - 1;
    localparam [AW-1:0] LAST = LAST_I[AW-1:0];

    reg  [AW-1:0] wrow, rrow;
    reg  [1:0]    wlane, rlane;
    reg  [LW-1:0] count;            // entries held
    reg  [LW-1:0] owed;             // of them, owed to the engine
    reg  [31:0]   drops;            // saturating overflow count

    // Ranks within the clock, 0..3, and the slot lane each item would take.
    wire [2:0]  r1 = {2'd0, in_valid[0]};
    wire [2:0]  r2 = r1 + {2'd0, in_valid[1]};
    wire [2:0]  r3 = r2 + {2'd0, in_valid[2]};
    wire [2:0]  n  = r3 + {2'd0, in_valid[3]};           // arrivals, 0..4
    wire [11:0] rank = {r3, r2, r1, 3'd0};               // item k at [k*3 +: 3]
    wire [LW-1:0] free_l = FULL - (count - owed);
    wire [LW-1:0] free_p = PFULL - count;
    wire [LW-1:0] free = (free_p < free_l) ? free_p : free_l;
    wire [LW-1:0] n_w = {{(LW-3){1'b0}}, n};
    wire [2:0]  acc = (n_w <= free) ? n : free[2:0];
    wire [2:0]  drop = n - acc;                          // 0..4
    wire [3:0]  take;                                    // item k is kept
    wire [15:0] hit;                                     // [k*4 + b]: item k -> bank b
    genvar k;
    generate
        for (k = 0; k < 4; k = k + 1) begin : g_item
            wire [2:0] rank_k = rank[k*3 +: 3];
            wire [1:0] lane = wlane + rank_k[1:0];
            assign take[k] = in_valid[k] && (rank_k < acc);
            assign hit[k*4 +: 4] = {4{take[k]}} & (4'b0001 << lane);
        end
    endgenerate

    // Bank b < wlane is written in the next row (the slots wrap past lane 3).
    wire [3:0]    wrap = ~(4'b1111 << wlane);
    wire [AW-1:0] wrow_next = (wrow == LAST) ? {AW{1'b0}} : wrow + 1'b1;
    wire [AW-1:0] rrow_next = (rrow == LAST) ? {AW{1'b0}} : rrow + 1'b1;
    wire          popped = pop && (count != {LW{1'b0}});
    wire [1:0]    rlane_n = rlane + {1'b0, popped};
    wire [AW-1:0] rrow_n = (popped && rlane == 2'd3) ? rrow_next : rrow;
    wire [2:0]    lane_sum = {1'b0, wlane} + acc;

    // Each bank reads the head's row every clock (the head bank's word is the FIFO head from
    // the next clock on); a write to the row being read is passed through.
    wire [4*DW-1:0] q_all;
    genvar b;
    generate
        for (b = 0; b < 4; b = b + 1) begin : g_bank
            wire          we = hit[b] | hit[4 + b] | hit[8 + b] | hit[12 + b];
            wire [DW-1:0] wd = ({DW{hit[b]}}      & in_data[0*DW +: DW])
                             | ({DW{hit[4 + b]}}  & in_data[1*DW +: DW])
                             | ({DW{hit[8 + b]}}  & in_data[2*DW +: DW])
                             | ({DW{hit[12 + b]}} & in_data[3*DW +: DW]);
            wire [AW-1:0] wa = wrap[b] ? wrow_next : wrow;
            sc_ram #(.DW(DW), .DEPTH(ROWS), .WRITE_FIRST(1), .AW(AW)) bank (
                .clk(clk), .we(we), .wa(wa), .wd(wd), .re(1'b1), .ra(rrow_n),
                .q(q_all[b*DW +: DW])
            );
        end
    endgenerate
    assign head = q_all[rlane*DW +: DW];

    always @(posedge clk) begin
        if (clear) begin
            wrow <= {AW{1'b0}};
            rrow <= {AW{1'b0}};
            wlane <= 2'd0;
            rlane <= 2'd0;
            count <= {LW{1'b0}};
            owed <= {LW{1'b0}};
            drops <= 32'd0;
        end else begin
            if (mark)
                owed <= count - {{(LW-1){1'b0}}, popped};
            else if (owed != {LW{1'b0}})
                owed <= owed - {{(LW-1){1'b0}}, popped};
            wlane <= lane_sum[1:0];
            if (lane_sum[2]) wrow <= wrow_next;
            rlane <= rlane_n;
            rrow <= rrow_n;
            count <= count + {{(LW-3){1'b0}}, acc} - {{(LW-1){1'b0}}, popped};
            if (drops > 32'hFFFF_FFFF - {29'd0, drop})
                drops <= 32'hFFFF_FFFF;
            else
                drops <= drops + {29'd0, drop};
        end
    end

    assign nonempty = count != {LW{1'b0}};
    wire [LW-1:0] held = count - owed;
    assign level = {{(16 - LW){1'b0}}, held};
    assign dropped = drops;
    assign dropping = drop != 3'd0;
    assign overrun = (n_w > free_p) && (free_p < free_l);

endmodule

`default_nettype wire
