//! How close each of the injection's interpolation kernels comes to an exact warp, on real
//! frames.
//!
//! No kernel warps a real image exactly (its pixels are not band-limited), and whatever the
//! kernel gets wrong is part of every injected frame, drawn anew with each frame's yaws. To
//! measure it without any estimator, every tenth left frame of the KITTI drive is warped by a
//! yaw and back by its inverse (the homography of `-alpha` undoes that of `alpha`), and the
//! result is compared with the original over the pixels both warps take from inside the
//! image. Both warps round to 8 bits, as `stereocal inject` writes them, so even an exact
//! kernel would leave about 0.4 grey levels rms. The test prints the rms difference per kernel
//! and yaw, and fails unless every Lanczos kernel comes closer than Keys' cubic and the wider
//! Lanczos closer than the narrower: the order `stereocal inject --resample` documents.
//! `bench/drives.py --resample` shows what the kernels do to the accuracy figures.
//!
//! Needs `../shared/data/real` (or `STEREOCAL_REAL_DATA`); skips loudly when absent, and fails
//! instead under `CI=true`. Run in release: `cargo test --release -p stereocal-synth --test
//! resampling -- --nocapture`.

mod common;

use common::{data_root, grey};
use image::GrayImage;
use stereocal::calib::Calibration;
use stereocal_synth::yaw_warp::{Resampling, YawWarp};

/// Kernels in the order of the fidelity the test expects.
const KERNELS: [Resampling; 3] = [
    Resampling::Bicubic,
    Resampling::Lanczos3,
    Resampling::Lanczos5,
];

/// How far inside the image both warps must take a compared pixel from (pixels): the five
/// taps a side of the widest kernel, so that no tap reads the replicated border.
const MARGIN: f64 = 5.0;

/// The rms difference (grey levels) between `img` and `img` warped by `alpha` and back.
fn round_trip_rms(img: &GrayImage, calib: &Calibration, alpha: f64, kernel: Resampling) -> f64 {
    let (forth, back) = (
        YawWarp::new(&calib.left, alpha),
        YawWarp::new(&calib.left, -alpha),
    );
    let there = forth.apply_with(img, kernel);
    let again = back.apply_with(&there, kernel);
    let (w, h) = img.dimensions();
    let (mut sum, mut n) = (0.0, 0u64);
    for y in 0..h {
        for x in 0..w {
            let (sx, sy) = back.source_of(f64::from(x), f64::from(y));
            if !back.source_inside(f64::from(x), f64::from(y), w, h, MARGIN)
                || !forth.source_inside(sx, sy, w, h, MARGIN)
            {
                continue;
            }
            let d = f64::from(again.get_pixel(x, y)[0]) - f64::from(img.get_pixel(x, y)[0]);
            sum += d * d;
            n += 1;
        }
    }
    (sum / n as f64).sqrt()
}

#[test]
fn wider_lanczos_kernels_warp_real_frames_closer_to_exact() {
    let Some(root) = data_root() else { return };
    let dir = root.join("kitti_odometry_drive");
    let calib = Calibration::load(dir.join("calib.toml")).expect("calib.toml");
    let mut names: Vec<_> = std::fs::read_dir(dir.join("left"))
        .expect("left/")
        .map(|e| e.expect("entry").path())
        .collect();
    names.sort();
    let frames: Vec<GrayImage> = names.iter().step_by(10).map(|p| grey(p)).collect();
    eprintln!(
        "round trip (warp by the yaw and back), rms grey levels over {} KITTI frames",
        frames.len()
    );
    eprintln!("yaw | bicubic (Keys) | Lanczos 3 | Lanczos 5");
    for deg in [1.0f64, 5.0, 10.0] {
        let rms: Vec<f64> = KERNELS
            .iter()
            .map(|&k| {
                let all: f64 = frames
                    .iter()
                    .map(|f| round_trip_rms(f, &calib, deg.to_radians(), k))
                    .sum();
                all / frames.len() as f64
            })
            .collect();
        eprintln!("{deg}° | {:.2} | {:.2} | {:.2}", rms[0], rms[1], rms[2]);
        assert!(
            rms.windows(2).all(|p| p[1] < p[0]),
            "at {deg}°: {rms:?} is not in the order bicubic > Lanczos 3 > Lanczos 5"
        );
    }
}
