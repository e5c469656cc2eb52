//! Static RAM of the front end at 640 pixels: fabric block RAM bits and the models' bytes.
//! The output FIFOs' entry widths come from the RTL itself, so the figure is the RTL's.

use stereocal_firmware::fabric::memory::{front_end_ram_bits, FifoEntryBits};
use stereocal_firmware::fabric::{FastFrontEnd, RegisterFrontEnd};

const SC_FABRIC: &str = include_str!("../../hdl-interface/rtl/sc_fabric.v");

/// The `DW` parameter of the `sc_out_fifo` instance named `instance` in `sc_fabric.v`.
fn rtl_entry_bits(instance: &str) -> usize {
    let line = SC_FABRIC
        .lines()
        .find(|l| l.contains("sc_out_fifo #(") && l.contains(instance))
        .unwrap_or_else(|| panic!("sc_fabric.v instantiates no sc_out_fifo {instance}"));
    let dw = line
        .split(".DW(")
        .nth(1)
        .and_then(|rest| rest.split(')').next())
        .unwrap_or_else(|| panic!("no .DW(...) in `{line}`"));
    dw.trim()
        .parse()
        .unwrap_or_else(|_| panic!("`{dw}` is not a width in `{line}`"))
}

#[test]
fn front_end_at_640_fits_256_kib() {
    let entry = FifoEntryBits {
        point: rtl_entry_bits("u_point_fifo"),
        sobel: rtl_entry_bits("u_sobel_fifo"),
    };
    let bits = front_end_ram_bits(640, 4, entry);
    let reg = core::mem::size_of::<RegisterFrontEnd<640, 320, 160, 80>>();
    let fast = core::mem::size_of::<FastFrontEnd<640, 320, 160, 80>>();
    eprintln!(
        "FIFO entries in sc_fabric.v: point {} bits, Sobel {} bits",
        entry.point, entry.sobel
    );
    eprintln!(
        "fabric block RAM at 640 px, 4 octaves: {bits} bits = {:.1} KiB",
        bits as f64 / 8192.0
    );
    eprintln!(
        "register-level model RegisterFrontEnd<640,320,160,80>: {reg} bytes = {:.1} KiB",
        reg as f64 / 1024.0
    );
    eprintln!(
        "fast path FastFrontEnd<640,320,160,80>: {fast} bytes = {:.1} KiB",
        fast as f64 / 1024.0
    );
    assert!(bits / 8 < 256 * 1024);
    assert!(reg < 256 * 1024);
    assert!(fast < 256 * 1024);
}
