//! Why the taps reproduce the design sigmas of table 4.2 and not its "discrete" column, checked
//! three ways: analytically (the middle DoG of a Gaussian blob must be able to be its scale
//! extremum), by running kernels with the discrete column through the fast path (they find
//! next to no point), and end to end (synthetic blobs are detected at the octave and scale
//! their size predicts).

mod common;

use stereocal_firmware::fabric::taps::{GAUSS_TAPS, TABLE_4_2_DISCRETE_TAPS, TAP_BITS};
use stereocal_firmware::fabric::{run_frame, Config, Extremum, FastFrontEnd};

/// Whether some blob variance `b` makes |D1| larger than |D0| and |D2| for cascade variance
/// increments `inc` on a base variance of `base`. For a Gaussian blob of variance `b` the
/// centre of scale `s_i` is `∝ 1 / (b + s_i)`, so `|D_i| ∝ inc_i / ((b + s_i)(b + s_{i+1}))`.
fn middle_can_win(base: f64, inc: [f64; 3]) -> bool {
    let s = [
        base,
        base + inc[0],
        base + inc[0] + inc[1],
        base + inc[0] + inc[1] + inc[2],
    ];
    (1..4000).any(|i| {
        let b = i as f64 * 0.01;
        let d = |k: usize| inc[k] / ((b + s[k]) * (b + s[k + 1]));
        d(1) > d(0) && d(1) > d(2)
    })
}

#[test]
fn the_thesis_discrete_column_never_lets_the_middle_dog_win() {
    let measured = [0.8292f64.powi(2), 0.9354f64.powi(2), 1.1040f64.powi(2)];
    for base in [1.0, 1.59] {
        assert!(!middle_can_win(base, measured), "base {base}");
    }
    let ours: Vec<f64> = GAUSS_TAPS[1..]
        .iter()
        .map(|t| (8 * t[0] as u32 + 2 * t[1] as u32) as f64 / (1u32 << TAP_BITS) as f64)
        .collect();
    assert!(middle_can_win(1.0, [ours[0], ours[1], ours[2]]));
}

/// Points the fast path finds on `img` with kernels `taps` and the default configuration.
fn points_with(taps: [[u16; 5]; 4], img: &[u8], w: usize, h: usize) -> usize {
    let mut fe =
        Box::new(FastFrontEnd::<640, 320, 160, 80>::with_kernels(taps).expect("symmetric"));
    common::run(&mut *fe, &Config::new(w as u16, h as u16), img)
        .points
        .len()
}

#[test]
fn asymmetric_or_unnormalised_kernels_are_refused() {
    let mut taps = GAUSS_TAPS;
    taps[2] = [56, 249, 412, 250, 57];
    assert!(FastFrontEnd::<64, 32, 16, 8>::with_kernels(taps).is_none());
    taps[2] = [57, 249, 414, 249, 57];
    assert!(FastFrontEnd::<64, 32, 16, 8>::with_kernels(taps).is_none());
    assert!(FastFrontEnd::<64, 32, 16, 8>::with_kernels(GAUSS_TAPS).is_some());
}

#[test]
fn the_thesis_discrete_column_finds_next_to_nothing_end_to_end() {
    // The textured test image, and (when the data set is present) a 640x480 crop of a real
    // frame: hundreds of points with the fabric's taps, next to none with table 4.2's
    // discrete column.
    let mut images = vec![(common::random_image(320, 240, 7), 320, 240)];
    if let Some((img, iw, ih)) = common::real_image() {
        images.push((common::fit(&img, iw, ih, 640, 480), 640, 480));
    }
    for (img, w, h) in images {
        let ours = points_with(GAUSS_TAPS, &img, w, h);
        let thesis = points_with(TABLE_4_2_DISCRETE_TAPS, &img, w, h);
        eprintln!("{w}x{h}: {ours} points with the design column, {thesis} with the discrete");
        assert!(
            ours >= 100,
            "{w}x{h}: only {ours} points with the fabric's taps"
        );
        assert!(
            thesis * 20 <= ours,
            "{w}x{h}: the discrete column found {thesis} points, the design {ours}"
        );
    }
}

/// A dark-on-bright Gaussian blob of deviation `sigma` at the image centre.
fn blob(w: usize, h: usize, sigma: f64) -> Vec<u8> {
    let (cx, cy) = (w as f64 / 2.0 + 0.3, h as f64 / 2.0 - 0.2);
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f64, (i / w) as f64);
            let r2 = (x - cx).powi(2) + (y - cy).powi(2);
            (200.0 - 150.0 * (-r2 / (2.0 * sigma * sigma)).exp()).round() as u8
        })
        .collect()
}

#[test]
fn blobs_are_found_at_the_predicted_octave_and_position() {
    // Sub-pixel check: the refined position must be within 0.1 octave pixel of the centre.
    let (w, h) = (128usize, 128usize);
    let mut fe = Box::new(FastFrontEnd::<128, 64, 32, 16>::new());
    // Middle DoG of octave k spans base variances 4^k·(k², k⁴) with k = 2^(1/3): a blob of
    // σ_b is an extremum where σ_b² + 0.25 (camera) sits near 4^k·k^3 = 2·4^k.
    for (sigma, octave) in [(1.4f64, 0u8), (2.8, 1), (5.6, 2)] {
        let img = blob(w, h, sigma);
        let cfg = Config::new(w as u16, h as u16);
        let mut pts: Vec<Extremum> = Vec::new();
        run_frame(
            &mut *fe,
            &cfg,
            &img,
            &mut |p| pts.extend_from_slice(p),
            &mut |_| {},
        )
        .unwrap();
        let near: Vec<&Extremum> = pts
            .iter()
            .filter(|p| {
                let s = (1u32 << p.octave) as f64;
                let x = (p.x as f64 + p.dx.to_num::<f64>()) * s;
                let y = (p.y as f64 + p.dy.to_num::<f64>()) * s;
                (x - 64.3).abs() < 0.1 * s && (y - 63.8).abs() < 0.1 * s
            })
            .collect();
        eprintln!(
            "blob sigma {sigma}: {:?}",
            near.iter()
                .map(|p| (
                    p.octave,
                    p.x,
                    p.y,
                    p.dx.to_num::<f64>(),
                    p.dy.to_num::<f64>(),
                    p.ds.to_num::<f64>()
                ))
                .collect::<Vec<_>>()
        );
        assert!(
            near.iter().any(|p| p.octave == octave && p.dog > 0),
            "blob sigma {sigma} not found in octave {octave}: {pts:?}"
        );
    }
}
