// sc_fabric: the fabric of one camera channel, behind its AXI4-lite slave: the generated
// register block (sc_regs), the 4-octave datapath (sc_frontend), the point FIFO (512 entries)
// and the Sobel FIFO (3 x W0 entries, as the model's OutputFifos), the frame control and the
// counters of the register map (hdl-interface/regmap.toml, version 2.2), and the stream
// engine (sc_stream, docs/STREAM_ENGINE.md) sending the frame's packets on LINK_OUT.
//
// Clocks: the datapath advances only on clocks where `pix_ce` is 1 (the camera's pixel
// clock as an enable of the fabric's clock); the registers, the FIFOs' pops and the engine
// work on every clock. With `pix_ce` always 1 every clock is a pixel clock, the contract the
// device model's FabricDevice::clock keeps.
//
// Bus: sc_regs' simple synchronous bus (bus_we / bus_re one-clock strobes, registered
// bus_rdata); a standard AXI4-lite front end drives it and `rst` (from !ARESETN).
//
// Frame control (CONTROL, STATUS):
// - CONTROL's strobes are sc_regs' `wo` outputs: high on the clock after the write, when they
//   act (at that clock's edge). What a read on that clock shows is made to agree with what the
//   write asked for, so a driver may read on the very next clock: STATUS.BUSY is 1 from the
//   clock after an accepted FRAME_ARM (BUSY = the frame state or the arm acting now), and
//   everything SOFT_RESET clears reads cleared from the clock after its write (all but the
//   sticky flags, below). The device model's clock-exact entry point (FabricDevice::clock)
//   is this contract, compared read for read by tests/tests/rtl_fabric_contract.rs.
// - FRAME_ARM (ignored while BUSY) starts sc_frontend (its `start`: the configuration
//   registers WIDTH, HEIGHT, OCTAVES, CONTRAST_THRESHOLD, EDGE_THRESHOLD.R,
//   OUTPUT_MODE.SOBEL_SCALE and MAX_OFFSET are latched) and raises BUSY. The driver validates
//   the configuration before writing it (FabricConfig::validate; the model's Config::validate
//   on width <= W0 and the last octave >= 3 x 3): the RTL does not check it again.
// - From the clock after the strobe's PIXEL_IN is ready while CONTROL.ENABLE is 1. Pixels before the first
//   one with SOF are taken and discarded; the SOF pixel is pixel (0, 0), and the frame is the
//   next WIDTH x HEIGHT pixels taken (SOF/EOL inside the frame are not checked). Each taken
//   pixel is one `clock(Some(p))` of the model; every other clock is `clock(None)`.
// - After the last pixel PIXEL_IN is not ready until sc_frontend's `done` (every configured
//   octave has emitted everything into the FIFOs): BUSY falls, STATUS.FRAME_DONE is set and
//   FRAME_COUNT counts the frame. With STREAM_CONTROL.ENABLE latched at FRAME_ARM that
//   happens when the stream engine has sent FrameEnd (state S_SEND until then).
// - Stream engine: the clock that feeds a line's last pixel, and every WIDTH pixel clocks of
//   the flush after it, end a line time; on the next clock both FIFOs are marked and their
//   entries are the engine's next snapshot (sc_out_fifo's owed entries); `done` marks the
//   last one. While the engine sends a frame the FIFOs are its own: POINT_FIFO_DATA and
//   SOBEL_FIFO_DATA read 0 and pop nothing.
// - SOFT_RESET empties both FIFOs, returns to idle, restarts sc_frontend (clearing its valid
//   bits), clears the STATUS flags, the overflow counters, FRAME_COUNT, LATENCY_CLOCKS and the
//   holding registers. Configuration registers keep their values. On the strobe's clock the
//   levels, counters, LATENCY_CLOCKS, FIFO heads (VALID 0; the pop is ignored), holding
//   registers and BUSY already read their cleared values; only STATUS's sticky flags, which
//   sc_regs holds, still read their old values on that one clock.
//
// FIFO entries, and arbitration between octaves: the four octaves may each push a point and a
// Sobel pixel on the same clock. Both FIFOs take up to 4 entries per clock in octave order
// o0, o1, o2, o3, the order in which the model's RegisterFrontEnd::clock pushes them (octave
// k's items are pushed inside octave k's clock, octave 0 first), so the FIFO contents and the
// overflow counts equal the model's entry for entry: each FIFO is an sc_out_fifo, 4 banks
// interleaved by slot (no skid buffer, no stall; the datapath has no back-pressure, as the
// model; its header has the layout). A pop on the same clock as pushes frees its slot for
// the next clock (the model's driver pops between clocks). POINT_OVERFLOW / SOBEL_OVERFLOW
// are set on a clock that dropped an entry.
//
// Reads: POINT_FIFO_DATA shows the head (VALID = level != 0; the whole word reads 0 when the
// FIFO is empty, SCALE = 1 otherwise); its read pops the head and loads the point's DX/DY and
// DS/DOG into the holding registers POINT_FIFO_DXDY / POINT_FIFO_DSDOG (zero when the FIFO
// was empty). SOBEL_FIFO_DATA likewise with SOBEL_FIFO_POSITION.
//
// LATENCY_CLOCKS: clocks from the frame's first pixel (clock 0) to the clock on which octave
// OCTAVES - 1 takes its first input sample (the model's first_input_clock(OCTAVES - 1):
// sc_frontend's sub_valid[OCTAVES - 2] while oct_en[OCTAVES - 2], or the first pixel itself
// with one octave), stored when it happens; it keeps the last frame's value until then.
//
// Widths: FIFO levels fit 16 bits (POINT_DEPTH, SOBEL_DEPTH <= 65535); point x < 2048 and
// y < 2048 (11 bits in POINT_FIFO_DATA; W0 <= 2047, the map's max_height 1024); counters 32
// bits; width * height < 2^32.
`default_nettype none

module sc_fabric #(
    parameter W0 = 1280,                 // line memories of octave k: Wk (sc_frontend)
    parameter W1 = 640,
    parameter W2 = 320,
    parameter W3 = 160,
    parameter POINT_DEPTH = 512,         // point_fifo_depth; a multiple of 4
    parameter SOBEL_DEPTH = 3 * W0       // sobel_fifo_depth = 3 x max_width; a multiple of 4
) (
    input  wire        clk,
    input  wire        rst,              // synchronous, active high (from !ARESETN)
    // Register bus (sc_regs): the AXI4-lite front end's side.
    input  wire [7:0]  bus_addr,
    input  wire [31:0] bus_wdata,
    input  wire        bus_we,
    input  wire        bus_re,
    output wire [31:0] bus_rdata,
    // PIXEL_IN (AXI4-stream rules).
    input  wire [7:0]  pixel_in_data,
    input  wire        pixel_in_valid,
    output wire        pixel_in_ready,
    input  wire        pix_ce,           // pixel-clock enable: the datapath advances only now
    input  wire        pixel_in_sof,
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire        pixel_in_eol,     // not checked: lines are counted by WIDTH
    /* verilator lint_on UNUSEDSIGNAL */
    // LINK_OUT (AXI4-stream rules): the stream engine's link frames.
    output wire [7:0]  link_out_data,
    output wire        link_out_valid,
    input  wire        link_out_ready
);

    // ---------------------------------------------------------------------------------------
    // Register block.
    wire        control_enable, control_frame_arm, control_soft_reset;
    wire        status_frame_done, status_point_overflow, status_sobel_overflow;
    wire [15:0] width_value, height_value, contrast_threshold_value, max_offset_value;
    wire [2:0]  octaves_count;
    wire [4:0]  edge_threshold_r;
    wire [1:0]  output_mode_sobel_scale;
    wire        point_fifo_data_pop, sobel_fifo_data_pop;

    wire        busy;
    wire        busy_shown;           // STATUS.BUSY
    wire        frame_end;            // BUSY falls on this clock
    wire        soft_reset = control_soft_reset;
    reg  [31:0] frame_count;
    reg  [31:0] latency;
    reg  [31:0] hold_dxdy, hold_dsdog, hold_position;

    // OUTPUT_MODE's packing fields (SOBEL_OUTPUT, POINTS_PER_BATCH, ROW_SEGMENT) are the stream
    // engine's; the sticky flags' values are not used by the fabric.
    wire        output_mode_sobel_output;
    wire [7:0]  output_mode_points_per_batch;
    wire [10:0] output_mode_row_segment;

    // The stream engine's registers (docs/STREAM_ENGINE.md) and its state.
    wire        stream_control_enable, stream_control_fec;
    wire [7:0]  stream_control_camera;
    wire [31:0] frame_id_value, timestamp_lo_value, timestamp_hi_value;
    wire [31:0] eng_points, eng_sobel, eng_dropped;
    wire [1:0]  eng_cause, eng_octave;
    wire [10:0] eng_fx, eng_fy;
    wire        eng_overrun;
    wire        snap_mark;            // the FIFOs' entries become the engine's snapshot

    wire        eng_busy;             // the stream engine sends a frame
    // Point entry: {octave[1:0], dog, ds, dy, dx (16 bits each), y[10:0], x[10:0]} (88 bits);
    // Sobel entry: {octave[1:0], ori[5:0], mag[7:0], y[15:0], x[15:0]} (48 bits).
    wire [87:0] pf_head;
    wire [47:0] sf_head;
    wire        pf_nonempty, sf_nonempty;
    // What the registers show: on SOFT_RESET's clock, the values it clears (shown = 0).
    wire        shown = !soft_reset;
    // What word 0 shows: the head, or all zero when the FIFO is empty.
    // While the stream engine sends a frame the FIFOs are its own: their words read 0.
    wire        bus_owns = !eng_busy;
    wire        pf_valid = pf_nonempty && shown && bus_owns;
    wire        sf_valid = sf_nonempty && shown && bus_owns;
    wire [87:0] pf_shown = pf_valid ? pf_head : 88'd0;
    wire [47:0] sf_shown = sf_valid ? sf_head : 48'd0;
    wire [15:0] pf_level16, sf_level16;
    wire [31:0] pf_dropped32, sf_dropped32;
    wire        pf_dropping, sf_dropping;

    sc_regs u_regs (
        .clk(clk), .rst(rst), .flags_clear(soft_reset),
        .bus_addr(bus_addr), .bus_wdata(bus_wdata), .bus_we(bus_we), .bus_re(bus_re),
        .bus_rdata(bus_rdata),
        .control_enable(control_enable), .control_frame_arm(control_frame_arm),
        .control_soft_reset(control_soft_reset),
        .status_busy(busy_shown),
        .status_frame_done(status_frame_done), .status_frame_done_set(frame_end),
        .status_point_overflow(status_point_overflow),
        .status_point_overflow_set(pf_dropping),
        .status_sobel_overflow(status_sobel_overflow),
        .status_sobel_overflow_set(sf_dropping),
        .width_value(width_value), .height_value(height_value),
        .octaves_count(octaves_count),
        .contrast_threshold_value(contrast_threshold_value),
        .edge_threshold_r(edge_threshold_r),
        .output_mode_sobel_output(output_mode_sobel_output),
        .output_mode_sobel_scale(output_mode_sobel_scale),
        .output_mode_points_per_batch(output_mode_points_per_batch),
        .output_mode_row_segment(output_mode_row_segment),
        .point_fifo_level_level(pf_level16 & {16{shown}}),
        .sobel_fifo_level_level(sf_level16 & {16{shown}}),
        .point_overflow_count_count(pf_dropped32 & {32{shown}}),
        .sobel_overflow_count_count(sf_dropped32 & {32{shown}}),
        .frame_count_count(frame_count & {32{shown}}),
        .latency_clocks_clocks(latency & {32{shown}}),
        .point_fifo_data_x(pf_shown[10:0]), .point_fifo_data_y(pf_shown[21:11]),
        .point_fifo_data_octave(pf_shown[87:86]), .point_fifo_data_scale({1'b0, pf_valid}),
        .point_fifo_data_valid(pf_valid), .point_fifo_data_pop(point_fifo_data_pop),
        .point_fifo_dxdy_dx(hold_dxdy[15:0] & {16{shown}}),
        .point_fifo_dxdy_dy(hold_dxdy[31:16] & {16{shown}}),
        .point_fifo_dsdog_ds(hold_dsdog[15:0] & {16{shown}}),
        .point_fifo_dsdog_dog(hold_dsdog[31:16] & {16{shown}}),
        .sobel_fifo_data_magnitude(sf_shown[39:32]),
        .sobel_fifo_data_orientation(sf_shown[45:40]),
        .sobel_fifo_data_octave(sf_shown[47:46]),
        .sobel_fifo_data_valid(sf_valid), .sobel_fifo_data_pop(sobel_fifo_data_pop),
        .sobel_fifo_position_x(hold_position[15:0] & {16{shown}}),
        .sobel_fifo_position_y(hold_position[31:16] & {16{shown}}),
        .max_offset_value(max_offset_value),
        .stream_control_enable(stream_control_enable), .stream_control_fec(stream_control_fec),
        .stream_control_camera(stream_control_camera),
        .frame_id_value(frame_id_value), .timestamp_lo_value(timestamp_lo_value),
        .timestamp_hi_value(timestamp_hi_value),
        .stream_points_count(eng_points & {32{shown}}),
        .stream_sobel_packets_count(eng_sobel & {32{shown}}),
        .stream_patches_dropped_count(eng_dropped & {32{shown}}),
        .stream_fault_cause(eng_cause & {2{shown}}), .stream_fault_octave(eng_octave & {2{shown}}),
        .stream_fault_x(eng_fx & {11{shown}}), .stream_fault_y(eng_fy & {11{shown}}),
        .stream_fault_overrun(eng_overrun && shown)
    );

    /* verilator lint_off UNUSEDSIGNAL */
    wire unused_flags = status_frame_done | status_point_overflow | status_sobel_overflow;
    /* verilator lint_on UNUSEDSIGNAL */

    // ---------------------------------------------------------------------------------------
    // Frame control.
    localparam [2:0] S_IDLE = 3'd0,   // no frame
                     S_SOF = 3'd1,    // armed: waiting for the SOF pixel
                     S_RUN = 3'd2,    // taking the frame's pixels
                     S_FLUSH = 3'd3,  // every pixel in: the octaves drain
                     S_SEND = 3'd4;   // the octaves are done: the stream engine finishes

    reg  [2:0]  state;
    reg         stream_on;            // the armed frame goes out through the stream engine
    reg  [31:0] total;                // WIDTH x HEIGHT of the armed frame
    reg  [31:0] taken;                // pixels of the frame fed so far
    reg  [1:0]  last_octave;          // OCTAVES - 1 of the armed frame, 0..3
    wire        fe_done;

    assign busy = state != S_IDLE;
    wire arm = control_frame_arm && !busy && !soft_reset && !rst;
    // BUSY from the clock after an accepted FRAME_ARM: a driver that reads STATUS on the next
    // clock sees the arm taken (arm is 0 on SOFT_RESET's clock, and so is busy_shown).
    assign busy_shown = (busy || arm) && shown;
    assign pixel_in_ready = control_enable && !soft_reset && pix_ce
                         && (state == S_SOF || state == S_RUN);
    wire take = pixel_in_valid && pixel_in_ready;
    wire feed = take && (state == S_RUN || pixel_in_sof);    // the pixel enters sc_frontend
    wire last_pixel = feed && (taken + 32'd1 == total);
    wire   fe_end = state == S_FLUSH && fe_done && !soft_reset;     // the octaves are done
    assign frame_end = stream_on ? (state == S_SEND && !eng_busy && !soft_reset) : fe_end;

    always @(posedge clk) begin
        if (rst || soft_reset) begin
            state <= S_IDLE;
            taken <= 32'd0;
        end else begin
            case (state)
                S_IDLE: if (arm) begin
                    state <= S_SOF;
                    taken <= 32'd0;
                end
                S_SOF, S_RUN: if (feed) begin
                    state <= last_pixel ? S_FLUSH : S_RUN;
                    taken <= taken + 32'd1;
                end
                S_FLUSH: if (fe_done) state <= stream_on ? S_SEND : S_IDLE;
                default: if (!eng_busy) state <= S_IDLE;
            endcase
        end
    end

    always @(posedge clk) begin
        if (arm) begin
            total <= {16'd0, width_value} * {16'd0, height_value};
            last_octave <= octaves_count[1:0] - 2'd1;   // OCTAVES 1..4 -> 0..3
        end
    end

    always @(posedge clk) begin
        if (rst || soft_reset) stream_on <= 1'b0;
        else if (arm) stream_on <= stream_control_enable;
    end

    always @(posedge clk) begin
        if (rst || soft_reset) frame_count <= 32'd0;
        else if (frame_end) frame_count <= frame_count + 32'd1;
    end

    // ---------------------------------------------------------------------------------------
    // Datapath. Its `start` is FRAME_ARM's clock (or SOFT_RESET's), never a pixel clock, and
    // `rst` and the clock after it: sc_frontend's control state has no other reset, and the
    // clock after `rst` latches the configuration registers' reset values.
    reg rst_d = 1'b0;
    always @(posedge clk) rst_d <= rst;
    wire fe_start = arm || soft_reset || rst || rst_d;
    wire [3:0]   oct_en, pt_valid, sb_valid;
    /* verilator lint_off UNUSEDSIGNAL */
    wire [3:0]   sub_valid;           // octave 3's: nothing follows it
    /* verilator lint_on UNUSEDSIGNAL */
    wire [63:0]  sub_data;
    wire [383:0] pt_data;
    wire [183:0] sb_data;
    // Observation ports of the co-simulation: not used here.
    /* verilator lint_off UNUSEDSIGNAL */
    wire [15:0]  g_valid;
    wire [255:0] g_data;
    wire [3:0]   dog_valid;
    wire [191:0] dog_data;
    /* verilator lint_on UNUSEDSIGNAL */

    sc_frontend #(.W0(W0), .W1(W1), .W2(W2), .W3(W3)) u_frontend (
        .clk(clk), .start(fe_start), .ce(pix_ce),
        .cfg_width(width_value), .cfg_height(height_value), .cfg_octaves(octaves_count),
        .cfg_contrast(contrast_threshold_value), .cfg_edge_ratio({3'd0, edge_threshold_r}),
        .cfg_sobel_scale(output_mode_sobel_scale), .cfg_max_offset(max_offset_value),
        .pix_valid(feed), .pix_data(pixel_in_data),
        .done(fe_done), .oct_en(oct_en),
        .g_valid(g_valid), .g_data(g_data), .dog_valid(dog_valid), .dog_data(dog_data),
        .sub_valid(sub_valid), .sub_data(sub_data),
        .pt_valid(pt_valid), .pt_data(pt_data), .sb_valid(sb_valid), .sb_data(sb_data)
    );

    /* verilator lint_off UNUSEDSIGNAL */
    wire unused_sub_data = |sub_data;    // only its valid bits time the latency
    /* verilator lint_on UNUSEDSIGNAL */

    // ---------------------------------------------------------------------------------------
    // LATENCY_CLOCKS. oct_in[k]: octave k takes an input sample on this clock.
    wire [3:0]  oct_in = {sub_valid[2:0] & oct_en[2:0], feed};
    reg         lat_wait;     // armed; the last octave's first input not seen yet
    reg         lat_run;      // counting: the frame's first pixel has been fed
    reg  [31:0] lat_count;    // clocks since the first pixel (from the clock after it)
    wire [31:0] lat_now = lat_run ? lat_count : 32'd0;
    always @(posedge clk) begin
        if (rst || soft_reset) begin
            lat_wait <= 1'b0;
            lat_run <= 1'b0;
            lat_count <= 32'd0;
            latency <= 32'd0;
        end else if (arm) begin
            lat_wait <= 1'b1;
            lat_run <= 1'b0;
            lat_count <= 32'd0;
        end else if (lat_wait) begin
            if (oct_in[last_octave]) begin
                latency <= lat_now;
                lat_wait <= 1'b0;
                lat_run <= 1'b0;
            end else if (pix_ce && (lat_run || feed)) begin
                lat_run <= 1'b1;
                lat_count <= lat_now + 32'd1;
            end
        end
    end

    // ---------------------------------------------------------------------------------------
    // FIFO inputs: item k is octave k's, valid only on a clock octave k advances.
    wire [3:0]   pf_v = pt_valid & oct_en;
    wire [3:0]   sf_v = sb_valid & oct_en;
    wire [351:0] pf_in;               // item k at [k*88 +: 88]
    wire [191:0] sf_in;               // item k at [k*48 +: 48]
    // pt_data x/y bits 15..11 are zero (x < W0 <= 2047, y < 2048).
    /* verilator lint_off UNUSEDSIGNAL */
    wire [383:0] pt_all = pt_data;
    /* verilator lint_on UNUSEDSIGNAL */
    genvar k;
    generate
        for (k = 0; k < 4; k = k + 1) begin : g_item
            localparam [1:0] OCT = k;
            // pt_data[k*96 +: 96] = {dog, ds, dy, dx, y, x}.
            assign pf_in[k*88 +: 88] = {OCT, pt_all[k*96+32 +: 64], pt_all[k*96+16 +: 11],
                                        pt_all[k*96 +: 11]};
            assign sf_in[k*48 +: 48] = {OCT, sb_data[k*46 +: 46]};
        end
    endgenerate

    // ---------------------------------------------------------------------------------------
    // The two FIFOs (sc_out_fifo: up to 4 entries per clock in octave order, one pop).
    // ... and a bus read of their heads pops nothing and loads no holding register.
    wire        pf_bus_pop = point_fifo_data_pop && bus_owns;
    wire        sf_bus_pop = sobel_fifo_data_pop && bus_owns;
    wire        eng_pf_pop, eng_sf_pop;
    wire        pf_overrun, sf_overrun;

    sc_out_fifo #(.DW(88), .DEPTH(POINT_DEPTH), .SPARE(POINT_DEPTH)) u_point_fifo (
        .clk(clk), .clear(rst || soft_reset),
        .in_valid(pf_v), .in_data(pf_in), .pop(pf_bus_pop || eng_pf_pop), .mark(snap_mark),
        .head(pf_head), .nonempty(pf_nonempty), .level(pf_level16),
        .dropped(pf_dropped32), .dropping(pf_dropping), .overrun(pf_overrun)
    );

    sc_out_fifo #(.DW(48), .DEPTH(SOBEL_DEPTH), .SPARE(SOBEL_DEPTH)) u_sobel_fifo (
        .clk(clk), .clear(rst || soft_reset),
        .in_valid(sf_v), .in_data(sf_in), .pop(sf_bus_pop || eng_sf_pop), .mark(snap_mark),
        .head(sf_head), .nonempty(sf_nonempty), .level(sf_level16),
        .dropped(sf_dropped32), .dropping(sf_dropping), .overrun(sf_overrun)
    );

    // Holding registers: loaded by the read that pops word 0 (zero when the FIFO was empty).
    always @(posedge clk) begin
        if (rst || soft_reset) begin
            hold_dxdy <= 32'd0;
            hold_dsdog <= 32'd0;
            hold_position <= 32'd0;
        end else begin
            if (pf_bus_pop) begin
                hold_dxdy <= pf_shown[53:22];     // {dy, dx}
                hold_dsdog <= pf_shown[85:54];    // {dog, ds}
            end
            if (sf_bus_pop)
                hold_position <= sf_shown[31:0];  // {y, x}
        end
    end

    // ---------------------------------------------------------------------------------------
    // Line times and snapshots. A line time ends on the clock that feeds a line's last pixel
    // and every WIDTH pixel clocks of the flush after the last line (the model's
    // FabricDevice::clock); on the clock after it the FIFOs are marked, and their entries
    // (everything held after that edge, `level`) are the engine's snapshot. The octaves'
    // end marks the last one.
    reg  [15:0] col;                  // column of the next pixel fed
    reg  [15:0] blank;                // flush pixel clocks since the last line time
    reg         line_d;               // the previous clock ended a line time
    wire        line_fed = feed && (col + 16'd1 == width_value);
    wire        line_blank = state == S_FLUSH && !fe_done && pix_ce
                          && (blank + 16'd1 == width_value);
    wire        snap_final = stream_on && fe_end;
    assign      snap_mark = stream_on && (line_d || snap_final);
    always @(posedge clk) begin
        if (rst || soft_reset || arm) begin
            col <= 16'd0;
            blank <= 16'd0;
            line_d <= 1'b0;
        end else begin
            if (feed) col <= line_fed ? 16'd0 : col + 16'd1;
            if (state == S_FLUSH && !fe_done && pix_ce) blank <= line_blank ? 16'd0 : blank + 16'd1;
            line_d <= line_fed || line_blank;
        end
    end

    sc_stream #(.W0(W0), .STASH(SOBEL_DEPTH)) u_stream (
        .clk(clk), .abort(rst || soft_reset), .rst(rst),
        .arm(arm && stream_control_enable),
        .cfg_width(width_value), .cfg_height(height_value), .cfg_octaves(octaves_count),
        .cfg_patches(output_mode_sobel_output), .cfg_scale(output_mode_sobel_scale),
        .cfg_batch(output_mode_points_per_batch), .cfg_segment(output_mode_row_segment),
        .cfg_frame_id(frame_id_value), .cfg_camera(stream_control_camera),
        .cfg_timestamp({timestamp_hi_value, timestamp_lo_value}), .fec(stream_control_fec),
        .drops_points(pf_dropped32), .drops_sobel(sf_dropped32),
        .fifo_overrun(pf_overrun || sf_overrun),
        .snap_valid(snap_mark), .snap_points(pf_level16), .snap_sobel(sf_level16),
        .snap_final(snap_final),
        .pf_head(pf_head), .pf_nonempty(pf_nonempty), .pf_pop(eng_pf_pop),
        .sf_head(sf_head), .sf_nonempty(sf_nonempty), .sf_pop(eng_sf_pop),
        .busy(eng_busy),
        .count_points(eng_points), .count_sobel(eng_sobel), .count_dropped(eng_dropped),
        .fault_cause(eng_cause), .fault_octave(eng_octave), .fault_x(eng_fx), .fault_y(eng_fy),
        .fault_overrun(eng_overrun),
        .link_data(link_out_data), .link_valid(link_out_valid), .link_ready(link_out_ready)
    );

endmodule

`default_nettype wire
