// Testbench of sc_fabric: the register bus, the frame control, the two FIFOs and their
// arbitration, the holding registers, the counters and SOFT_RESET.
//
// The datapath (sc_frontend) is the real one; this bench checks what sc_fabric does with its
// outputs, not the datapath itself (the co-simulation harness compares sc_frontend with the
// Rust model). A reference FIFO per stream, written in the model's sequential style (each
// clock: the pushes of octaves 0..3 in order, each refused when the FIFO is full as it was
// before the clock; the driver's pop), follows sc_frontend's pt_valid / sb_valid and the pop
// strobes; every word read over the bus must equal the reference's head, and the levels,
// overflow counts and flags must agree. Small FIFOs (8 points, 3 x 64 Sobel pixels) make
// both overflow.
//
// Frame 1: 64 x 48, 3 octaves, a few pixels before SOF (discarded), gaps in PIXEL_IN and
// ENABLE low for a while; nothing read until FRAME_DONE, then both FIFOs drained. Frame 2: a
// pixel on every clock (LATENCY_CLOCKS must be the model's), reads interleaved with the frame
// (pops on clocks with pushes). Then SOFT_RESET. With +dump=FILE +trace the bench writes frame
// 1's image ($writememh) and prints the points sc_frontend pushed, in push order, to compare
// with the model's RegisterFrontEnd on the same image (they were equal, 76 points, when this
// bench was written).
// Run: hdl-interface/rtl/tb/sc_fabric_run.sh (prints PASS, exits non-zero on a failure).
`default_nettype none

module sc_fabric_tb;
    localparam W = 64, H = 48, OCTAVES = 3;
    localparam PD = 8, SD = 3 * 64;
    localparam MODEL_LATENCY = 1323;

    reg         clk = 1'b0;
    reg         rst = 1'b1;
    reg  [7:0]  bus_addr = 8'h00;
    reg  [31:0] bus_wdata = 32'h0;
    reg         bus_we = 1'b0;
    reg         bus_re = 1'b0;
    wire [31:0] bus_rdata;
    reg  [7:0]  pixel_in_data = 8'h0;
    reg         pixel_in_valid = 1'b0;
    wire        pixel_in_ready;
    reg         pixel_in_sof = 1'b0;
    reg         pixel_in_eol = 1'b0;

    sc_fabric #(.W0(64), .W1(32), .W2(16), .W3(12), .POINT_DEPTH(PD), .SOBEL_DEPTH(SD)) dut (
        .clk(clk), .rst(rst),
        .bus_addr(bus_addr), .bus_wdata(bus_wdata), .bus_we(bus_we), .bus_re(bus_re),
        .bus_rdata(bus_rdata),
        .pixel_in_data(pixel_in_data), .pixel_in_valid(pixel_in_valid),
        .pixel_in_ready(pixel_in_ready), .pixel_in_sof(pixel_in_sof),
        .pixel_in_eol(pixel_in_eol), .pix_ce(1'b1),
        .link_out_data(), .link_out_valid(), .link_out_ready(1'b1)
    );

    always #5 clk = ~clk;

    integer failures = 0;
    task check(input [255:0] what, input [31:0] got, input [31:0] want);
        begin
            if (got !== want) begin
                if (failures < 20) $display("FAIL %0s: got %h, want %h", what, got, want);
                failures = failures + 1;
            end
        end
    endtask

    // ---------------------------------------------------------------------------------------
    // Reference FIFOs (the model's sequential pushes), updated at every rising edge.
    reg  [87:0] rp_mem [0:PD-1];
    reg  [47:0] rs_mem [0:SD-1];
    integer rp_rd = 0, rp_wr = 0, rp_cnt = 0, rp_drop = 0, rp_pushed = 0;
    integer rs_rd = 0, rs_wr = 0, rs_cnt = 0, rs_drop = 0, rs_pushed = 0;
    integer pre, kept, k;
    reg  [87:0] p_entry;
    reg  [47:0] s_entry;
    reg  [31:0] exp_point, exp_dxdy, exp_dsdog, exp_sobel, exp_position;
    integer cycle = 0, first_pixel = -1, last_first = -1;
    reg     trace = 1'b0;             // +trace: print frame 1's points (to compare with the model)
    integer point_overflows = 0, sobel_overflows = 0;   // frames that dropped entries
    always @(posedge clk) begin
        cycle = cycle + 1;
        if (rst || dut.soft_reset) begin
            rp_rd = 0; rp_wr = 0; rp_cnt = 0; rp_drop = 0;
            rs_rd = 0; rs_wr = 0; rs_cnt = 0; rs_drop = 0;
        end else begin
            // The driver's pops: the head before the edge.
            if (dut.point_fifo_data_pop) begin
                if (rp_cnt > 0) begin
                    p_entry = rp_mem[rp_rd];
                    exp_point = {1'b1, 5'd0, 2'd1, p_entry[87:86], p_entry[21:0]};
                    exp_dxdy = p_entry[53:22];
                    exp_dsdog = p_entry[85:54];
                    rp_rd = (rp_rd + 1) % PD;
                    rp_cnt = rp_cnt - 1;
                end else begin
                    exp_point = 32'h0; exp_dxdy = 32'h0; exp_dsdog = 32'h0;
                end
            end
            if (dut.sobel_fifo_data_pop) begin
                if (rs_cnt > 0) begin
                    s_entry = rs_mem[rs_rd];
                    exp_sobel = {1'b1, 15'd0, s_entry[47:32]};
                    exp_position = s_entry[31:0];
                    rs_rd = (rs_rd + 1) % SD;
                    rs_cnt = rs_cnt - 1;
                end else begin
                    exp_sobel = 32'h0; exp_position = 32'h0;
                end
            end
            // The clock's pushes, octave 0 first, against the level before the edge.
            pre = rp_cnt + (dut.point_fifo_data_pop && exp_point[31] ? 1 : 0);
            kept = 0;
            for (k = 0; k < 4; k = k + 1) begin
                if (dut.pt_valid[k] && dut.oct_en[k]) begin
                    rp_pushed = rp_pushed + 1;
                    if (trace)
                        $display("point o%0d x %0d y %0d dx %0d dy %0d ds %0d dog %0d", k,
                                 dut.pt_data[k*96 +: 16], dut.pt_data[k*96+16 +: 16],
                                 $signed(dut.pt_data[k*96+32 +: 16]),
                                 $signed(dut.pt_data[k*96+48 +: 16]),
                                 $signed(dut.pt_data[k*96+64 +: 16]),
                                 $signed(dut.pt_data[k*96+80 +: 16]));
                    if (pre + kept < PD) begin
                        rp_mem[rp_wr] = {k[1:0], dut.pt_data[k*96+32 +: 64],
                                         dut.pt_data[k*96+16 +: 11], dut.pt_data[k*96 +: 11]};
                        rp_wr = (rp_wr + 1) % PD;
                        kept = kept + 1;
                    end else begin
                        rp_drop = rp_drop + 1;
                    end
                end
            end
            rp_cnt = rp_cnt + kept;
            pre = rs_cnt + (dut.sobel_fifo_data_pop && exp_sobel[31] ? 1 : 0);
            kept = 0;
            for (k = 0; k < 4; k = k + 1) begin
                if (dut.sb_valid[k] && dut.oct_en[k]) begin
                    rs_pushed = rs_pushed + 1;
                    if (pre + kept < SD) begin
                        rs_mem[rs_wr] = {k[1:0], dut.sb_data[k*46 +: 46]};
                        rs_wr = (rs_wr + 1) % SD;
                        kept = kept + 1;
                    end else begin
                        rs_drop = rs_drop + 1;
                    end
                end
            end
            rs_cnt = rs_cnt + kept;
            // Latency: first pixel fed to the first input of octave OCTAVES - 1.
            if (dut.feed && first_pixel < 0) first_pixel = cycle;
            if (dut.sub_valid[OCTAVES-2] && dut.oct_en[OCTAVES-2] && last_first < 0)
                last_first = cycle;
        end
    end

    // Coverage: clocks where several octaves push, clocks where a pop meets pushes.
    function integer ones(input [3:0] b);
        ones = b[0] + b[1] + b[2] + b[3];
    endfunction
    integer multi_push_clocks = 0, pop_push_clocks = 0;
    always @(posedge clk) begin
        if (ones(dut.pt_valid & dut.oct_en) > 1 || ones(dut.sb_valid & dut.oct_en) > 1)
            multi_push_clocks = multi_push_clocks + 1;
        if (dut.sobel_fifo_data_pop && (dut.sb_valid & dut.oct_en) != 4'd0)
            pop_push_clocks = pop_push_clocks + 1;
    end

    // ---------------------------------------------------------------------------------------
    // Bus cycles.
`include "tb_bus.vh"

    reg [31:0] v;
    integer points_read, sobel_read;
    task pop_point;
        begin
            read(8'h3C, v);
            check("POINT_FIFO_DATA", v, exp_point);
            if (v[31]) points_read = points_read + 1;
            read(8'h40, v);
            check("POINT_FIFO_DXDY", v, exp_dxdy);
            read(8'h44, v);
            check("POINT_FIFO_DSDOG", v, exp_dsdog);
        end
    endtask

    task pop_sobel;
        begin
            read(8'h48, v);
            check("SOBEL_FIFO_DATA", v, exp_sobel);
            if (v[31]) sobel_read = sobel_read + 1;
            read(8'h4C, v);
            check("SOBEL_FIFO_POSITION", v, exp_position);
        end
    endtask

    task drain;
        begin
            read(8'h24, v);
            check("POINT_FIFO_LEVEL", v, rp_cnt);
            read(8'h28, v);
            check("SOBEL_FIFO_LEVEL", v, rs_cnt);
            while (rp_cnt > 0) pop_point;
            pop_point; // empty: VALID 0, holding registers 0
            check("empty point word", exp_point, 32'h0);
            while (rs_cnt > 0) pop_sobel;
            pop_sobel;
            check("empty sobel word", exp_sobel, 32'h0);
        end
    endtask

    // ---------------------------------------------------------------------------------------
    // Pixel source: a random image, one frame per `frame_go`, with gaps.
    reg  [7:0] image [0:W*H-1];
    integer    next_pixel = 0;
    reg        frame_go = 1'b0;
    reg        gapless = 1'b0;     // a pixel on every clock (else about 1 clock in 4 is idle)
    integer    junk = 0;
    integer    seed = 7;
    reg        pixel_in_ready_seen = 1'b0;   // PIXEL_IN ready during the clock that just ended
    always @(negedge clk) begin
        if (pixel_in_valid && pixel_in_ready_seen) begin
            if (junk > 0) junk = junk - 1;
            else next_pixel = next_pixel + 1;
        end
        pixel_in_valid = 1'b0;
        pixel_in_sof = 1'b0;
        pixel_in_eol = 1'b0;
        if (frame_go && next_pixel < W * H && (gapless || ($random(seed) & 3) != 0)) begin
            pixel_in_valid = 1'b1;
            if (junk > 0) begin
                pixel_in_data = 8'hEE;
            end else begin
                pixel_in_data = image[next_pixel];
                pixel_in_sof = next_pixel == 0;
                pixel_in_eol = (next_pixel % W) == W - 1;
            end
        end
    end
    always @(posedge clk) pixel_in_ready_seen <= pixel_in_ready;

    task run_frame(input integer interleave);
        integer i, t, p_drop0, s_drop0, p_pushed0, s_pushed0, sx, sy, x, y, flip;
        reg [8*256-1:0] dump_path;
        real level;
        begin
            p_drop0 = rp_drop;
            s_drop0 = rs_drop;
            // Gaussian blobs (sigma 1.6, 10 pixels apart, bright and dark in a checkerboard,
            // random signs per frame) on mid grey with a little noise: many points (the model
            // finds 94 on the noiseless image), so the point FIFO overflows.
            flip = $random(seed) & 1;
            for (y = 0; y < H; y = y + 1)
                for (x = 0; x < W; x = x + 1) begin
                    sx = (x / 10) * 10 + 5;
                    sy = (y / 10) * 10 + 5;
                    level = 110.0 * $exp(-((x - sx) * (x - sx) + (y - sy) * (y - sy)) / 5.12);
                    if ((((x / 10) + (y / 10)) & 1) ^ flip) level = -level;
                    image[y * W + x] = $rtoi(128.0 + level) + ($random(seed) & 1);
                end
            if (interleave == 0) begin
                if ($value$plusargs("dump=%s", dump_path)) $writememh(dump_path, image);
                trace = $test$plusargs("trace");
            end
            p_pushed0 = rp_pushed;
            s_pushed0 = rs_pushed;
            next_pixel = 0;
            junk = 3;
            first_pixel = -1;
            last_first = -1;
            write(8'h04, 32'h3);          // ENABLE, FRAME_ARM
            @(negedge clk);
            frame_go = 1'b1;
            read(8'h08, v);
            check("BUSY after FRAME_ARM", v & 32'h1, 32'h1);
            t = 0;
            while (next_pixel < W * H) begin
                if (interleave) begin
                    pop_sobel;
                    if (t % 4 == 0) pop_point;
                end else begin
                    @(negedge clk);
                end
                t = t + 1;
                if (!interleave && t == 500) begin
                    write(8'h04, 32'h0);  // ENABLE low: PIXEL_IN not ready
                    repeat (20) begin
                        @(negedge clk);
                        check("ready low while disabled", pixel_in_ready, 0);
                    end
                    write(8'h04, 32'h1);
                end
            end
            frame_go = 1'b0;
            v = 0;
            while (!v[1]) read(8'h08, v);  // FRAME_DONE
            check("BUSY low at FRAME_DONE", v & 32'h1, 32'h0);
            trace = 1'b0;
            if (rp_drop != p_drop0) point_overflows = point_overflows + 1;
            if (rs_drop != s_drop0) sobel_overflows = sobel_overflows + 1;
            check("POINT_OVERFLOW flag", (v >> 2) & 1, rp_drop != p_drop0);
            check("SOBEL_OVERFLOW flag", (v >> 3) & 1, rs_drop != s_drop0);
            read(8'h2C, v);
            check("POINT_OVERFLOW_COUNT", v, rp_drop);
            read(8'h30, v);
            check("SOBEL_OVERFLOW_COUNT", v, rs_drop);
            read(8'h38, v);
            check("LATENCY_CLOCKS", v, last_first - first_pixel);
            // One pixel per clock: the model's first_input_clock(2) for 64 x 48 (latency.rs
            // sample_clock(64, 48, 2, 0); RegisterFrontEnd<64, 32, 16, 12> says 1323).
            if (gapless) check("LATENCY_CLOCKS = the model's", v, MODEL_LATENCY);
            $display("frame: %0d points and %0d Sobel pixels pushed, latency %0d clocks",
                     rp_pushed - p_pushed0, rs_pushed - s_pushed0, v);
            write(8'h08, 32'hE);          // clear the flags
            read(8'h08, v);
            check("STATUS cleared", v, 32'h0);
            drain;
        end
    endtask

    initial begin
        points_read = 0;
        sobel_read = 0;
        repeat (3) @(negedge clk);
        rst = 1'b0;
        read(8'h00, v);
        check("VERSION", v, 32'h5C01_0202);
        write(8'h0C, W);
        write(8'h10, H);
        write(8'h14, OCTAVES);
        write(8'h18, 32'h0100);           // 1.0 grey level
        write(8'h50, 32'd4096);
        read(8'h08, v);
        check("idle", v, 32'h0);
        check("not ready before FRAME_ARM", pixel_in_ready, 0);

        run_frame(0);
        read(8'h34, v);
        check("FRAME_COUNT 1", v, 32'd1);
        gapless = 1'b1;
        run_frame(1);
        gapless = 1'b0;
        read(8'h34, v);
        check("FRAME_COUNT 2", v, 32'd2);

        // SOFT_RESET clears the counters and the FIFOs, keeps the configuration.
        write(8'h04, 32'h3);
        frame_go = 1'b1; next_pixel = 0; junk = 0;
        repeat (200) @(negedge clk);
        frame_go = 1'b0;
        write(8'h04, 32'h4);
        repeat (2) @(negedge clk);
        read(8'h08, v);
        check("STATUS after SOFT_RESET", v, 32'h0);
        read(8'h24, v);
        check("point level after SOFT_RESET", v, 32'h0);
        read(8'h28, v);
        check("sobel level after SOFT_RESET", v, 32'h0);
        read(8'h30, v);
        check("sobel overflows after SOFT_RESET", v, 32'h0);
        read(8'h34, v);
        check("FRAME_COUNT after SOFT_RESET", v, 32'h0);
        read(8'h38, v);
        check("LATENCY after SOFT_RESET", v, 32'h0);
        read(8'h0C, v);
        check("WIDTH kept", v, W);

        $display("points pushed %0d (read %0d), sobel pushed %0d (read %0d)",
                 rp_pushed, points_read, rs_pushed, sobel_read);
        $display("clocks with several pushes %0d, Sobel pops on push clocks %0d",
                 multi_push_clocks, pop_push_clocks);
        if (points_read == 0 || sobel_read == 0 || point_overflows == 0 || sobel_overflows == 0)
            $display("FAIL: the frames did not exercise both FIFOs");
        else if (failures == 0) $display("PASS sc_fabric_tb");
        if (failures != 0) $display("FAIL sc_fabric_tb: %0d failures", failures);
        $finish;
    end

    initial begin
        #50_000_000;
        $display("FAIL sc_fabric_tb: timeout");
        $finish;
    end
endmodule

`default_nettype wire
