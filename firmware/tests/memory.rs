//! Static RAM of the front end at 640 pixels: fabric block RAM bits and the models' bytes.

use stereocal_firmware::fabric::memory::front_end_ram_bits;
use stereocal_firmware::fabric::{FastFrontEnd, RegisterFrontEnd};

#[test]
fn front_end_at_640_fits_256_kib() {
    let bits = front_end_ram_bits(640, 4);
    let reg = core::mem::size_of::<RegisterFrontEnd<640, 320, 160, 80>>();
    let fast = core::mem::size_of::<FastFrontEnd<640, 320, 160, 80>>();
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
