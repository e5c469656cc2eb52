//! Extremum detector, edge test and refinement: golden cubes, a property test against a
//! brute-force definition, and the whole detector against a brute-force scan of the DoG images.

mod common;

use proptest::prelude::*;
use stereocal_firmware::fabric::edge::passes_edge_test;
use stereocal_firmware::fabric::extrema::{is_extremum, Cube};
use stereocal_firmware::fabric::fast::Probe;
use stereocal_firmware::fabric::refine::refine;
use stereocal_firmware::fabric::{Config, Extremum, FastFrontEnd, FrontEnd};

fn cube_from(f: impl Fn(i32, i32, i32) -> f64) -> Cube {
    core::array::from_fn(|s| {
        core::array::from_fn(|y| {
            core::array::from_fn(|x| f(x as i32 - 1, y as i32 - 1, s as i32 - 1).round() as i16)
        })
    })
}

#[test]
fn golden_max_min_and_threshold() {
    // A peak of 10.0 grey levels (2560 Q8.8) over a 1.0 floor: a maximum for threshold < 2560.
    let mut c: Cube = [[[256; 3]; 3]; 3];
    c[1][1][1] = 2560;
    assert!(is_extremum(&c, 0));
    assert!(is_extremum(&c, 2559));
    assert!(!is_extremum(&c, 2560), "contrast must exceed the threshold");
    // One equal neighbour (in the scale below, corner) breaks a strict maximum.
    c[0][2][2] = 2560;
    assert!(!is_extremum(&c, 0));
    // The negated cube is a minimum.
    let mut m: Cube = [[[-256; 3]; 3]; 3];
    m[1][1][1] = -2560;
    assert!(is_extremum(&m, 1000));
}

#[test]
fn golden_refinement_recovers_a_quadratic_peak() {
    // D = 2000 - 400·((x-0.25)² + 2(y+0.125)² + 3(s-0.1)²) sampled on the 3x3x3 grid: the fit is
    // exact for a quadratic, so the offsets are (0.25, -0.125, 0.1) up to the rounding of the
    // samples to integers (a few 1/8192).
    let c = cube_from(|x, y, s| {
        2000.0
            - 400.0
                * ((x as f64 - 0.25).powi(2)
                    + 2.0 * (y as f64 + 0.125).powi(2)
                    + 3.0 * (s as f64 - 0.1).powi(2))
    });
    assert!(is_extremum(&c, 0));
    let [dx, dy, ds] = refine(&c, 4096).expect("well-conditioned peak");
    for (got, want) in [
        (dx.to_num::<f64>(), 0.25),
        (dy.to_num(), -0.125),
        (ds.to_num(), 0.1),
    ] {
        assert!((got - want).abs() < 4.0 / 8192.0, "{got} vs {want}");
    }
}

#[test]
fn refinement_rejects_far_offsets_and_flat_cubes() {
    let far = cube_from(|x, y, s| {
        2000.0 - 400.0 * ((x as f64 - 0.7).powi(2) + (y as f64).powi(2) + (s as f64).powi(2))
    });
    assert!(refine(&far, 4096).is_none(), "offset 0.7 > 0.5");
    assert!(refine(&far, 8191).is_some(), "accepted below 1.0");
    assert!(
        refine(&[[[5; 3]; 3]; 3], 4096).is_none(),
        "singular Hessian"
    );
}

#[test]
fn golden_edge_test() {
    // A round blob passes; a ridge along x (no curvature along x) fails; r = 0 disables.
    let blob = cube_from(|x, y, _| 1000.0 - 100.0 * (x * x + y * y) as f64);
    assert!(passes_edge_test(&blob[1], 10));
    let ridge = cube_from(|x, y, _| 1000.0 - 100.0 * (y * y) as f64 - 2.0 * (x * x) as f64);
    assert!(!passes_edge_test(&ridge[1], 10));
    assert!(passes_edge_test(&ridge[1], 0));
    // Saddle: Det < 0 fails for any r.
    let saddle = cube_from(|x, y, _| 1000.0 - 100.0 * (x * x) as f64 + 100.0 * (y * y) as f64);
    assert!(!passes_edge_test(&saddle[1], 255));
}

/// Brute-force definition: the centre is above the threshold and above the maximum of the
/// other 26 (or the mirror for minima).
fn brute(c: &Cube, t: u16) -> bool {
    let v = c[1][1][1] as i32;
    let others: Vec<i32> = (0..27)
        .filter(|&i| i != 13)
        .map(|i| c[i / 9][(i / 3) % 3][i % 3] as i32)
        .collect();
    (v > t as i32 && others.iter().all(|&o| o < v))
        || (v < -(t as i32) && others.iter().all(|&o| o > v))
}

proptest! {
    #[test]
    fn detector_matches_brute_force(vals in prop::array::uniform27(-40i16..40), t in 0u16..30) {
        let mut c: Cube = [[[0; 3]; 3]; 3];
        for (i, v) in vals.iter().enumerate() {
            c[i / 9][(i / 3) % 3][i % 3] = *v;
        }
        prop_assert_eq!(is_extremum(&c, t), brute(&c, t));
    }
}

/// Collects the DoG images of every octave.
struct Dogs {
    w: Vec<usize>,
    d: Vec<[Vec<i16>; 3]>,
}

impl Probe for Dogs {
    fn dog_row(&mut self, o: u8, i: u8, y: u16, row: &[i16]) {
        let (o, w) = (o as usize, row.len());
        self.w[o] = w;
        let img = &mut self.d[o][i as usize];
        if img.len() < (y as usize + 1) * w {
            img.resize((y as usize + 1) * w, 0);
        }
        img[y as usize * w..(y as usize + 1) * w].copy_from_slice(row);
    }
}

#[test]
fn whole_detector_equals_a_brute_force_scan_of_the_dog_images() {
    let (w, h) = (96u16, 80u16);
    let img = common::random_image(w as usize, h as usize, 3);
    let cfg = Config::new(w, h);
    let mut fe = Box::new(FastFrontEnd::<96, 48, 24, 12>::new());
    fe.start_frame(&cfg).unwrap();
    let mut probe = Dogs {
        w: vec![0; 4],
        d: (0..4).map(|_| [vec![], vec![], vec![]]).collect(),
    };
    let mut got = Vec::new();
    let drain = |fe: &mut FastFrontEnd<96, 48, 24, 12>, got: &mut Vec<Extremum>| {
        while let Some(p) = fe.pop_point() {
            got.push(p);
        }
        while fe.pop_sobel().is_some() {}
    };
    for row in img.chunks(w as usize) {
        fe.push_row_probed(row, &mut probe).unwrap();
        drain(&mut fe, &mut got);
    }
    while !fe.blank_row_probed(&mut probe) {
        drain(&mut fe, &mut got);
    }
    drain(&mut fe, &mut got);
    let mut want = Vec::new();
    for o in 0..4 {
        let ow = probe.w[o];
        let oh = probe.d[o][0].len() / ow;
        for y in 1..oh - 1 {
            for x in 1..ow - 1 {
                let c: Cube = core::array::from_fn(|s| {
                    core::array::from_fn(|dy| {
                        core::array::from_fn(|dx| probe.d[o][s][(y + dy - 1) * ow + x + dx - 1])
                    })
                });
                if brute(&c, cfg.contrast_threshold) && passes_edge_test(&c[1], cfg.edge_ratio) {
                    if let Some([dx, dy, ds]) = refine(&c, cfg.max_offset) {
                        want.push(Extremum {
                            x: x as u16,
                            y: y as u16,
                            octave: o as u8,
                            scale: 1,
                            dx,
                            dy,
                            ds,
                            dog: c[1][1][1],
                        });
                    }
                }
            }
        }
    }
    got.sort_by_key(|p| (p.octave, p.y, p.x));
    assert!(!want.is_empty());
    assert_eq!(got, want);
}
