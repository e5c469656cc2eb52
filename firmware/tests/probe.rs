//! The observation probe of the register-level model (`RegisterFrontEnd::probe`, the RTL's
//! `sc_frontend` observation ports) agrees with what the model hands out: the points and
//! Sobel pixels it records are exactly the FIFO streams, octave `k`'s subsampler output is
//! octave `k+1`'s input on the same clock, and nothing is recorded for a disabled octave.

mod common;

use stereocal_firmware::fabric::{Config, FrontEnd, RegisterFrontEnd};

#[test]
fn probe_matches_the_output_streams() {
    let (w, h) = (72u16, 52u16);
    for (octaves, sobel_scale) in [(4u8, 1u8), (2, 3)] {
        let cfg = Config {
            octaves,
            sobel_scale,
            ..Config::new(w, h)
        };
        let img = common::random_image(w as usize, h as usize, 7 + octaves as u64);
        let mut fe = Box::new(RegisterFrontEnd::<1280, 640, 320, 160>::new());
        fe.start_frame(&cfg).unwrap();
        let (mut probed_points, mut probed_sobel) = (Vec::new(), Vec::new());
        let (mut fifo_points, mut fifo_sobel) = (Vec::new(), Vec::new());
        let mut pixels = img.iter().copied();
        let mut clocks = 0u64;
        let mut done_seen = false;
        while !fe.octaves_done() {
            let pixel = pixels.next();
            fe.clock(pixel);
            clocks += 1;
            assert!(clocks < 200_000, "never done");
            let p = *fe.probe();
            if pixel.is_some() {
                assert!(p.octaves[0].en);
                assert!(!fe.octaves_done());
            }
            for (k, o) in p.octaves.iter().enumerate() {
                if !o.en || k >= octaves as usize {
                    assert_eq!(
                        *o,
                        stereocal_firmware::fabric::OctaveProbe::IDLE,
                        "octave {k}"
                    );
                    continue;
                }
                if k > 0 {
                    assert_eq!(o.g[0], p.octaves[k - 1].sub, "octave {k} input");
                }
                probed_points.extend(o.point);
                probed_sobel.extend(o.sobel);
                assert!(o.point.is_none_or(|e| e.octave as usize == k));
                assert!(o.sobel.is_none_or(|s| s.octave as usize == k));
            }
            while let Some(e) = fe.pop_point() {
                fifo_points.push(e);
            }
            while let Some(s) = fe.pop_sobel() {
                fifo_sobel.push(s);
            }
            done_seen |= fe.octaves_done();
        }
        assert!(done_seen && pixels.next().is_none());
        assert!(!probed_points.is_empty() && !probed_sobel.is_empty());
        assert_eq!(probed_points, fifo_points);
        assert_eq!(probed_sobel, fifo_sobel);
        assert_eq!(fe.overflow(), Default::default());
    }
}
