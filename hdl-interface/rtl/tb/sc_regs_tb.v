// Testbench of the generated register block (rtl/sc_regs.v): rw storage and resets, ro inputs,
// w1c flags, wo strobes, pops_on_read pops, reserved bits and unmapped offsets.
// Run: hdl-interface/rtl/tb/sc_regs_run.sh (prints PASS, exits non-zero on a failure).
`default_nettype none

module sc_regs_tb;
    reg         clk = 1'b0;
    reg         rst = 1'b1;
    reg         flags_clear = 1'b0;
    reg  [7:0]  bus_addr = 8'h00;
    reg  [31:0] bus_wdata = 32'h0;
    reg         bus_we = 1'b0;
    reg         bus_re = 1'b0;
    wire [31:0] bus_rdata;

    wire        control_enable, control_frame_arm, control_soft_reset;
    reg         status_busy = 1'b0;
    wire        status_frame_done, status_point_overflow, status_sobel_overflow;
    reg         frame_done_set = 1'b0, point_overflow_set = 1'b0, sobel_overflow_set = 1'b0;
    wire [15:0] width_value, height_value, contrast_threshold_value, max_offset_value;
    wire [2:0]  octaves_count;
    wire [4:0]  edge_threshold_r;
    wire        output_mode_sobel_output;
    wire [1:0]  output_mode_sobel_scale;
    wire [7:0]  output_mode_points_per_batch;
    wire [10:0] output_mode_row_segment;
    reg  [15:0] point_level = 16'h0, sobel_level = 16'h0;
    reg  [31:0] point_overflows = 32'h0, sobel_overflows = 32'h0, frames = 32'h0, latency = 32'h0;
    reg  [10:0] px = 11'h0, py = 11'h0;
    reg  [1:0]  poct = 2'h0, pscale = 2'h0;
    reg         pvalid = 1'b0;
    wire        point_pop;
    reg  [15:0] dx = 16'h0, dy = 16'h0, ds = 16'h0, dog = 16'h0;
    reg  [7:0]  smag = 8'h0;
    reg  [5:0]  sori = 6'h0;
    reg  [1:0]  soct = 2'h0;
    reg         svalid = 1'b0;
    wire        sobel_pop;
    reg  [15:0] sx = 16'h0, sy = 16'h0;
    wire        stream_enable, stream_fec;
    wire [7:0]  stream_camera;
    wire [31:0] frame_id, timestamp_lo, timestamp_hi;
    reg  [31:0] stream_points = 32'h0, stream_sobel_packets = 32'h0, stream_patches_dropped = 32'h0;
    reg  [1:0]  fault_cause = 2'h0, fault_octave = 2'h0;
    reg  [10:0] fault_x = 11'h0, fault_y = 11'h0;
    reg         fault_overrun = 1'b0;

    sc_regs dut (
        .clk(clk), .rst(rst), .flags_clear(flags_clear),
        .bus_addr(bus_addr), .bus_wdata(bus_wdata), .bus_we(bus_we), .bus_re(bus_re),
        .bus_rdata(bus_rdata),
        .control_enable(control_enable), .control_frame_arm(control_frame_arm),
        .control_soft_reset(control_soft_reset),
        .status_busy(status_busy),
        .status_frame_done(status_frame_done), .status_frame_done_set(frame_done_set),
        .status_point_overflow(status_point_overflow),
        .status_point_overflow_set(point_overflow_set),
        .status_sobel_overflow(status_sobel_overflow),
        .status_sobel_overflow_set(sobel_overflow_set),
        .width_value(width_value), .height_value(height_value), .octaves_count(octaves_count),
        .contrast_threshold_value(contrast_threshold_value),
        .edge_threshold_r(edge_threshold_r),
        .output_mode_sobel_output(output_mode_sobel_output),
        .output_mode_sobel_scale(output_mode_sobel_scale),
        .output_mode_points_per_batch(output_mode_points_per_batch),
        .output_mode_row_segment(output_mode_row_segment),
        .point_fifo_level_level(point_level), .sobel_fifo_level_level(sobel_level),
        .point_overflow_count_count(point_overflows),
        .sobel_overflow_count_count(sobel_overflows),
        .frame_count_count(frames), .latency_clocks_clocks(latency),
        .point_fifo_data_x(px), .point_fifo_data_y(py), .point_fifo_data_octave(poct),
        .point_fifo_data_scale(pscale), .point_fifo_data_valid(pvalid),
        .point_fifo_data_pop(point_pop),
        .point_fifo_dxdy_dx(dx), .point_fifo_dxdy_dy(dy),
        .point_fifo_dsdog_ds(ds), .point_fifo_dsdog_dog(dog),
        .sobel_fifo_data_magnitude(smag), .sobel_fifo_data_orientation(sori),
        .sobel_fifo_data_octave(soct), .sobel_fifo_data_valid(svalid),
        .sobel_fifo_data_pop(sobel_pop),
        .sobel_fifo_position_x(sx), .sobel_fifo_position_y(sy),
        .max_offset_value(max_offset_value),
        .stream_control_enable(stream_enable), .stream_control_fec(stream_fec),
        .stream_control_camera(stream_camera),
        .frame_id_value(frame_id), .timestamp_lo_value(timestamp_lo),
        .timestamp_hi_value(timestamp_hi),
        .stream_points_count(stream_points), .stream_sobel_packets_count(stream_sobel_packets),
        .stream_patches_dropped_count(stream_patches_dropped),
        .stream_fault_cause(fault_cause), .stream_fault_octave(fault_octave),
        .stream_fault_x(fault_x), .stream_fault_y(fault_y),
        .stream_fault_overrun(fault_overrun)
    );

    always #5 clk = ~clk;

    integer failures = 0;
    // Strobes counted at the rising edges that see them (a registered strobe is seen at the edge
    // after the one that raised it).
    integer arm_pulses = 0, reset_pulses = 0, point_pops = 0, sobel_pops = 0;
    always @(posedge clk) begin
        if (control_frame_arm) arm_pulses = arm_pulses + 1;
        if (control_soft_reset) reset_pulses = reset_pulses + 1;
        if (point_pop) point_pops = point_pops + 1;
        if (sobel_pop) sobel_pops = sobel_pops + 1;
    end

    task check(input [255:0] what, input [31:0] got, input [31:0] want);
        begin
            if (got !== want) begin
                $display("FAIL %0s: got %h, want %h", what, got, want);
                failures = failures + 1;
            end
        end
    endtask

    // One-clock bus cycles, driven between edges.
`include "tb_bus.vh"

    task expect_read(input [255:0] what, input [7:0] addr, input [31:0] want);
        reg [31:0] v;
        begin
            read(addr, v);
            check(what, v, want);
        end
    endtask

    reg [31:0] v;
    initial begin
        repeat (2) @(negedge clk);
        rst = 1'b0;

        // Resets and constants.
        expect_read("VERSION", 8'h00, 32'h5C01_0202);
        expect_read("CONTROL reset", 8'h04, 32'h0);
        expect_read("STATUS reset", 8'h08, 32'h0);
        expect_read("WIDTH reset", 8'h0C, 32'd640);
        expect_read("HEIGHT reset", 8'h10, 32'd480);
        expect_read("OCTAVES reset", 8'h14, 32'd4);
        expect_read("CONTRAST reset", 8'h18, 32'h0800);
        expect_read("EDGE reset", 8'h1C, 32'd10);
        expect_read("OUTPUT_MODE reset", 8'h20, 32'h0500_1011);
        expect_read("MAX_OFFSET reset", 8'h50, 32'd4096);
        check("max_offset port", {16'h0, max_offset_value}, 32'd4096);

        // rw: stored bits only; reserved bits read 0; the ports follow.
        write(8'h0C, 32'hFFFF_0500);
        expect_read("WIDTH rw", 8'h0C, 32'h0500);
        check("width port", {16'h0, width_value}, 32'h0500);
        write(8'h20, 32'hFFFF_FFFF);
        expect_read("OUTPUT_MODE reserved", 8'h20, 32'h07FF_FF31);
        check("sobel_scale port", {30'h0, output_mode_sobel_scale}, 32'h3);
        check("points_per_batch port", {24'h0, output_mode_points_per_batch}, 32'hFF);
        check("row_segment port", {21'h0, output_mode_row_segment}, 32'h7FF);
        write(8'h14, 32'h2);
        write(8'h18, 32'h0100);
        write(8'h1C, 32'h0C);
        write(8'h50, 32'h1FFF);
        check("octaves port", {29'h0, octaves_count}, 32'h2);
        check("contrast port", {16'h0, contrast_threshold_value}, 32'h0100);
        check("edge port", {27'h0, edge_threshold_r}, 32'h0C);
        check("max_offset written", {16'h0, max_offset_value}, 32'h1FFF);
        expect_read("STREAM_CONTROL reset", 8'h54, 32'h0);
        write(8'h54, 32'hFFFF_FFFF);
        expect_read("STREAM_CONTROL reserved", 8'h54, 32'h0000_FF03);
        check("stream ports", {22'h0, stream_camera, stream_fec, stream_enable}, 32'h3FF);
        write(8'h58, 32'hDEAD_BEEF);
        write(8'h5C, 32'h0123_4567);
        write(8'h60, 32'h89AB_CDEF);
        expect_read("FRAME_ID rw", 8'h58, 32'hDEAD_BEEF);
        check("frame_id port", frame_id, 32'hDEAD_BEEF);
        check("timestamp ports", timestamp_lo ^ timestamp_hi, 32'h8888_8888);

        // ro: bus writes ignored, the fabric's value read.
        write(8'h00, 32'h0);
        expect_read("VERSION after write", 8'h00, 32'h5C01_0202);
        point_level = 16'd512; sobel_level = 16'd3840;
        point_overflows = 32'hFFFF_FFFF; sobel_overflows = 32'd7; frames = 32'd3;
        latency = 32'd1234; dx = 16'hF000; dy = 16'h0800; ds = 16'hFFFF; dog = 16'hFC80;
        sx = 16'd319; sy = 16'd239;
        write(8'h24, 32'h0);
        expect_read("POINT_FIFO_LEVEL", 8'h24, 32'd512);
        expect_read("SOBEL_FIFO_LEVEL", 8'h28, 32'd3840);
        expect_read("POINT_OVERFLOW_COUNT", 8'h2C, 32'hFFFF_FFFF);
        expect_read("SOBEL_OVERFLOW_COUNT", 8'h30, 32'd7);
        expect_read("FRAME_COUNT", 8'h34, 32'd3);
        expect_read("LATENCY_CLOCKS", 8'h38, 32'd1234);
        expect_read("POINT_FIFO_DXDY", 8'h40, 32'h0800_F000);
        expect_read("POINT_FIFO_DSDOG", 8'h44, 32'hFC80_FFFF);
        expect_read("SOBEL_FIFO_POSITION", 8'h4C, 32'h00EF_013F);
        stream_points = 32'd1000; stream_sobel_packets = 32'd77; stream_patches_dropped = 32'd5;
        fault_cause = 2'd1; fault_octave = 2'd3; fault_x = 11'd1279; fault_y = 11'd1023;
        fault_overrun = 1'b1;
        expect_read("STREAM_POINTS", 8'h64, 32'd1000);
        expect_read("STREAM_SOBEL_PACKETS", 8'h68, 32'd77);
        expect_read("STREAM_PATCHES_DROPPED", 8'h6C, 32'd5);
        expect_read("STREAM_FAULT", 8'h70, {5'h0, 1'b1, 11'd1023, 11'd1279, 2'd3, 2'd1});

        // w1c: set by the fabric, cleared by writing 1, a set beats a clear on one clock.
        status_busy = 1'b1;
        @(negedge clk); frame_done_set = 1'b1; sobel_overflow_set = 1'b1;
        @(negedge clk); frame_done_set = 1'b0; sobel_overflow_set = 1'b0;
        expect_read("STATUS set", 8'h08, 32'hB);
        write(8'h08, 32'h0);
        expect_read("STATUS write 0", 8'h08, 32'hB);
        write(8'h08, 32'hFFFF_FFF2);
        expect_read("STATUS clear frame_done", 8'h08, 32'h9);
        @(negedge clk);
        bus_addr = 8'h08; bus_wdata = 32'h4; bus_we = 1'b1; point_overflow_set = 1'b1;
        @(negedge clk);
        bus_we = 1'b0; point_overflow_set = 1'b0;
        expect_read("STATUS set wins", 8'h08, 32'hD);
        write(8'h08, 32'hC);
        status_busy = 1'b0;
        expect_read("STATUS cleared", 8'h08, 32'h0);
        // flags_clear: every flag at once; a set on the same clock still wins.
        @(negedge clk); frame_done_set = 1'b1; point_overflow_set = 1'b1;
        @(negedge clk); frame_done_set = 1'b0; point_overflow_set = 1'b0;
        expect_read("STATUS before flags_clear", 8'h08, 32'h6);
        @(negedge clk); flags_clear = 1'b1; sobel_overflow_set = 1'b1;
        @(negedge clk); flags_clear = 1'b0; sobel_overflow_set = 1'b0;
        expect_read("STATUS after flags_clear", 8'h08, 32'h8);
        @(negedge clk); flags_clear = 1'b1;
        @(negedge clk); flags_clear = 1'b0;
        expect_read("STATUS all clear", 8'h08, 32'h0);

        // wo: one clock after the write, reads 0; the rw bit next to it is stored.
        check("no arm yet", arm_pulses, 0);
        write(8'h04, 32'h3);
        @(negedge clk); // the strobe is the register after the write's edge
        check("frame_arm fired once", arm_pulses, 1);
        check("enable set", {31'h0, control_enable}, 32'h1);
        expect_read("CONTROL reads enable only", 8'h04, 32'h1);
        repeat (3) @(negedge clk);
        check("frame_arm still once", arm_pulses, 1);
        write(8'h04, 32'h5);
        @(negedge clk);
        check("soft_reset fired once", reset_pulses, 1);
        check("frame_arm not fired", arm_pulses, 1);

        // pops_on_read: a pop per read of the data word, none for the other words.
        px = 11'd1279; py = 11'd1023; poct = 2'd3; pscale = 2'd1; pvalid = 1'b1;
        smag = 8'd200; sori = 6'd63; soct = 2'd2; svalid = 1'b1;
        expect_read("POINT_FIFO_DATA", 8'h3C, 32'h81DF_FCFF);
        check("one point pop", point_pops, 1);
        expect_read("POINT_FIFO_DXDY no pop", 8'h40, 32'h0800_F000);
        check("still one point pop", point_pops, 1);
        expect_read("SOBEL_FIFO_DATA", 8'h48, 32'h8000_BFC8);
        check("one sobel pop", sobel_pops, 1);
        check("sobel read does not pop points", point_pops, 1);
        pvalid = 1'b0;
        expect_read("POINT_FIFO_DATA empty", 8'h3C, 32'h01DF_FCFF);
        check("pop strobe on every read", point_pops, 2);
        write(8'h3C, 32'hFFFF_FFFF);
        check("writes do not pop", point_pops, 2);

        // Unmapped offsets: read 0, writes change nothing.
        expect_read("unmapped 0x74", 8'h74, 32'h0);
        expect_read("unmapped 0xFC", 8'hFC, 32'h0);
        write(8'h74, 32'hFFFF_FFFF);
        write(8'hFC, 32'hFFFF_FFFF);
        expect_read("WIDTH kept", 8'h0C, 32'h0500);
        expect_read("misaligned byte address reads its word", 8'h0E, 32'h0500);

        // rst restores the resets.
        @(negedge clk); rst = 1'b1;
        @(negedge clk); rst = 1'b0;
        expect_read("WIDTH after rst", 8'h0C, 32'd640);
        expect_read("CONTROL after rst", 8'h04, 32'h0);
        expect_read("MAX_OFFSET after rst", 8'h50, 32'd4096);

        if (failures == 0) $display("PASS sc_regs_tb");
        else $display("FAIL sc_regs_tb: %0d failures", failures);
        $finish;
    end
endmodule

`default_nettype wire
