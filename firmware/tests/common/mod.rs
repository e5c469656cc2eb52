//! Shared helpers of the integration tests.
#![allow(dead_code)]

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use stereocal_firmware::fabric::{run_frame, Config, Extremum, FrontEnd, Overflow, SobelEntry};

/// Everything a frame produced, each stream in the order the FIFO gave it.
#[derive(Debug, PartialEq, Eq)]
pub struct FrameOut {
    pub points: Vec<Extremum>,
    pub sobel: Vec<SobelEntry>,
    pub overflow: Overflow,
}

pub fn run<F: FrontEnd + ?Sized>(fe: &mut F, cfg: &Config, img: &[u8]) -> FrameOut {
    let mut points: Vec<Extremum> = Vec::new();
    let mut sobel: Vec<SobelEntry> = Vec::new();
    let overflow = run_frame(
        fe,
        cfg,
        img,
        &mut |p| points.extend_from_slice(p),
        &mut |s| sobel.extend(s.pixels()),
    )
    .expect("frame runs");
    FrameOut {
        points,
        sobel,
        overflow,
    }
}

/// Smooth random texture: a sum of random blobs over noise, so there are real extrema.
pub fn random_image(w: usize, h: usize, seed: u64) -> Vec<u8> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut f = vec![0f32; w * h];
    let blobs = (w * h / 200).max(4);
    for _ in 0..blobs {
        let (cx, cy) = (
            rng.random_range(0.0..w as f32),
            rng.random_range(0.0..h as f32),
        );
        let s = rng.random_range(1.0f32..6.0);
        let a = rng.random_range(-120.0f32..120.0);
        let r = (3.0 * s) as i32 + 1;
        for y in (cy as i32 - r).max(0)..(cy as i32 + r).min(h as i32) {
            for x in (cx as i32 - r).max(0)..(cx as i32 + r).min(w as i32) {
                let d2 = (x as f32 - cx).powi(2) + (y as f32 - cy).powi(2);
                f[y as usize * w + x as usize] += a * (-d2 / (2.0 * s * s)).exp();
            }
        }
    }
    f.iter()
        .map(|&v| (128.0 + v + rng.random_range(-8.0f32..8.0)).clamp(0.0, 255.0) as u8)
        .collect()
}

/// Uniform noise.
pub fn noise_image(w: usize, h: usize, seed: u64) -> Vec<u8> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..w * h).map(|_| rng.random::<u8>()).collect()
}

/// Says that a check is skipped, straight to stderr: the test harness captures `eprintln!`,
/// and a skip must be seen in a plain `cargo test` run.
fn loud_skip(what: &str) {
    use std::io::Write;
    // A closed stderr has nobody to tell.
    let _ = writeln!(std::io::stderr(), "\n*** SKIPPED {what} ***\n");
}

/// The real test image as 8-bit grey, or `None` (with a loud message) when the data set is
/// absent outside CI. Under `CI=true` its absence is a failure.
pub fn real_image() -> Option<(Vec<u8>, usize, usize)> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/data/real/eth3d_two_view/terrace/im0.png"
    );
    match Some(path).filter(|p| std::path::Path::new(p).exists()) {
        Some(p) => {
            let img = image::open(p).expect("real image decodes").into_luma8();
            let (w, h) = img.dimensions();
            Some((img.into_raw(), w as usize, h as usize))
        }
        None => {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "real image missing under CI=true: {path}"
            );
            loud_skip(&format!("real-image check: {path} not found"));
            None
        }
    }
}

/// The first left frame of the KITTI drive (1241x376) as 8-bit grey, or `None` (with a loud
/// message) when the data set is absent outside CI. Under `CI=true` its absence is a failure.
pub fn kitti_image() -> Option<(Vec<u8>, usize, usize)> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../shared/data/real/kitti_odometry_drive/left/000000.png"
    );
    if !std::path::Path::new(path).exists() {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "KITTI frame missing under CI=true: {path}"
        );
        loud_skip(&format!("KITTI-frame check: {path} not found"));
        return None;
    }
    let img = image::open(path).expect("KITTI frame decodes").into_luma8();
    let (w, h) = img.dimensions();
    Some((img.into_raw(), w as usize, h as usize))
}

/// Centre crop / pad (by edge replication) of a grey image to `w x h`.
pub fn fit(img: &[u8], iw: usize, ih: usize, w: usize, h: usize) -> Vec<u8> {
    let (ox, oy) = (
        (iw as isize - w as isize) / 2,
        (ih as isize - h as isize) / 2,
    );
    let mut out = vec![0u8; w * h];
    for y in 0..h {
        for x in 0..w {
            let sx = (x as isize + ox).clamp(0, iw as isize - 1) as usize;
            let sy = (y as isize + oy).clamp(0, ih as isize - 1) as usize;
            out[y * w + x] = img[sy * iw + sx];
        }
    }
    out
}
