// sc_stream: the stream engine of one camera channel (docs/STREAM_ENGINE.md), the RTL of the
// Rust model firmware/src/fabric/stream: it takes the point and Sobel FIFOs' snapshots, keeps
// every octave's last RING_ROWS Sobel rows, batches the points, cuts the rows into SobelRows
// segments or the 16x16 windows around the points into SobelPatch packets, adds FrameStart
// and FrameEnd, and frames them (sc_framer) on LINK_OUT as the camera's wire source.
//
// Snapshots: sc_fabric marks the FIFOs at the end of each line time and at the frame's end
// (snap_valid with the entries marked, snap_final at the end); the engine takes a snapshot's
// points first, in FIFO order, then its Sobel pixels: octave 0's into the ring as they come,
// the deeper octaves' into the stash, replayed octave by octave, so that rows complete in the
// model's order. Snapshots wait in a queue of SNAPS; one more is an overrun.
//
// The engine is sequential: one record, one ring pixel or one packet byte at a time. Its
// byte-for-byte equality with the model holds whatever its speed, as long as it keeps up with
// the datapath (no overrun): then the FIFOs drop what the model's drop (sc_out_fifo's owed
// entries). When it falls behind, the frame stops with STREAM_FAULT.OVERRUN set.
//
// The ring: one memory of 68 rows of W0 pixels (the model's STORE_ROWS), octave k's RING_ROWS
// slots at base_k = 32 (w_0 + .. + w_{k-1}). Slots are not cleared: a pixel's cell is written
// when it arrives, the cells a row skips (pixels the FIFO dropped) are written zero as the
// row goes on (gap) or when it completes (trail), so a complete row reads what the model's
// cleared-then-written slot holds. `has` marks the slots whose row received a pixel.
//
// Widths: point x, y < 2048; frame width <= W0 <= 2047; height <= 2047; counters 32 bits.
`default_nettype none

module sc_stream #(
    parameter W0 = 1280,                 // octave 0's widest line (the ring's row)
    parameter STASH = 3 * W0,            // Sobel entries of one snapshot (the FIFO's depth)
    parameter QUEUE = 512,               // points waiting for their patch (MAX_PENDING)
    parameter SNAPS = 4                  // snapshots waiting
) (
    input  wire         clk,
    input  wire         abort,           // rst or SOFT_RESET: the frame is abandoned
    input  wire         rst,             // power-up: the numbering restarts too
    // FRAME_ARM with STREAM_CONTROL.ENABLE: the registers of the frame.
    input  wire         arm,
    input  wire [15:0]  cfg_width,
    input  wire [15:0]  cfg_height,
    input  wire [2:0]   cfg_octaves,
    input  wire         cfg_patches,     // OUTPUT_MODE.SOBEL_OUTPUT = patches
    input  wire [1:0]   cfg_scale,       // OUTPUT_MODE.SOBEL_SCALE
    input  wire [7:0]   cfg_batch,       // OUTPUT_MODE.POINTS_PER_BATCH
    input  wire [10:0]  cfg_segment,     // OUTPUT_MODE.ROW_SEGMENT
    input  wire [31:0]  cfg_frame_id,
    input  wire [7:0]   cfg_camera,
    input  wire [63:0]  cfg_timestamp,
    input  wire         fec,             // STREAM_CONTROL.FEC (live: each link frame)
    // The FIFOs' drop counters (FrameEnd counts those since FRAME_ARM).
    input  wire [31:0]  drops_points,
    input  wire [31:0]  drops_sobel,
    input  wire         fifo_overrun,    // a FIFO refused an item for want of a spare slot
    // Snapshots.
    input  wire         snap_valid,
    input  wire [15:0]  snap_points,
    input  wire [15:0]  snap_sobel,
    input  wire         snap_final,
    // FIFO heads (valid from the clock after a push or pop) and pops.
    input  wire [87:0]  pf_head,         // {octave[1:0], dog, ds, dy, dx, y[10:0], x[10:0]}
    input  wire         pf_nonempty,
    output wire         pf_pop,
    input  wire [47:0]  sf_head,         // {octave[1:0], ori[5:0], mag[7:0], y, x}
    input  wire         sf_nonempty,
    output wire         sf_pop,
    // State.
    output wire         busy,            // a frame is being sent (FRAME_ARM .. FrameEnd)
    output reg  [31:0]  count_points,
    output reg  [31:0]  count_sobel,
    output reg  [31:0]  count_dropped,
    output reg  [1:0]   fault_cause,     // STREAM_FAULT.CAUSE: 1 Sobel order, 2 point outside
    output reg  [1:0]   fault_octave,
    output reg  [10:0]  fault_x,
    output reg  [10:0]  fault_y,
    output reg          fault_overrun,
    // LINK_OUT.
    output wire [7:0]   link_data,
    output wire         link_valid,
    input  wire         link_ready
);

    localparam RING = 68 * W0;
    localparam RA = $clog2(RING);
    localparam SA = $clog2(STASH);
    localparam QA = $clog2(QUEUE);
    localparam [15:0] HALF = 16'd8;

    // ---- states ----
    localparam [5:0]
        E_IDLE = 6'd0, E_RUN = 6'd1, E_PT = 6'd2, E_PT_CHECK = 6'd3, E_PT_PATCH = 6'd4,
        E_SB = 6'd5, E_RP_READ = 6'd6, E_RP_WAIT = 6'd7, E_RP_USE = 6'd8, E_SNAP_END = 6'd9,
        E_FL_OCT = 6'd10, E_FL_TRAIL = 6'd11, E_FL_NEXT = 6'd12, E_FL_BATCH = 6'd13,
        E_FL_END = 6'd14, E_DONE = 6'd15, E_DISCARD = 6'd16,
        // PUSH: one Sobel pixel into the ring.
        U_CHECK = 6'd20, U_TRAIL = 6'd21, U_OPEN = 6'd22, U_GAP = 6'd23, U_DONE = 6'd24,
        // COMPLETED: the rows first..end of octave co completed.
        C_ROW = 6'd28, C_SEG = 6'd29,
        // PASS: the waiting patches of pass_oct (or all) that are ready, in queue order.
        P_READ = 6'd32, P_WAIT = 6'd33, P_USE = 6'd34,
        // SEND_PATCH: patch pp_* if its top rows are held.
        S_CHECK = 6'd38,
        // TX: one packet into the framer.
        T_FIXED = 6'd40, T_FETCH = 6'd41, T_WAIT = 6'd42, T_ELEM = 6'd43;

    localparam [7:0] K_START = 8'h10, K_BATCH = 8'h11, K_ROWS = 8'h12, K_PATCH = 8'h13,
                     K_END = 8'h14;

    reg [5:0] st;
    reg [5:0] ret_push, ret_cmp, ret_pass, ret_sp, ret_tx;

    // ---- the frame ----
    reg [15:0] w [0:3];
    reg [15:0] h [0:3];
    reg [RA-1:0] base [0:3];
    reg [2:0]  octaves;
    reg        patches;
    reg [1:0]  scale;
    reg [7:0]  limit;                    // 1..128
    reg [10:0] segment;                  // >= 1
    reg [31:0] frame_id;
    reg [7:0]  camera;
    reg [63:0] timestamp;
    reg [31:0] drops_p0, drops_s0;       // the FIFOs' drops at FRAME_ARM
    reg        sending;                  // FRAME_ARM .. FrameEnd (or the fault's end)
    reg        faulted;
    // The wire source of camera `c` (1 + c; camera 255 shares 255 with camera 254).
    function [7:0] source_of(input [7:0] c);
        source_of = (c == 8'hFF) ? 8'hFF : c + 8'd1;
    endfunction
    wire [7:0] source = source_of(camera);
    reg [7:0]  seq_source;               // the source the numbering counts
    reg [15:0] seq;

    // ---- octave rows ----
    reg [15:0] next_row [0:3];
    reg        open [0:3];
    reg [15:0] nx [0:3];                 // the open row's next column to write
    reg [31:0] has [0:3];                // slot s's row received a pixel

    // ---- snapshot queue ----
    localparam QSW = $clog2(SNAPS);
    reg [32:0] snaps [0:SNAPS-1];        // {final, sobel, points}
    reg [QSW:0] sq_n;
    reg [QSW-1:0] sq_rd, sq_wr;
    reg [15:0] pts_left, sob_left;
    reg        snap_is_final;
    reg        final_seen;               // the frame's last snapshot has arrived

    // ---- records ----
    reg [1:0]  co;                       // octave of PUSH / COMPLETED / FLUSH
    reg [15:0] px_x, px_y;
    reg [13:0] px_val;                   // {ori, mag}
    reg [15:0] first, c_end, c_row;
    reg [15:0] seg_x;
    reg [87:0] pt;                       // the point being taken
    reg [31:0] pt_index;
    // Patch being sent (SEND_PATCH, TX of K_PATCH).
    reg [15:0] pp_index;
    reg [1:0]  pp_oct;
    reg [15:0] pp_x, pp_y;
    // PASS.
    reg [1:0]  pass_oct;
    reg        pass_all;
    reg [QA:0] q_n, q_r, q_w;
    // Stash and its replay.
    reg [SA:0] st_n, st_i;
    reg [1:0]  rp_oct;
    // Batch.
    reg [7:0]  b_n;
    // Flush.
    reg [2:0]  fk;

    // ---- memories (synchronous reads; the ring's ports are below) ----
    wire [13:0] ring_q;
    reg [47:0]  stash [0:STASH-1];
    reg [47:0]  stash_q;
    reg [49:0]  queue [0:QUEUE-1];       // {index[15:0], octave[1:0], y[15:0], x[15:0]}
    reg [49:0]  queue_q;
    reg [111:0] batch [0:127];           // the wire point record, little-endian bytes
    reg [111:0] batch_q;

    // ---- ring addressing: slot of `row` (its low 5 bits) in an octave at `b`, `wk` wide ----
    /* verilator lint_off UNUSEDSIGNAL */
    function [RA-1:0] ring_addr(input [RA-1:0] b, input [15:0] wk, input [15:0] row,
                                input [15:0] x);
        reg [31:0] a;
        begin
            a = {{(32-RA){1'b0}}, b} + {27'd0, row[4:0]} * {16'd0, wk} + {16'd0, x};
            ring_addr = a[RA-1:0];
        end
    endfunction
    /* verilator lint_on UNUSEDSIGNAL */

    // Rows first..=last (at most 32 apart) as a slot mask; all slots when 32 or more.
    function [31:0] slot_mask(input [15:0] from, input [15:0] last);
        integer s;
        reg [15:0] d;
        begin
            d = last - from;
            for (s = 0; s < 32; s = s + 1)
                slot_mask[s] = (d >= 16'd31) || ((s[4:0] - from[4:0]) <= d[4:0]);
        end
    endfunction

    // The oldest complete row octave k still holds.
    function [15:0] oldest(input [15:0] next, input o);
        reg [16:0] t;
        begin
            t = {1'b0, next} + {16'd0, o};
            oldest = (t > 17'd32) ? t[15:0] - 16'd32 : 16'd0;
        end
    endfunction

    wire [15:0] co_old = oldest(next_row[co], open[co]);
    wire [15:0] pp_old = oldest(next_row[pp_oct], open[pp_oct]);
    wire [15:0] pp_top = (pp_y > HALF) ? pp_y - HALF : 16'd0;

    // ---- TX: the packet being formed ----
    reg [7:0]  tx_kind;
    reg [15:0] tx_len;                   // payload bytes
    reg [15:0] tx_i;                     // byte of the packet (header included)
    reg [15:0] tx_e;                     // element (point record or pixel)
    reg [3:0]  tx_j;                     // byte within the element
    reg [111:0] tx_el;                   // the element's bytes
    reg [15:0] tx_count;                 // elements
    reg [15:0] tx_row, tx_x;             // SobelRows: row and first column; patch: x, y
    wire [15:0] tx_elem0 = (tx_kind == K_BATCH) ? 16'd14 : 16'd20;  // 7 + payload offset
    wire [3:0]  tx_esize = (tx_kind == K_BATCH) ? 4'd14 : 4'd2;
    wire [15:0] tx_total = tx_len + 16'd7;

    wire [31:0] ov_p = drops_points - drops_p0;
    wire [31:0] ov_s = drops_sobel - drops_s0;
    wire [32:0] ds_sum = {1'b0, ov_s} + {1'b0, count_dropped};
    wire [31:0] dropped_sobel = ds_sum[32] ? 32'hFFFF_FFFF : ds_sum[31:0];
    wire [7:0]  end_flags = {6'd0, dropped_sobel != 32'd0, ov_p != 32'd0};

    // Byte `i` of the packet outside its elements.
    function [7:0] pick(input [63:0] v, input [2:0] b);
        pick = v[b*8 +: 8];
    endfunction

    reg [7:0] fixed_byte;
    always @(*) begin
        fixed_byte = 8'd0;
        case (tx_i)
            16'd0: fixed_byte = 8'd3;
            16'd1: fixed_byte = tx_kind;
            16'd2: fixed_byte = source;
            16'd3: fixed_byte = seq[7:0];
            16'd4: fixed_byte = seq[15:8];
            16'd5: fixed_byte = tx_len[7:0];
            16'd6: fixed_byte = tx_len[15:8];
            16'd7, 16'd8, 16'd9, 16'd10: fixed_byte = pick({32'd0, frame_id}, tx_i[2:0] - 3'd7);
            16'd11: fixed_byte = camera;
            default: begin
                case (tx_kind)
                    K_START: case (tx_i)
                        16'd12: fixed_byte = w[0][7:0];
                        16'd13: fixed_byte = w[0][15:8];
                        16'd14: fixed_byte = h[0][7:0];
                        16'd15: fixed_byte = h[0][15:8];
                        16'd16: fixed_byte = {5'd0, octaves};
                        default: fixed_byte = pick(timestamp, tx_i[2:0] - 3'd1);  // 17..24
                    endcase
                    K_BATCH: case (tx_i)
                        16'd12: fixed_byte = tx_count[7:0];
                        default: fixed_byte = 8'd0;                               // 13
                    endcase
                    K_ROWS: case (tx_i)
                        16'd12: fixed_byte = {6'd0, co};
                        16'd13: fixed_byte = {6'd0, scale};
                        16'd14: fixed_byte = tx_row[7:0];
                        16'd15: fixed_byte = tx_row[15:8];
                        16'd16: fixed_byte = tx_x[7:0];
                        16'd17: fixed_byte = tx_x[15:8];
                        16'd18: fixed_byte = tx_count[7:0];
                        default: fixed_byte = tx_count[15:8];                     // 19
                    endcase
                    K_PATCH: case (tx_i)
                        16'd12: fixed_byte = pp_index[7:0];
                        16'd13: fixed_byte = pp_index[15:8];
                        16'd14: fixed_byte = {6'd0, pp_oct};
                        16'd15: fixed_byte = {6'd0, scale};
                        16'd16: fixed_byte = pp_x[7:0];
                        16'd17: fixed_byte = pp_x[15:8];
                        16'd18: fixed_byte = pp_y[7:0];
                        default: fixed_byte = pp_y[15:8];                         // 19
                    endcase
                    default: case (tx_i)                                          // K_END
                        16'd12, 16'd13, 16'd14, 16'd15:
                            fixed_byte = pick({32'd0, count_points}, tx_i[2:0] - 3'd4);
                        16'd16, 16'd17, 16'd18, 16'd19:
                            fixed_byte = pick({32'd0, count_sobel}, tx_i[2:0]);
                        16'd20: fixed_byte = end_flags;
                        16'd21, 16'd22, 16'd23, 16'd24:
                            fixed_byte = pick({32'd0, ov_p}, tx_i[2:0] - 3'd5);
                        default:                                                  // 25..28
                            fixed_byte = pick({32'd0, dropped_sobel}, tx_i[2:0] - 3'd1);
                    endcase
                endcase
            end
        endcase
    end

    // ---- the framer ----
    wire       fr_ready;
    wire       in_elem = (st == T_ELEM);
    wire       fr_valid = (st == T_FIXED) || in_elem;
    wire [7:0] fr_data = in_elem ? tx_el[tx_j*8 +: 8] : fixed_byte;
    wire       fr_last = tx_i + 16'd1 == tx_total;
    wire       fr_take = fr_valid && fr_ready;

    sc_framer u_framer (
        .clk(clk), .rst(abort), .fec(fec),
        .in_data(fr_data), .in_valid(fr_valid), .in_last(fr_last), .in_ready(fr_ready),
        .out_data(link_data), .out_valid(link_valid), .out_ready(link_ready)
    );

    // ---- patch pixel (tx_e = dy * 16 + dx) for the fetch ----
    wire [15:0] pw_y = pp_y - HALF + {12'd0, tx_e[7:4]};     // wraps when above the image
    wire [15:0] pw_x = pp_x - HALF + {12'd0, tx_e[3:0]};
    wire        pw_in = (pp_y + {12'd0, tx_e[7:4]} >= HALF) && (pp_x + {12'd0, tx_e[3:0]} >= HALF)
                     && pw_x < w[pp_oct] && pw_y < h[pp_oct]
                     && pw_y >= pp_old && pw_y < next_row[pp_oct] && has[pp_oct][pw_y[4:0]];
    reg         pw_in_d;

    // ---- the memories' ports ----
    reg          ring_we;
    reg [RA-1:0] ring_wa;
    reg [13:0]   ring_wd;
    reg [RA-1:0] ring_ra;
    always @(*) begin
        ring_we = 1'b0;
        ring_wa = ring_addr(base[co], w[co], next_row[co], nx[co]);
        ring_wd = 14'd0;
        if (st == U_TRAIL || st == E_FL_TRAIL) begin
            ring_we = nx[co] < w[co];
        end else if (st == U_GAP) begin
            ring_wa = ring_addr(base[co], w[co], px_y, (nx[co] < px_x) ? nx[co] : px_x);
            ring_we = 1'b1;
            ring_wd = (nx[co] < px_x) ? 14'd0 : px_val;
        end
        if (tx_kind == K_PATCH)
            ring_ra = ring_addr(base[pp_oct], w[pp_oct], pw_y, pw_x);
        else
            ring_ra = ring_addr(base[co], w[co], tx_row, tx_x + tx_e);
    end

    sc_ram #(.DW(14), .DEPTH(RING), .AW(RA)) ring (
        .clk(clk), .we(ring_we), .wa(ring_wa), .wd(ring_wd), .re(1'b1), .ra(ring_ra), .q(ring_q)
    );

    always @(posedge clk) begin
        stash_q <= stash[st_i[SA-1:0]];
        queue_q <= queue[q_r[QA-1:0]];
        batch_q <= batch[tx_e[6:0]];
    end

    // ---- pops ----
    assign pf_pop = (st == E_PT && pts_left != 16'd0)
                 || (st == E_DISCARD && pf_nonempty);
    assign sf_pop = (st == E_SB && sob_left != 16'd0)
                 || (st == E_DISCARD && sf_nonempty);
    assign busy = sending;

    // The point taken: {octave[1:0], dog, ds, dy, dx, y[10:0], x[10:0]}.
    wire [1:0]  pt_oct = pt[87:86];
    wire [15:0] pt_x = {5'd0, pt[10:0]};
    wire [15:0] pt_y = {5'd0, pt[21:11]};
    wire        pt_outside = {1'b0, pt_oct} >= octaves || pt_x >= w[pt_oct] || pt_y >= h[pt_oct];
    wire [16:0] pt_need17 = {1'b0, pt_y} + {1'b0, HALF};
    wire [15:0] pt_need = (pt_need17 > {1'b0, h[pt_oct]}) ? h[pt_oct] : pt_need17[15:0];

    // The queue entry read: {index, octave, y, x}.
    wire [1:0]  q_oct = queue_q[33:32];
    wire [15:0] q_y = queue_q[31:16];
    wire [16:0] q_need17 = {1'b0, q_y} + {1'b0, HALF};
    wire [15:0] q_need = (q_need17 > {1'b0, h[q_oct]}) ? h[q_oct] : q_need17[15:0];
    wire        q_ready = pass_all || (q_oct == pass_oct && next_row[pass_oct] >= q_need);

    // The Sobel entry's fields (the FIFO head, or the stash's).
    wire [47:0] sb_e = (st == E_SB) ? sf_head : stash_q;
    wire        px_bad = {1'b0, co} >= octaves || px_x >= w[co] || px_y >= h[co]
                      || px_y < next_row[co];

    // Octave dims: ceil(n / 2^k).
    function [15:0] cdiv(input [15:0] n, input [1:0] sh);
        reg [15:0] m;
        begin
            m = (16'd1 << sh) - 16'd1;
            cdiv = (n >> sh) + {15'd0, (n & m) != 16'd0};
        end
    endfunction

    // A snapshot with no entries changes nothing (the model's take of empty FIFOs): only the
    // others and the last one wait in the queue.
    wire snap_queued = sending && snap_valid
                    && (snap_final || snap_points != 16'd0 || snap_sobel != 16'd0);

    // Octave k's first slot: RING_ROWS rows of each octave before it (< 68 W0: RA bits).
    /* verilator lint_off UNUSEDSIGNAL */
    wire [31:0] b1 = {16'd0, cfg_width} << 5;
    wire [31:0] b2 = b1 + ({16'd0, cdiv(cfg_width, 2'd1)} << 5);
    wire [31:0] b3 = b2 + ({16'd0, cdiv(cfg_width, 2'd2)} << 5);
    /* verilator lint_on UNUSEDSIGNAL */

    function [31:0] sat_inc(input [31:0] v);
        sat_inc = (v == 32'hFFFF_FFFF) ? v : v + 32'd1;
    endfunction

    // What FRAME_ARM and an abort both zero: the fault, the counters, the snapshot queue.
    task clear_frame;
        begin
            faulted <= 1'b0;
            sq_n <= 0;
            sq_rd <= 0;
            sq_wr <= 0;
            count_points <= 32'd0;
            count_sobel <= 32'd0;
            count_dropped <= 32'd0;
            fault_cause <= 2'd0;
            fault_octave <= 2'd0;
            fault_x <= 11'd0;
            fault_y <= 11'd0;
            fault_overrun <= 1'b0;
        end
    endtask

    integer i;
    always @(posedge clk) begin
        if (abort) begin
            st <= E_IDLE;
            sending <= 1'b0;
            clear_frame();
            if (rst) begin
                seq <= 16'd0;
                seq_source <= 8'd1;
            end
        end else begin
            // Snapshots queue whatever the engine does; one too many is an overrun.
            if (sending && snap_valid && snap_final) final_seen <= 1'b1;
            if (snap_queued) begin
                if (sq_n == SNAPS[QSW:0]) begin
                    fault_overrun <= 1'b1;
                    faulted <= 1'b1;
                end else begin
                    snaps[sq_wr] <= {snap_final, snap_sobel, snap_points};
                    sq_wr <= sq_wr + 1'b1;
                end
            end
            if (sending && fifo_overrun) begin
                fault_overrun <= 1'b1;
                faulted <= 1'b1;
            end
            // The snapshot queue's count: one in, one out (FRAME_ARM, below, empties it).
            sq_n <= sq_n + {{QSW{1'b0}}, snap_queued && sq_n != SNAPS[QSW:0]}
                 - {{QSW{1'b0}}, ((st == E_RUN && !faulted) || st == E_DISCARD) && sq_n != 0};

            case (st)
            E_IDLE: if (arm) begin
                for (i = 0; i < 4; i = i + 1) begin
                    w[i] <= cdiv(cfg_width, i[1:0]);
                    h[i] <= cdiv(cfg_height, i[1:0]);
                    next_row[i] <= 16'd0;
                    open[i] <= 1'b0;
                    nx[i] <= 16'd0;
                    has[i] <= 32'd0;
                end
                base[0] <= {RA{1'b0}};
                base[1] <= b1[RA-1:0];
                base[2] <= b2[RA-1:0];
                base[3] <= b3[RA-1:0];
                octaves <= cfg_octaves;
                patches <= cfg_patches;
                scale <= cfg_scale;
                limit <= (cfg_batch == 8'd0) ? 8'd1 : (cfg_batch > 8'd128) ? 8'd128 : cfg_batch;
                segment <= (cfg_segment == 11'd0) ? 11'd1 : cfg_segment;
                frame_id <= cfg_frame_id;
                camera <= cfg_camera;
                timestamp <= cfg_timestamp;
                drops_p0 <= drops_points;
                drops_s0 <= drops_sobel;
                if (source_of(cfg_camera) != seq_source) begin
                    seq_source <= source_of(cfg_camera);
                    seq <= 16'd0;
                end
                sending <= 1'b1;
                clear_frame();
                snap_is_final <= 1'b0;
                final_seen <= 1'b0;
                q_n <= 0;
                b_n <= 8'd0;
                st_n <= 0;
                tx_kind <= K_START;
                tx_len <= 16'd18;
                tx_i <= 16'd0;
                ret_tx <= E_RUN;
                st <= T_FIXED;
            end

            // ---- snapshots ----
            E_RUN: if (faulted) begin
                st <= E_DISCARD;
            end else if (sq_n != 0) begin
                {snap_is_final, sob_left, pts_left} <= snaps[sq_rd];
                sq_rd <= sq_rd + 1'b1;
                st <= E_PT;
            end
            E_DISCARD: begin
                // After a fault: everything is popped and dropped, up to the frame's end (its
                // last snapshot may have found the queue full).
                if (sq_n != 0) sq_rd <= sq_rd + 1'b1;
                if (final_seen && sq_n == 0 && !pf_nonempty && !sf_nonempty) st <= E_DONE;
            end
            E_PT: if (pts_left == 16'd0) begin
                st <= E_SB;
            end else begin
                pts_left <= pts_left - 16'd1;
                pt <= pf_head;
                st <= faulted ? E_PT : E_PT_CHECK;
            end
            E_PT_CHECK: if (pt_outside) begin
                faulted <= 1'b1;
                fault_cause <= 2'd2;
                fault_octave <= pt_oct;
                fault_x <= pt_x[10:0];
                fault_y <= pt_y[10:0];
                st <= E_PT;
            end else begin
                batch[b_n[6:0]] <= {pt[85:22], 8'd1, 6'd0, pt_oct, pt_y, pt_x};
                b_n <= b_n + 8'd1;
                pt_index <= count_points;
                count_points <= sat_inc(count_points);
                if (b_n + 8'd1 >= limit) begin
                    tx_kind <= K_BATCH;
                    tx_len <= 16'd7 + 16'd14 * {8'd0, b_n + 8'd1};
                    tx_count <= {8'd0, b_n + 8'd1};
                    tx_i <= 16'd0;
                    ret_tx <= E_PT_PATCH;
                    st <= T_FIXED;
                end else begin
                    st <= E_PT_PATCH;
                end
            end
            E_PT_PATCH: begin
                st <= E_PT;
                if (patches) begin
                    if (pt_index > 32'd65535) begin
                        count_dropped <= sat_inc(count_dropped);
                    end else if (next_row[pt_oct] >= pt_need) begin
                        pp_index <= pt_index[15:0];
                        pp_oct <= pt_oct;
                        pp_x <= pt_x;
                        pp_y <= pt_y;
                        ret_sp <= E_PT;
                        st <= S_CHECK;
                    end else if (q_n != QUEUE[QA:0]) begin
                        queue[q_n[QA-1:0]] <= {pt_index[15:0], pt_oct, pt_y, pt_x};
                        q_n <= q_n + 1'b1;
                    end else begin
                        count_dropped <= sat_inc(count_dropped);
                    end
                end
            end
            E_SB: if (sob_left == 16'd0) begin
                st_i <= 0;
                rp_oct <= 2'd1;
                st <= E_RP_READ;
            end else begin
                sob_left <= sob_left - 16'd1;
                if (!faulted) begin
                    if (sf_head[47:46] == 2'd0) begin
                        co <= 2'd0;
                        px_x <= sb_e[15:0];
                        px_y <= sb_e[31:16];
                        px_val <= sb_e[45:32];
                        ret_push <= E_SB;
                        st <= U_CHECK;
                    end else begin
                        stash[st_n[SA-1:0]] <= sf_head;
                        st_n <= st_n + 1'b1;
                    end
                end
            end
            E_RP_READ: if (st_i == st_n) begin
                st_i <= 0;
                if (rp_oct == 2'd3) st <= E_SNAP_END;
                rp_oct <= rp_oct + 2'd1;
            end else begin
                st <= E_RP_WAIT;                // stash_q <= stash[st_i] at this edge
            end
            E_RP_WAIT: st <= E_RP_USE;
            E_RP_USE: begin
                st_i <= st_i + 1'b1;
                st <= E_RP_READ;
                if (!faulted && sb_e[47:46] == rp_oct) begin
                    co <= rp_oct;
                    px_x <= sb_e[15:0];
                    px_y <= sb_e[31:16];
                    px_val <= sb_e[45:32];
                    ret_push <= E_RP_READ;
                    st <= U_CHECK;
                end
            end
            E_SNAP_END: begin
                st_n <= 0;
                st <= snap_is_final ? (faulted ? E_DONE : E_FL_OCT) : E_RUN;
                fk <= 3'd0;
            end

            // ---- PUSH ----
            U_CHECK: if (px_bad) begin
                faulted <= 1'b1;
                fault_cause <= 2'd1;
                fault_octave <= co;
                fault_x <= px_x[10:0];
                fault_y <= px_y[10:0];
                st <= ret_push;
            end else begin
                first <= next_row[co];
                if (px_y > next_row[co] || !open[co])
                    st <= open[co] ? U_TRAIL : U_OPEN;
                else
                    st <= U_GAP;
            end
            U_TRAIL: if (nx[co] < w[co]) nx[co] <= nx[co] + 16'd1;
                     else st <= U_OPEN;
            U_OPEN: begin
                has[co] <= has[co] & ~slot_mask(open[co] ? next_row[co] + 16'd1 : next_row[co],
                                                px_y);
                nx[co] <= 16'd0;
                st <= U_GAP;
            end
            U_GAP: if (nx[co] < px_x) begin
                nx[co] <= nx[co] + 16'd1;
            end else begin
                has[co][px_y[4:0]] <= 1'b1;
                if (px_x + 16'd1 > nx[co]) nx[co] <= px_x + 16'd1;
                st <= U_DONE;
            end
            U_DONE: begin
                if (px_x + 16'd1 == w[co]) begin
                    next_row[co] <= px_y + 16'd1;
                    open[co] <= 1'b0;
                    c_end <= px_y + 16'd1;
                end else begin
                    next_row[co] <= px_y;
                    open[co] <= 1'b1;
                    c_end <= px_y;
                end
                c_row <= first;
                ret_cmp <= ret_push;
                if ((px_x + 16'd1 == w[co] ? px_y + 16'd1 : px_y) > first)
                    st <= patches ? P_READ : C_ROW;
                else
                    st <= ret_push;
                pass_oct <= co;
                pass_all <= 1'b0;
                q_r <= 0;
                q_w <= 0;
                ret_pass <= ret_push;
            end

            // ---- COMPLETED, rows mode: rows c_row..c_end of octave co ----
            C_ROW: if (c_row == c_end) begin
                st <= ret_cmp;
            end else if (c_row >= co_old && c_row < next_row[co] && has[co][c_row[4:0]]) begin
                seg_x <= 16'd0;
                st <= C_SEG;
            end else begin
                c_row <= c_row + 16'd1;
            end
            C_SEG: if (seg_x >= w[co]) begin
                c_row <= c_row + 16'd1;
                st <= C_ROW;
            end else begin
                tx_kind <= K_ROWS;
                tx_row <= c_row;
                tx_x <= seg_x;
                tx_count <= (w[co] - seg_x < {5'd0, segment}) ? w[co] - seg_x : {5'd0, segment};
                tx_len <= 16'd13 + 16'd2 * ((w[co] - seg_x < {5'd0, segment})
                                            ? w[co] - seg_x : {5'd0, segment});
                tx_i <= 16'd0;
                seg_x <= seg_x + {5'd0, segment};
                count_sobel <= sat_inc(count_sobel);
                ret_tx <= C_SEG;
                st <= T_FIXED;
            end

            // ---- PASS over the waiting patches ----
            P_READ: if (q_r == q_n) begin
                q_n <= q_w;
                st <= ret_pass;
            end else begin
                st <= P_WAIT;                   // queue_q <= queue[q_r] at this edge
            end
            P_WAIT: st <= P_USE;
            P_USE: begin
                q_r <= q_r + 1'b1;
                if (q_ready) begin
                    pp_index <= queue_q[49:34];
                    pp_oct <= q_oct;
                    pp_x <= queue_q[15:0];
                    pp_y <= q_y;
                    ret_sp <= P_READ;
                    st <= S_CHECK;
                end else begin
                    queue[q_w[QA-1:0]] <= queue_q;
                    q_w <= q_w + 1'b1;
                    st <= P_READ;
                end
            end

            // ---- SEND_PATCH ----
            S_CHECK: if (pp_top >= pp_old && pp_top < h[pp_oct]) begin
                tx_kind <= K_PATCH;
                tx_len <= 16'd525;
                tx_count <= 16'd256;
                tx_i <= 16'd0;
                count_sobel <= sat_inc(count_sobel);
                ret_tx <= ret_sp;
                st <= T_FIXED;
            end else begin
                count_dropped <= sat_inc(count_dropped);
                st <= ret_sp;
            end

            // ---- FLUSH: the frame's end ----
            E_FL_OCT: if ({1'b0, fk} >= {1'b0, octaves} || fk == 3'd4) begin
                pass_all <= 1'b1;
                q_r <= 0;
                q_w <= 0;
                ret_pass <= E_FL_BATCH;
                st <= P_READ;
            end else begin
                co <= fk[1:0];
                st <= open[fk[1:0]] ? E_FL_TRAIL : E_FL_NEXT;
            end
            E_FL_TRAIL: if (nx[co] < w[co]) begin
                nx[co] <= nx[co] + 16'd1;
            end else begin
                next_row[co] <= next_row[co] + 16'd1;
                open[co] <= 1'b0;
                c_row <= next_row[co];
                c_end <= next_row[co] + 16'd1;
                ret_cmp <= E_FL_NEXT;
                pass_oct <= co;
                pass_all <= 1'b0;
                q_r <= 0;
                q_w <= 0;
                ret_pass <= E_FL_NEXT;
                st <= patches ? P_READ : C_ROW;
            end
            E_FL_NEXT: begin
                fk <= fk + 3'd1;
                st <= E_FL_OCT;
            end
            E_FL_BATCH: if (b_n != 8'd0) begin
                tx_kind <= K_BATCH;
                tx_len <= 16'd7 + 16'd14 * {8'd0, b_n};
                tx_count <= {8'd0, b_n};
                tx_i <= 16'd0;
                ret_tx <= E_FL_END;
                st <= T_FIXED;
            end else begin
                st <= E_FL_END;
            end
            E_FL_END: if (faulted) begin
                st <= E_DONE;
            end else begin
                tx_kind <= K_END;
                tx_len <= 16'd22;
                tx_i <= 16'd0;
                ret_tx <= E_DONE;
                st <= T_FIXED;
            end
            E_DONE: if (fr_ready && !link_valid) begin
                // The framer has sent the last link frame's delimiter.
                sending <= 1'b0;
                st <= E_IDLE;
            end

            // ---- TX ----
            T_FIXED: if (fr_take) begin
                tx_i <= tx_i + 16'd1;
                if (fr_last) begin
                    seq <= seq + 16'd1;
                    if (tx_kind == K_BATCH) b_n <= 8'd0;
                    st <= ret_tx;
                end else if (tx_i + 16'd1 == tx_elem0 && tx_kind != K_START
                             && tx_kind != K_END) begin
                    tx_e <= 16'd0;
                    st <= T_FETCH;
                end
            end
            T_FETCH: begin
                pw_in_d <= pw_in;
                st <= T_WAIT;                   // ring_q / batch_q <= element tx_e
            end
            T_WAIT: begin
                tx_j <= 4'd0;
                if (tx_kind == K_BATCH)
                    tx_el <= batch_q;
                else if (tx_kind == K_PATCH)
                    tx_el <= {96'd0, pw_in_d ? {2'd0, ring_q} : 16'd0};
                else
                    tx_el <= {96'd0, 2'd0, ring_q};
                st <= T_ELEM;
            end
            T_ELEM: if (fr_take) begin
                tx_i <= tx_i + 16'd1;
                tx_j <= tx_j + 4'd1;
                if (fr_last) begin
                    seq <= seq + 16'd1;
                    if (tx_kind == K_BATCH) b_n <= 8'd0;
                    st <= ret_tx;
                end else if (tx_j + 4'd1 == tx_esize) begin
                    tx_e <= tx_e + 16'd1;
                    st <= T_FETCH;
                end
            end
            default: st <= E_IDLE;
            endcase

        end
    end

endmodule

`default_nettype wire
