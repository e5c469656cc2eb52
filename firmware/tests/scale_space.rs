//! Why the taps reproduce the design sigmas of table 4.2 and not its "discrete" column, checked
//! two ways: analytically (the middle DoG of a Gaussian blob must be able to be its scale
//! extremum) and end to end (synthetic blobs are detected at the octave and scale their size
//! predicts).

use stereocal_firmware::fabric::taps::{GAUSS_TAPS, TAP_BITS};
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
