// sc_soc: the soft-core of the SoC in the loop, a real RV32IMAC core (VexRiscv_IMAC from PyPI,
// fetched and adapted to QEMU virt's memory map by fetch_core.sh) with its instruction and
// data Wishbone buses carried to the harness (sim/sc_soc_sim.cpp), which serves them as the
// `virt` machine's RAM (0x8000_0000), 16550 UART (0x1000_0000) and `sifive_test` finisher
// (0x0010_0000), so that the firmware ELF QEMU runs runs here byte for byte.
//
// The core starts at 0x8000_0000, where QEMU's `-bios none -kernel ELF` starts it; it has no
// interrupt sources (the firmware polls).
`default_nettype none

module sc_soc (
    input  wire        clk,
    input  wire        reset,            // synchronous, active high
    // Instruction bus (Wishbone B4 classic, 30-bit word addresses, incrementing bursts).
    output wire        ibus_cyc,
    output wire        ibus_stb,
    input  wire        ibus_ack,
    input  wire        ibus_err,
    output wire [29:0] ibus_adr,
    input  wire [31:0] ibus_dat_r,
    // Data bus.
    output wire        dbus_cyc,
    output wire        dbus_stb,
    input  wire        dbus_ack,
    input  wire        dbus_err,
    output wire        dbus_we,
    output wire [29:0] dbus_adr,
    output wire [31:0] dbus_dat_w,
    output wire [3:0]  dbus_sel,
    input  wire [31:0] dbus_dat_r
);

    /* verilator lint_off UNUSEDSIGNAL */
    wire        ibus_we;
    wire [31:0] ibus_dat_w;
    wire [3:0]  ibus_sel;
    wire [2:0]  ibus_cti, dbus_cti;
    wire [1:0]  ibus_bte, dbus_bte;
    /* verilator lint_on UNUSEDSIGNAL */

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
        .dBusWishbone_CYC(dbus_cyc), .dBusWishbone_STB(dbus_stb), .dBusWishbone_ACK(dbus_ack),
        .dBusWishbone_WE(dbus_we), .dBusWishbone_ADR(dbus_adr),
        .dBusWishbone_DAT_MISO(dbus_dat_r), .dBusWishbone_DAT_MOSI(dbus_dat_w),
        .dBusWishbone_SEL(dbus_sel), .dBusWishbone_ERR(dbus_err),
        .dBusWishbone_CTI(dbus_cti), .dBusWishbone_BTE(dbus_bte),
        .clk(clk), .reset(reset)
    );

endmodule

`default_nettype wire
