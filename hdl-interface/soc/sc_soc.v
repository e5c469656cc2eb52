// sc_soc: the SoC in the loop: a real RV32IMAC core (VexRiscv_IMAC from PyPI, fetched and
// adapted to QEMU virt's memory map by fetch_core.sh) and the fabric of both camera channels
// (sc_fabric, with their stream engines) on its data bus. The harness (sim/sc_soc_sim.cpp)
// is the board: it serves the rest of the buses as the `virt` machine's RAM (0x8000_0000),
// 16550 UART (0x1000_0000) and `sifive_test` finisher (0x0010_0000), drives the cameras and
// carries the UART and both LINK_OUT ports to the host, so that the firmware ELF QEMU runs
// runs here byte for byte.
//
// Memory map of the fabric (hdl-interface/regmap.toml: base_address 0x4000_0000, a window of
// 256 bytes): camera c's sc_fabric at 0x4000_0000 + c * 0x1_0000, c = 0 (left), 1 (right);
// the rest of 0x4000_0000 .. 0x4001_FFFF reads 0 and ignores writes (sc_regs' decoding of
// its 256-byte window repeats inside each 64 KiB slot, as the register bus has 8 address
// bits).
//
// The bus adapter: Wishbone classic to sc_regs' strobes. An access to a fabric raises its
// bus_we or bus_re for exactly one clock, and acknowledges on the next clock with the word
// sc_regs registered: one strobe per bus transfer, so a read of a FIFO's data pops once.
//
// Clocks: one clock for all; the fabrics' datapaths advance on `pix_ce` (the cameras' pixel
// clock as an enable), their registers, stream engines and framers on every clock.
//
// The core starts at 0x8000_0000, where QEMU's `-bios none -kernel ELF` starts it; it has no
// interrupt sources (the firmware polls).
`default_nettype none

module sc_soc #(
    parameter W0 = 640                   // the fabrics' widest line (sc_fabric): 640x480
) (
    input  wire        clk,
    input  wire        reset,            // synchronous, active high
    // Instruction bus (Wishbone B4 classic, 30-bit word addresses, incrementing bursts).
    output wire        ibus_cyc,
    output wire        ibus_stb,
    input  wire        ibus_ack,
    input  wire        ibus_err,
    output wire [29:0] ibus_adr,
    input  wire [31:0] ibus_dat_r,
    // Data bus, but for the fabric's addresses (the harness sees STB only for the others).
    output wire        dbus_cyc,
    output wire        dbus_stb,
    input  wire        dbus_ack,
    input  wire        dbus_err,
    output wire        dbus_we,
    output wire [29:0] dbus_adr,
    output wire [31:0] dbus_dat_w,
    output wire [3:0]  dbus_sel,
    input  wire [31:0] dbus_dat_r,
    // The cameras (PIXEL_IN of camera c at [c]) and their pixel-clock enable.
    input  wire        pix_ce,
    input  wire [15:0] cam_data,
    input  wire [1:0]  cam_valid,
    input  wire [1:0]  cam_sof,
    input  wire [1:0]  cam_eol,
    output wire [1:0]  cam_ready,
    // LINK_OUT of camera c at [c].
    output wire [15:0] link_data,
    output wire [1:0]  link_valid,
    input  wire [1:0]  link_ready,
    // Observation: fabric register reads and writes so far (the harness checks one strobe
    // per transfer).
    output reg  [31:0] fabric_reads,
    output reg  [31:0] fabric_writes
);

    // ---- the core ----
    /* verilator lint_off UNUSEDSIGNAL */
    wire        ibus_we;
    wire [31:0] ibus_dat_w;
    wire [3:0]  ibus_sel;
    wire [2:0]  ibus_cti, dbus_cti;
    wire [1:0]  ibus_bte, dbus_bte;
    /* verilator lint_on UNUSEDSIGNAL */
    wire        core_dstb;
    wire        fab_ack;                         // the bus adapter's (below)
    wire [31:0] fab_rdata;
    wire        core_dack = dbus_ack || fab_ack;
    wire [31:0] core_ddat = fab_ack ? fab_rdata : dbus_dat_r;

    VexRiscv u_core (
        .externalResetVector(32'h8000_0000),
        .timerInterrupt(1'b0),
        .softwareInterrupt(1'b0),
        .externalInterruptArray(32'd0),
        .iBusWishbone_CYC(ibus_cyc), .iBusWishbone_STB(ibus_stb), .iBusWishbone_ACK(ibus_ack),
        .iBusWishbone_WE(ibus_we), .iBusWishbone_ADR(ibus_adr),
        .iBusWishbone_DAT_MISO(ibus_dat_r), .iBusWishbone_DAT_MOSI(ibus_dat_w),
        .iBusWishbone_SEL(ibus_sel), .iBusWishbone_ERR(ibus_err),
        .iBusWishbone_CTI(ibus_cti), .iBusWishbone_BTE(ibus_bte),
        .dBusWishbone_CYC(dbus_cyc), .dBusWishbone_STB(core_dstb), .dBusWishbone_ACK(core_dack),
        .dBusWishbone_WE(dbus_we), .dBusWishbone_ADR(dbus_adr),
        .dBusWishbone_DAT_MISO(core_ddat), .dBusWishbone_DAT_MOSI(dbus_dat_w),
        .dBusWishbone_SEL(dbus_sel), .dBusWishbone_ERR(dbus_err),
        .dBusWishbone_CTI(dbus_cti), .dBusWishbone_BTE(dbus_bte),
        .clk(clk), .reset(reset)
    );

    // ---- the bus adapter ----
    // Byte address 0x4000_0000 .. 0x4001_FFFF: word address bits [29:15] = 0x4000_0000 >> 17.
    wire        fab_range = dbus_adr[29:15] == 15'h2000;
    wire        fab_cam = dbus_adr[14];          // byte address bit 16
    wire        fab_mapped = dbus_adr[13:6] == 8'd0;   // inside the 256-byte window
    assign      dbus_stb = core_dstb && !fab_range;
    reg         fab_wait;                        // the strobe went out; acknowledge now
    reg         fab_cam_d, fab_mapped_d;
    wire        fab_go = dbus_cyc && core_dstb && fab_range && !fab_wait;
    assign      fab_ack = fab_wait;
    wire [31:0] rdata0, rdata1;
    assign      fab_rdata = !fab_mapped_d ? 32'd0 : fab_cam_d ? rdata1 : rdata0;

    always @(posedge clk) begin
        if (reset) begin
            fab_wait <= 1'b0;
            fabric_reads <= 32'd0;
            fabric_writes <= 32'd0;
        end else begin
            fab_wait <= fab_go;
            if (fab_go) begin
                fab_cam_d <= fab_cam;
                fab_mapped_d <= fab_mapped;
                if (fab_mapped) begin
                    if (dbus_we) fabric_writes <= fabric_writes + 32'd1;
                    else fabric_reads <= fabric_reads + 32'd1;
                end
            end
        end
    end

    // ---- the fabrics ----
    genvar c;
    generate
        for (c = 0; c < 2; c = c + 1) begin : g_cam
            wire sel = fab_go && fab_mapped && (fab_cam == c[0]);
            wire [31:0] rdata;
            sc_fabric #(.W0(W0), .W1(W0 / 2), .W2(W0 / 4), .W3(W0 / 8)) u_fabric (
                .clk(clk), .rst(reset),
                .bus_addr({dbus_adr[5:0], 2'b00}), .bus_wdata(dbus_dat_w),
                .bus_we(sel && dbus_we), .bus_re(sel && !dbus_we), .bus_rdata(rdata),
                .pixel_in_data(cam_data[c*8 +: 8]), .pixel_in_valid(cam_valid[c]),
                .pixel_in_ready(cam_ready[c]), .pixel_in_sof(cam_sof[c]),
                .pixel_in_eol(cam_eol[c]), .pix_ce(pix_ce),
                .link_out_data(link_data[c*8 +: 8]), .link_out_valid(link_valid[c]),
                .link_out_ready(link_ready[c])
            );
            if (c == 0) begin : g_r0
                assign rdata0 = rdata;
            end else begin : g_r1
                assign rdata1 = rdata;
            end
        end
    endgenerate

endmodule

`default_nettype wire
