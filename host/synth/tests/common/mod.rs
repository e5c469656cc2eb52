//! What the real-data tests of this crate share: where the data is, loading an image, and the
//! fabric's fast path turned into a host `FeatureFrame`.

use std::io::Write;
use std::path::PathBuf;

use image::GrayImage;
use stereocal::features::{FeatureFrame, Gradients, Keypoint, SobelPlane};
use stereocal_firmware::fabric::{run_frame, Config, FastFrontEnd};

/// The real data: `STEREOCAL_REAL_DATA`, or `../shared/data/real` beside the repository.
/// `None` with a loud skip when it is absent, a panic instead under `CI=true`.
pub fn data_root() -> Option<PathBuf> {
    let root = std::env::var_os("STEREOCAL_REAL_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../../shared/data/real"
            ))
        });
    if root.join("eth3d_two_view").is_dir() {
        return Some(root);
    }
    if std::env::var("CI").as_deref() == Ok("true") {
        panic!(
            "real data missing at {} (required under CI=true)",
            root.display()
        );
    }
    // Straight to stderr: the test harness captures `eprintln!`, and a skip must be seen.
    let _ = writeln!(
        std::io::stderr(),
        "\n*** SKIPPED: real data not found at {} — set STEREOCAL_REAL_DATA ***\n",
        root.display()
    );
    None
}

/// The image at `path` in 8-bit grey.
pub fn grey(path: &std::path::Path) -> GrayImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .into_luma8()
}

/// Adaptor: the fabric fast path's extrema and Sobel stream → a host `FeatureFrame` with
/// full Sobel planes. `keep` filters keypoints by full-resolution position.
#[allow(dead_code)] // Each test file compiles this module on its own and uses what it needs.
pub fn features(img: &GrayImage, index: u64, keep: &dyn Fn(f32, f32) -> bool) -> FeatureFrame {
    let (w, h) = img.dimensions();
    features_at(
        img,
        index,
        keep,
        Config::new(w as u16, h as u16).sobel_scale,
    )
}

/// [`features`] with the Sobel unit reading Gaussian scale `sobel_scale` (0..=3).
pub fn features_at(
    img: &GrayImage,
    index: u64,
    keep: &dyn Fn(f32, f32) -> bool,
    sobel_scale: u8,
) -> FeatureFrame {
    let (w, h) = img.dimensions();
    let config = Config {
        sobel_scale,
        ..Config::new(w as u16, h as u16)
    };
    let mut fe = Box::new(FastFrontEnd::<1280, 640, 320, 160>::new());
    let mut points = Vec::new();
    let mut sobel = Vec::new();
    let overflow = run_frame(
        &mut *fe,
        &config,
        img.as_raw(),
        &mut |p| points.extend_from_slice(p),
        &mut |s| sobel.extend(s.pixels()),
    )
    .expect("fabric fast path");
    assert_eq!(
        overflow.points + overflow.sobel,
        0,
        "fabric FIFO overflow {overflow:?}"
    );
    let mut planes: Vec<SobelPlane> = Vec::new();
    for octave in 0..config.octaves {
        let (pw, ph) = (w.div_ceil(1 << octave), h.div_ceil(1 << octave));
        let mut mag = vec![0u8; (pw * ph) as usize];
        let mut ori = vec![0u8; (pw * ph) as usize];
        for s in sobel.iter().filter(|s| s.octave == octave) {
            let i = s.y as usize * pw as usize + s.x as usize;
            if i < mag.len() {
                mag[i] = s.magnitude;
                ori[i] = s.orientation;
            }
        }
        planes.push(SobelPlane::new(octave, pw, ph, mag, ori).expect("plane"));
    }
    let keypoints: Vec<Keypoint> = points
        .iter()
        .map(|p| {
            let s = (1u32 << p.octave) as f32;
            Keypoint {
                x: (p.x as f32 + p.dx.to_num::<f32>()) * s,
                y: (p.y as f32 + p.dy.to_num::<f32>()) * s,
                octave: p.octave,
                scale: p.scale as f32 + p.ds.to_num::<f32>(),
                dog: p.dog as f32 / 256.0,
            }
        })
        .filter(|k| {
            keep(k.x, k.y)
                && k.x >= 0.0
                && k.y >= 0.0
                && k.x <= (w - 1) as f32
                && k.y <= (h - 1) as f32
        })
        .collect();
    FeatureFrame::new(
        index,
        index * 33_333,
        w,
        h,
        keypoints,
        Gradients::Planes(planes),
    )
    .expect("frame")
}
