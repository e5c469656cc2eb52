//! The latency figures of `fabric::latency` equal the clocks the register-level model takes,
//! and the 640x240 @ 54 MHz figure (thesis: ~40 µs) is printed.

mod common;

use stereocal_firmware::fabric::latency::{clocks_to_ns, first_pixel_of_last_octave, sample_clock};
use stereocal_firmware::fabric::{run_frame, Config, RegisterFrontEnd};

#[test]
fn model_takes_the_computed_number_of_clocks() {
    let mut fe = Box::new(RegisterFrontEnd::<96, 48, 24, 12>::new());
    for &(w, h, oct) in &[
        (96u16, 64u16, 4u8),
        (40, 30, 3),
        (25, 9, 2),
        (13, 11, 2),
        (96, 12, 2),
    ] {
        let mut cfg = Config::new(w, h);
        cfg.octaves = oct;
        let img = common::random_image(w as usize, h as usize, 1);
        run_frame(&mut *fe, &cfg, &img, &mut |_| {}, &mut |_| {}).unwrap();
        for k in 0..oct {
            assert_eq!(
                fe.first_input_clock(k as usize),
                Some(sample_clock(w, h, k, 0)),
                "{w}x{h}: first input of octave {k}"
            );
        }
    }
}

#[test]
fn figure_640x240_at_54_mhz() {
    let clocks = first_pixel_of_last_octave(640, 240, 4);
    let us = clocks_to_ns(clocks, 54_000_000) as f64 / 1000.0;
    eprintln!("first pixel in -> first pixel of octave 3, 640x240: {clocks} clocks = {us:.1} us at 54 MHz");
    for k in 1..4 {
        let c = sample_clock(640, 240, k, 0);
        eprintln!(
            "  octave {k} starts at clock {c} ({:.1} us, {:.2} input rows)",
            c as f64 / 54.0,
            c as f64 / 640.0
        );
    }
    // Each octave waits for 3 (octave 0: 4) cascaded column filters of 2 of its own rows, and
    // its rows arrive 2^k times slower: far above the thesis' ~40 µs, see the crate report.
    assert_eq!(clocks, sample_clock(640, 240, 3, 0));
    assert!(
        clocks > 5120,
        "at least octave 0's 4 convolvers of 2 rows each"
    );
}
