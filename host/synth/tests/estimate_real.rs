//! Accuracy of the verge estimator on real street pairs with an exactly injected verge, and on
//! raw EuRoC pairs with the general model.
//!
//! Each ETH3D two-view pair (rectified) is turned into a sequence: frame `i` warps the left
//! image by `alpha_l(i)` and the right one by `alpha_r(i)` (pure-rotation homographies,
//! `stereocal_synth::inject`), runs the fabric's fast path on both images, converts its
//! output to `FeatureFrame`s directly and estimates: this test measures the estimator, not
//! the wire (`bash bench/injected_real.sh` runs the same kind of sequences through
//! `stereocal run`, wire included). The rectification leaves a constant residual angle, so
//! errors are reported after removing the median error of each scene.
//!
//! Needs `../shared/data/real` (or `STEREOCAL_REAL_DATA`), whose `geometry.json` files give each
//! data set's intrinsics and stereo pose (`docs/ARCHITECTURE.md`, "Real data"); skips loudly
//! when absent, and fails instead under `CI=true`. Run in release: `cargo test --release -p stereocal-synth --test
//! estimate_real -- --nocapture`.

mod common;

use common::{data_root, features, grey};
use image::GrayImage;
use rayon::prelude::*;
use stereocal::calib::{Calibration, CameraIntrinsics, Extrinsics};
use stereocal::estimator::{EstimatorConfig, FrameEstimate, Model, VergeEstimator};
use stereocal::kalman::{KalmanConfig, Measurement, VergeFilter};
use stereocal_synth::yaw_warp::YawWarp;

fn camera(v: &serde_json::Value) -> CameraIntrinsics {
    let f = |k: &str| {
        v[k].as_f64()
            .unwrap_or_else(|| panic!("geometry.json: missing {k}"))
    };
    let d = |i: usize| v["dist"][i].as_f64().unwrap_or(0.0);
    CameraIntrinsics {
        k1: d(0),
        k2: d(1),
        p1: d(2),
        p2: d(3),
        ..CameraIntrinsics::pinhole(f("fx"), f("fy"), f("cx"), f("cy"))
    }
}

struct Scene {
    name: &'static str,
    left: GrayImage,
    right: GrayImage,
    calib: Calibration,
}

fn eth3d_scenes(root: &std::path::Path) -> Vec<Scene> {
    let dir = root.join("eth3d_two_view");
    let geo: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("geometry.json")).expect("geometry.json"),
    )
    .expect("geometry.json is JSON");
    ["terrace", "playground"]
        .into_iter()
        .map(|name| {
            let g = &geo["scenes"][name];
            Scene {
                name,
                left: grey(&dir.join(name).join("im0.png")),
                right: grey(&dir.join(name).join("im1.png")),
                calib: Calibration {
                    baseline_m: g["stereo"]["baseline_m"].as_f64().expect("baseline"),
                    left: camera(&g["cam0"]),
                    right: camera(&g["cam1"]),
                    extrinsics: Extrinsics::default(),
                },
            }
        })
        .collect()
}

/// Margin (pixels) from the injected images' invalid border within which keypoints are dropped.
const BORDER_MARGIN: f64 = 12.0;

/// Warps the pair by (alpha_l, alpha_r) and estimates.
fn run_frame_pair(
    scene: &Scene,
    est: &VergeEstimator,
    index: u64,
    alpha_l: f64,
    alpha_r: f64,
) -> Option<FrameEstimate> {
    let (w, h) = scene.left.dimensions();
    let wl = YawWarp::new(&scene.calib.left, alpha_l);
    let wr = YawWarp::new(&scene.calib.right, alpha_r);
    let (il, ir) = rayon::join(|| wl.apply(&scene.left), || wr.apply(&scene.right));
    let (fl, fr) = rayon::join(
        || {
            features(&il, index, &|x, y| {
                wl.source_inside(x as f64, y as f64, w, h, BORDER_MARGIN)
            })
        },
        || {
            features(&ir, index, &|x, y| {
                wr.source_inside(x as f64, y as f64, w, h, BORDER_MARGIN)
            })
        },
    );
    est.estimate(&fl, &fr).ok()
}

#[derive(Debug)]
struct Stats {
    frames: usize,
    estimated: usize,
    residual: f64,
    median: f64,
    p95: f64,
    max: f64,
    mean_matches: f64,
}

fn stats(errors: &[Option<f64>], matches: &[usize]) -> Stats {
    let mut e: Vec<f64> = errors.iter().flatten().copied().collect();
    let frames = errors.len();
    let estimated = e.len();
    e.sort_by(f64::total_cmp);
    let residual = if e.is_empty() {
        f64::NAN
    } else {
        e[e.len() / 2]
    };
    let mut abs: Vec<f64> = e.iter().map(|v| (v - residual).abs()).collect();
    abs.sort_by(f64::total_cmp);
    let pick = |q: f64| {
        abs.get(((abs.len() as f64 - 1.0) * q).round() as usize)
            .copied()
            .unwrap_or(f64::NAN)
    };
    Stats {
        frames,
        estimated,
        residual,
        median: pick(0.5),
        p95: pick(0.95),
        max: abs.last().copied().unwrap_or(f64::NAN),
        mean_matches: matches.iter().sum::<usize>() as f64 / matches.len().max(1) as f64,
    }
}

const FRAMES: usize = 32;

#[test]
fn injected_verge_on_street_pairs() {
    let Some(root) = data_root() else { return };
    let config = EstimatorConfig::default();
    let mut all_errors = Vec::new();
    let mut fixed_spans = Vec::new();
    for scene in eth3d_scenes(&root) {
        let est = VergeEstimator::new(scene.calib, config);
        // Moving head: independent yaws, verge over about ±3°.
        let results: Vec<(f64, Option<FrameEstimate>)> = (0..FRAMES)
            .into_par_iter()
            .map(|i| {
                let phase = i as f64 / FRAMES as f64 * std::f64::consts::TAU;
                let al = (1.6 * phase.sin()).to_radians();
                let ar = (-1.4 * (phase + 0.7).sin() + 0.3).to_radians();
                (al - ar, run_frame_pair(&scene, &est, i as u64, al, ar))
            })
            .collect();
        let errors: Vec<Option<f64>> = results
            .iter()
            .map(|(truth, e)| e.as_ref().map(|e| e.verge_deg - truth.to_degrees()))
            .collect();
        let matches: Vec<usize> = results
            .iter()
            .filter_map(|(_, e)| e.as_ref().map(|e| e.used))
            .collect();
        let s = stats(&errors, &matches);
        println!(
            "{:<10} moving: {}/{} estimated, residual {:+.4}°, |err| median {:.4}° p95 {:.4}° max {:.4}°, {:.0} matches/frame",
            scene.name, s.estimated, s.frames, s.residual, s.median, s.p95, s.max, s.mean_matches
        );
        for (i, (t, e)) in results.iter().enumerate() {
            if let Some(e) = e {
                println!(
                    "  {i:2} truth {:+.3}° est {:+.4}° err {:+.4}° σ {:.4}° used {} inl {} res {:.3}px",
                    t.to_degrees(),
                    e.verge_deg,
                    e.verge_deg - t.to_degrees() - s.residual,
                    e.sigma_deg,
                    e.used,
                    e.inliers,
                    e.residual_px
                );
            }
        }
        all_errors.extend(errors.iter().map(|e| e.map(|v| v - s.residual)));
        // The same moving sequence through the Kalman filter (30 fps timestamps).
        let mut filter = VergeFilter::new(KalmanConfig::default());
        let filtered: Vec<Option<f64>> = results
            .iter()
            .enumerate()
            .map(|(i, (truth, e))| {
                let m = e.as_ref().map(|e| Measurement {
                    verge_deg: e.verge_deg - s.residual,
                    sigma_deg: e.sigma_deg,
                });
                let o = filter
                    .step(i as u64 * 33_333, m)
                    .expect("time runs forward");
                o.map(|o| o.verge_deg - truth.to_degrees())
            })
            .collect();
        let fstats = stats(&filtered, &[]);
        println!(
            "{:<10} moving, filtered: |err| median {:.4}° max {:.4}° (residual {:+.4}°)",
            scene.name, fstats.median, fstats.max, fstats.residual
        );

        // Fixed cameras: constant verge 1.5°, the head's common yaw varies (the view changes).
        let fixed: Vec<Option<FrameEstimate>> = (0..FRAMES)
            .into_par_iter()
            .map(|i| {
                let common = 1.0 * (i as f64 / FRAMES as f64 * std::f64::consts::TAU).sin();
                run_frame_pair(
                    &scene,
                    &est,
                    i as u64,
                    (common + 0.75).to_radians(),
                    (common - 0.75).to_radians(),
                )
            })
            .collect();
        let mut filter = VergeFilter::new(KalmanConfig::default());
        let mut filtered = Vec::new();
        for (i, e) in fixed.iter().enumerate() {
            let m = e.as_ref().map(|e| Measurement {
                verge_deg: e.verge_deg,
                sigma_deg: e.sigma_deg,
            });
            if let Some(o) = filter
                .step(i as u64 * 33_333, m)
                .expect("time runs forward")
            {
                filtered.push(o.verge_deg);
            }
        }
        let settled = &filtered[filtered.len().min(8)..];
        let span = settled.iter().cloned().fold(f64::MIN, f64::max)
            - settled.iter().cloned().fold(f64::MAX, f64::min);
        let raw: Vec<Option<f64>> = fixed
            .iter()
            .map(|e| e.as_ref().map(|e| e.verge_deg - 1.5))
            .collect();
        let fs = stats(&raw, &[]);
        println!(
            "{:<10} fixed 1.5°: {}/{} estimated, raw |err| median {:.4}° max {:.4}°, filtered span {:.4}° (after 8 frames)",
            scene.name, fs.estimated, fs.frames, fs.median, fs.max, span
        );
        fixed_spans.push(span);
    }
    let total = stats(&all_errors, &[]);
    let fraction = total.estimated as f64 / total.frames as f64;
    println!(
        "ALL moving: {:.1}% estimated, |err| median {:.4}° p95 {:.4}° max {:.4}°",
        100.0 * fraction,
        total.median,
        total.p95,
        total.max
    );
    assert!(
        fraction >= 0.95,
        "only {:.1}% of frames estimated",
        100.0 * fraction
    );
    assert!(
        total.median <= MEDIAN_LIMIT_DEG,
        "median {:.4}°",
        total.median
    );
    assert!(total.max <= MAX_LIMIT_DEG, "max {:.4}°", total.max);
    for span in fixed_spans {
        assert!(
            span <= FIXED_SPAN_LIMIT_DEG,
            "fixed-camera filtered span {span:.4}°"
        );
    }
}

const MEDIAN_LIMIT_DEG: f64 = 0.02;
const MAX_LIMIT_DEG: f64 = 0.08;
const FIXED_SPAN_LIMIT_DEG: f64 = 0.03;

#[test]
fn euroc_raw_pairs_with_the_general_model() {
    let Some(root) = data_root() else { return };
    let dir = root.join("euroc_pairs");
    let geo: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("geometry.json")).expect("geometry.json"),
    )
    .expect("JSON");
    let calib = Calibration {
        baseline_m: geo["stereo"]["baseline_m"].as_f64().expect("baseline"),
        left: camera(&geo["cam0"]),
        right: camera(&geo["cam1"]),
        extrinsics: Extrinsics::default(),
    };
    let ypr = &geo["stereo"]["yaw_pitch_roll_deg"];
    let truth_verge = -ypr[0].as_f64().expect("yaw");
    let truth_pitch = ypr[1].as_f64().expect("pitch");
    let general = VergeEstimator::new(
        calib,
        EstimatorConfig {
            model: Model::General,
            ..EstimatorConfig::default()
        },
    );
    let constrained = VergeEstimator::new(calib, EstimatorConfig::default());
    let mut errs = Vec::new();
    for name in ["lcd0", "lcd1", "lcd2", "lcd3", "sf0", "sf1"] {
        let l = grey(&dir.join(format!("{name}_left.png")));
        let r = grey(&dir.join(format!("{name}_right.png")));
        let fl = features(&l, 0, &|_, _| true);
        let fr = features(&r, 0, &|_, _| true);
        let g = general.estimate(&fl, &fr);
        let c = constrained.estimate(&fl, &fr);
        match &g {
            Ok(g) => {
                let p = g.pose.expect("general pose");
                println!(
                    "{name}: general verge {:+.4}° (truth {:+.4}°) pitch {:+.4}° (truth {:+.4}°) σ {:.4}° used {} inliers {} res {:.3}px | constrained {}",
                    g.verge_deg,
                    truth_verge,
                    p.pitch.to_degrees(),
                    truth_pitch,
                    g.sigma_deg,
                    g.used,
                    g.inliers,
                    g.residual_px,
                    c.as_ref().map(|c| format!("{:+.4}° res {:.3}px", c.verge_deg, c.residual_px)).unwrap_or_else(|e| e.to_string())
                );
                errs.push((g.verge_deg - truth_verge).abs());
                assert!(
                    (p.pitch.to_degrees() - truth_pitch).abs() < 0.1,
                    "{name}: pitch {p:?}"
                );
            }
            Err(e) => println!("{name}: no estimate ({e})"),
        }
    }
    assert!(
        errs.len() >= 5,
        "only {} of 6 EuRoC pairs estimated",
        errs.len()
    );
    let worst = errs.iter().cloned().fold(0.0, f64::max);
    println!("EuRoC general model: worst |verge error| {worst:.4}°");
    assert!(
        worst < EUROC_LIMIT_DEG,
        "EuRoC worst verge error {worst:.4}°"
    );
}

const EUROC_LIMIT_DEG: f64 = 0.1;
