//! Per-frame-pair cost of the host estimator at 500 keypoints per image.
//!
//! `match+E+RANSAC+Kalman` is the budgeted part (≤ 1 ms): matching of precomputed descriptors,
//! calibrated coordinates, RANSAC, the robust constrained refinement and a Kalman step.
//! Descriptors, the sub-pixel refinement and the whole estimate are measured separately.
//! The frames are synthetic (a textured gradient field seen by two cameras 9 px apart), so the
//! benchmark needs no data files.

use criterion::{criterion_group, criterion_main, Criterion};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use stereocal::calib::{Calibration, CameraIntrinsics, Extrinsics};
use stereocal::descriptor::{describe, DescriptorConfig};
use stereocal::estimator::{EstimatorConfig, VergeEstimator};
use stereocal::features::{FeatureFrame, Gradients, Keypoint, SobelPlane};
use stereocal::kalman::{KalmanConfig, Measurement, VergeFilter};
use stereocal::matching::{match_descriptors, MatchConfig};
use stereocal::subpixel::{refine_pair, SubpixelConfig};

const W: u32 = 640;
const H: u32 = 480;
const KEYPOINTS: usize = 500;
const DISPARITY: i32 = 9;

/// Disparity of image row `y`: a slanted plane, like a road, nearer at the bottom. A constant
/// disparity (a fronto-parallel plane) would leave the verge undetermined: every verge in a
/// one-parameter family fits such matches exactly.
fn disparity(y: i32) -> i32 {
    DISPARITY + y / 40
}

/// A smooth random gradient field; `shift(y)` moves row `y`'s content left by that many
/// pixels.
fn plane(seed: u64, shift: impl Fn(i32) -> i32) -> SobelPlane {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let waves: Vec<(f32, f32, f32, f32)> = (0..12)
        .map(|_| {
            (
                rng.random_range(0.05..0.6),
                rng.random_range(0.05..0.6),
                rng.random_range(0.0..std::f32::consts::TAU),
                rng.random_range(10.0..30.0),
            )
        })
        .collect();
    let mut mag = Vec::with_capacity((W * H) as usize);
    let mut ori = Vec::with_capacity((W * H) as usize);
    for y in 0..H as i32 {
        for x in 0..W as i32 {
            let xs = (x + shift(y)) as f32;
            let v: f32 = waves
                .iter()
                .map(|(a, b, p, amp)| amp * (a * xs + b * y as f32 + p).sin())
                .sum();
            mag.push((v.abs() * 0.8).min(255.0) as u8);
            ori.push(((v * 3.0).rem_euclid(64.0)) as u8);
        }
    }
    SobelPlane::new(0, W, H, mag, ori).expect("plane size")
}

fn frames() -> (FeatureFrame, FeatureFrame) {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut left = Vec::new();
    let mut right = Vec::new();
    for _ in 0..KEYPOINTS {
        let x: f32 = rng.random_range(30.0..(W as f32 - 30.0));
        let y: f32 = rng.random_range(20.0..(H as f32 - 20.0));
        let k = Keypoint {
            x,
            y,
            octave: 0,
            scale: 1.0,
            dog: 5.0,
        };
        left.push(k);
        right.push(Keypoint {
            x: x - disparity(y as i32) as f32,
            ..k
        });
    }
    let lf = FeatureFrame::new(0, 0, W, H, left, Gradients::Planes(vec![plane(7, |_| 0)]));
    let rf = FeatureFrame::new(
        0,
        0,
        W,
        H,
        right,
        Gradients::Planes(vec![plane(7, disparity)]),
    );
    (lf.expect("left frame"), rf.expect("right frame"))
}

fn bench(c: &mut Criterion) {
    let (lf, rf) = frames();
    let cam = CameraIntrinsics::pinhole(600.0, 600.0, W as f64 / 2.0, H as f64 / 2.0);
    let calib = Calibration {
        baseline_m: 0.3,
        left: cam,
        right: cam,
        extrinsics: Extrinsics::default(),
    };
    let config = EstimatorConfig::default();
    let estimator = VergeEstimator::new(calib, config);
    // The fixed band the matcher's benchmark has always timed (a rectified pair's rows).
    let rows = |k: &stereocal::features::Keypoint| [k.y - 24.0, k.y + 24.0];
    let dl = describe(&lf, &DescriptorConfig::default());
    let dr = describe(&rf, &DescriptorConfig::default());
    let matches = match_descriptors(
        &dl,
        lf.keypoints(),
        &dr,
        rf.keypoints(),
        &MatchConfig::default(),
        &rows,
    );
    assert!(matches.len() > 300, "{} matches", matches.len());
    let pairs: Vec<([f64; 2], [f64; 2])> = matches
        .iter()
        .map(|m| {
            let a = lf.keypoints()[m.left as usize];
            let b = rf.keypoints()[m.right as usize];
            ([a.x as f64, a.y as f64], [b.x as f64, b.y as f64])
        })
        .collect();

    // The timed estimate must be a real one: parallel cameras, verge 0.
    let check = estimator
        .estimate_from_pixels(&pairs)
        .expect("the benchmark's pairs give an estimate");
    assert!(check.verge_deg.abs() < 0.01, "verge {}", check.verge_deg);
    let full = estimator
        .estimate(&lf, &rf)
        .expect("the benchmark's frames give an estimate");
    assert!(full.verge_deg.abs() < 0.01, "verge {}", full.verge_deg);

    c.bench_function("describe 2x500 (128)", |b| {
        b.iter(|| {
            (
                describe(black_box(&lf), &DescriptorConfig::default()),
                describe(black_box(&rf), &DescriptorConfig::default()),
            )
        })
    });
    c.bench_function("match+E+RANSAC+Kalman", |b| {
        let mut t = 0u64;
        let mut filter = VergeFilter::new(KalmanConfig::default());
        b.iter(|| {
            let m = match_descriptors(
                black_box(&dl),
                lf.keypoints(),
                black_box(&dr),
                rf.keypoints(),
                &config.matching,
                &rows,
            );
            let p: Vec<([f64; 2], [f64; 2])> = m
                .iter()
                .map(|m| {
                    let a = lf.keypoints()[m.left as usize];
                    let b = rf.keypoints()[m.right as usize];
                    ([a.x as f64, a.y as f64], [b.x as f64, b.y as f64])
                })
                .collect();
            let est = estimator.estimate_from_pixels(&p).ok();
            t += 33_333;
            filter
                .step(
                    t,
                    est.map(|e| Measurement {
                        verge_deg: e.verge_deg,
                        sigma_deg: e.sigma_deg,
                    }),
                )
                .ok()
        })
    });
    c.bench_function("match only", |b| {
        b.iter(|| {
            match_descriptors(
                black_box(&dl),
                lf.keypoints(),
                black_box(&dr),
                rf.keypoints(),
                &config.matching,
                &rows,
            )
        })
    });
    c.bench_function("E+RANSAC+refine only", |b| {
        b.iter(|| estimator.estimate_from_pixels(black_box(&pairs)).ok())
    });
    let (pl, pr) = (lf.plane(0).expect("plane"), rf.plane(0).expect("plane"));
    let refine_all = |config: &SubpixelConfig| {
        pairs
            .iter()
            .filter_map(|(l, r)| {
                refine_pair(
                    pl,
                    pr,
                    [l[0] as f32, l[1] as f32],
                    [r[0] as f32, r[1] as f32],
                    &stereocal::subpixel::IDENTITY,
                    config,
                )
            })
            .count()
    };
    let gradient = SubpixelConfig {
        disparity_gradient: true,
        ..SubpixelConfig::default()
    };
    for (name, config) in [
        ("subpixel refine (all matches)", SubpixelConfig::default()),
        (
            "subpixel refine, disparity gradient (all matches)",
            gradient,
        ),
    ] {
        assert!(refine_all(&config) > pairs.len() / 2, "most matches refine");
        c.bench_function(name, |b| b.iter(|| refine_all(&config)));
    }
    c.bench_function(
        "full estimate (describe+match+subpixel+RANSAC+refine)",
        |b| b.iter(|| estimator.estimate(black_box(&lf), black_box(&rf)).ok()),
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
