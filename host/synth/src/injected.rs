//! A sequence made from real rectified frames by injecting an exact verge per frame, written
//! in the formats every tool reads (`left/`, `right/`, `calib.toml`, `truth.csv`, and the
//! injected yaws as a head's encoders would read them in `encoders.csv`), so that `stereocal
//! run --truth` measures real-image accuracy through the whole chain.
//!
//! The frames come from one pair repeated (the view never changes, so every error that depends
//! on the view is constant) or from a recorded sequence, a drive whose content changes every
//! frame, where those errors show. The rectification leaves an unknown residual verge, so the
//! truth is exact only up to it: `stereocal run` removes the median offset before its
//! statistics, and a bench that also runs the untouched sequence can subtract the untouched
//! estimate of each frame, which cancels whatever depends on the view.
//!
//! A warped image has a border where the source ran out, which a real turning camera never
//! shows: there the warp repeats edge pixels, and features on those smears move with the
//! injected yaw in a way no geometry explains, biasing the estimate by the view. So every frame
//! is cropped to the largest rectangle that is valid in every warped image of the sequence (its
//! sides a multiple of 8, as the fabric's four octaves need), and the calibration's principal
//! points move with the crop.

use std::fs;
use std::path::Path;

use image::GrayImage;
use rayon::prelude::*;

use crate::yaw_warp::{Resampling, YawWarp};
use crate::SynthError;
use stereocal::calib::{Calibration, CameraIntrinsics};
use stereocal::encoders::write_encoders_csv;
use stereocal::image_sequence::{GrayFrame, StereoSequence};
use stereocal::output::output_dir::StagingDir;
use stereocal::output::verge_csv::write_truth_csv;

/// How the two cameras move over the sequence.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// Each camera yaws on its own slow sinusoid: the verge sweeps about ±3°.
    Moving,
    /// Verge fixed at 1.5° while the head's common yaw sweeps ±1° (the view changes).
    Fixed,
    /// The verge swings ±10° (one period over the sequence), each camera taking half of it:
    /// the range the issue's targets name for wide verges.
    Swing,
}

/// Where the frames to warp come from.
#[derive(Debug, Clone, Copy)]
pub enum Source<'a> {
    /// One pair, warped anew for every frame.
    Pair {
        left: &'a GrayImage,
        right: &'a GrayImage,
    },
    /// A recorded sequence: output frame `i` is its pair `i`.
    Sequence(&'a StereoSequence),
}

impl Source<'_> {
    /// Pair `frame` and its size, checked against `first` (frame 0's size) when given.
    fn pair(
        &self,
        frame: usize,
        first: Option<(u32, u32)>,
    ) -> Result<(GrayImage, GrayImage), SynthError> {
        let (left, right) = match self {
            Source::Pair { left, right } => ((*left).clone(), (*right).clone()),
            Source::Sequence(seq) => {
                let size = first.map(|(w, h)| (w as usize, h as usize));
                let (l, r) = seq.pair(frame, size)?;
                (to_image(l, frame)?, to_image(r, frame)?)
            }
        };
        if left.dimensions() != right.dimensions() {
            return Err(SynthError::InvalidConfig {
                field: "images",
                reason: format!(
                    "frame {frame}: left is {:?}, right is {:?}; a pair must have one size",
                    left.dimensions(),
                    right.dimensions()
                ),
            });
        }
        Ok((left, right))
    }
}

fn to_image(g: GrayFrame, frame: usize) -> Result<GrayImage, SynthError> {
    let (w, h) = (g.width, g.height);
    GrayImage::from_raw(w as u32, h as u32, g.pixels).ok_or(SynthError::InvalidConfig {
        field: "images",
        reason: format!("frame {frame}: a {w}x{h} image decoded to a different number of pixels"),
    })
}

/// A head motion over the sequence and where in its period frame 0 starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trajectory {
    pub motion: Motion,
    /// The motion's phase at frame 0 (degrees of its period): the same motion from another
    /// instant, which puts other yaws on each frame, so that a figure measured on injected
    /// frames can be drawn again.
    pub phase_deg: f64,
}

impl From<Motion> for Trajectory {
    /// The motion from the start of its period.
    fn from(motion: Motion) -> Self {
        Self {
            motion,
            phase_deg: 0.0,
        }
    }
}

impl Trajectory {
    /// The yaws (radians) of frame `i` of `frames`: (alpha_l, alpha_r).
    pub fn yaws(&self, i: usize, frames: usize) -> (f64, f64) {
        let phase =
            self.phase_deg.to_radians() + i as f64 / frames.max(1) as f64 * std::f64::consts::TAU;
        let (l, r) = match self.motion {
            Motion::Moving => (1.6 * phase.sin(), -1.4 * (phase + 0.7).sin() + 0.3),
            Motion::Fixed => {
                let common = phase.sin();
                (common + 0.75, common - 0.75)
            }
            Motion::Swing => {
                let half = 5.0 * phase.sin();
                (half, -half)
            }
        };
        (l.to_radians(), r.to_radians())
    }
}

/// Sides of the crop are multiples of this (2^(octaves-1) for the fabric's four octaves).
const CROP_STEP: u32 = 8;

/// Distance (pixels) a valid output pixel's source must keep from the input's edge: the
/// bicubic kernel reaches two pixels out.
const SOURCE_MARGIN: f64 = 2.0;

/// A crop window: top-left corner and size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// The largest rectangle (sides multiples of `step`) whose every pixel samples inside the input
/// in all `warps` of a `width` x `height` image; `None` when nothing is left.
pub fn common_window(warps: &[YawWarp], width: u32, height: u32, step: u32) -> Option<Window> {
    // Each warp's valid region is a convex quadrilateral, and so is their intersection: per row
    // it is one interval [lo, hi] of valid columns (empty when lo > hi).
    let rows: Vec<(i64, i64)> = (0..height)
        .map(|y| {
            let inside = |x: u32| {
                warps.iter().all(|w| {
                    w.source_inside(f64::from(x), f64::from(y), width, height, SOURCE_MARGIN)
                })
            };
            let lo = (0..width).find(|&x| inside(x));
            let hi = (0..width).rev().find(|&x| inside(x));
            match (lo, hi) {
                (Some(lo), Some(hi)) => (i64::from(lo), i64::from(hi)),
                _ => (1, 0),
            }
        })
        .collect();
    let mut best: Option<(u64, Window)> = None;
    for y0 in 0..rows.len() {
        let (mut lo, mut hi) = (i64::MIN, i64::MAX);
        for (y1, &(l, h)) in rows.iter().enumerate().skip(y0) {
            lo = lo.max(l);
            hi = hi.min(h);
            if lo > hi {
                break;
            }
            let w = ((hi - lo + 1) as u32) / step * step;
            let h = ((y1 - y0 + 1) as u32) / step * step;
            let area = u64::from(w) * u64::from(h);
            if area > 0 && best.is_none_or(|(a, _)| area > a) {
                // Centre the rounded rectangle in the valid one.
                let x = lo as u32 + ((hi - lo + 1) as u32 - w) / 2;
                let y = y0 as u32 + ((y1 - y0 + 1) as u32 - h) / 2;
                best = Some((
                    area,
                    Window {
                        x,
                        y,
                        width: w,
                        height: h,
                    },
                ));
            }
        }
    }
    best.map(|(_, w)| w)
}

/// `camera` seen through a crop starting at `window`'s corner.
fn cropped_camera(camera: &CameraIntrinsics, window: Window) -> CameraIntrinsics {
    CameraIntrinsics {
        cx: camera.cx - f64::from(window.x),
        cy: camera.cy - f64::from(window.y),
        ..*camera
    }
}

/// Writes `frames` injected pairs of `source`, the cameras turned as `trajectory` says, into
/// `dir` (which must not exist or be empty), warped with `resampling` and cropped to the
/// [`common_window`] of the sequence,
/// with `calib.toml` (principal points moved with the crop), `truth.csv` and `encoders.csv`
/// (each frame's two yaws: what maps a point of an injected frame back to its source frame,
/// and what `run --encoders` takes). Everything is
/// written to a sibling [`StagingDir`] first and renamed into place, so neither a failure nor
/// Ctrl-C leaves anything half-written.
pub fn write_injected(
    dir: &Path,
    source: Source<'_>,
    calib: &Calibration,
    trajectory: Trajectory,
    frames: usize,
    resampling: Resampling,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<(), SynthError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| SynthError::Io { path, source }
    };
    if frames == 0 {
        return Err(SynthError::InvalidConfig {
            field: "frames",
            reason: "must be at least 1".into(),
        });
    }
    if !trajectory.phase_deg.is_finite() {
        return Err(SynthError::InvalidConfig {
            field: "phase",
            reason: format!("{} is not a finite angle", trajectory.phase_deg),
        });
    }
    if let Source::Sequence(seq) = source {
        if frames > seq.len() {
            return Err(SynthError::InvalidConfig {
                field: "frames",
                reason: format!("{frames} asked for, the sequence has {}", seq.len()),
            });
        }
    }
    let (width, height) = source.pair(0, None)?.0.dimensions();
    let yaws: Vec<(f64, f64)> = (0..frames).map(|i| trajectory.yaws(i, frames)).collect();
    // Frame i's left and right warps at 2i and 2i + 1: the crop window is taken over all of
    // them, and each frame is rendered through its own.
    let warps: Vec<YawWarp> = yaws
        .iter()
        .flat_map(|&(al, ar)| {
            [
                YawWarp::new(&calib.left, al),
                YawWarp::new(&calib.right, ar),
            ]
        })
        .collect();
    let window =
        common_window(&warps, width, height, CROP_STEP).ok_or(SynthError::InvalidConfig {
            field: "images",
            reason: format!("a {width}x{height} pair has no pixel valid under every injected yaw"),
        })?;
    let cropped = Calibration {
        left: cropped_camera(&calib.left, window),
        right: cropped_camera(&calib.right, window),
        ..*calib
    };
    if dir.exists() && fs::read_dir(dir).map_err(io(dir))?.next().is_some() {
        return Err(SynthError::OutputNotEmpty(dir.to_path_buf()));
    }
    let parent = dir
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    fs::create_dir_all(parent).map_err(io(parent))?;
    let staging = StagingDir::new_in(parent).map_err(io(parent))?;
    let (ldir, rdir) = (staging.path().join("left"), staging.path().join("right"));
    // `create_dir`, not `create_dir_all`: should Ctrl-C's handler have removed the staging
    // directory meanwhile, this fails instead of making it again for the exit to leave behind.
    for d in [&ldir, &rdir] {
        fs::create_dir(d).map_err(io(d))?;
    }
    (0..frames).into_par_iter().try_for_each(|i| {
        let name = format!("{i:06}.png");
        let (left, right) = source.pair(i, Some((width, height)))?;
        for (d, img, warp) in [
            (&ldir, &left, &warps[2 * i]),
            (&rdir, &right, &warps[2 * i + 1]),
        ] {
            let path = d.join(&name);
            let warped = warp.apply_with(img, resampling);
            image::imageops::crop_imm(&warped, window.x, window.y, window.width, window.height)
                .to_image()
                .save(&path)
                .map_err(|source| SynthError::Image { path, source })?;
        }
        progress(i);
        Ok::<(), SynthError>(())
    })?;
    let yaws_deg: Vec<(f64, f64)> = yaws
        .iter()
        .map(|&(al, ar)| (al.to_degrees(), ar.to_degrees()))
        .collect();
    let truth: Vec<f64> = yaws_deg.iter().map(|(l, r)| l - r).collect();
    let write_csv =
        |name: &str, write: &dyn Fn(std::io::BufWriter<fs::File>) -> std::io::Result<()>| {
            let path = staging.path().join(name);
            let file = fs::File::create(&path).map_err(io(&path))?;
            write(std::io::BufWriter::new(file)).map_err(io(&path))
        };
    write_csv("truth.csv", &|f| {
        write_truth_csv(f, &truth).map_err(std::io::Error::other)
    })?;
    write_csv("encoders.csv", &|f| {
        write_encoders_csv(f, &yaws_deg).map_err(std::io::Error::other)
    })?;
    let calib_path = staging.path().join("calib.toml");
    fs::write(&calib_path, cropped.to_toml_string()).map_err(io(&calib_path))?;
    staging.persist(dir).map_err(io(dir))
}

#[cfg(test)]
mod tests {
    use super::*;
    use stereocal::calib::{CameraIntrinsics, Extrinsics};

    #[test]
    fn writes_pairs_truth_and_calibration_atomically() {
        let tmp = tempfile::tempdir().unwrap();
        let img = GrayImage::from_fn(64, 48, |x, y| image::Luma([((x * 7 + y * 3) % 251) as u8]));
        let cam = CameraIntrinsics::pinhole(60.0, 60.0, 32.0, 24.0);
        let calib = Calibration {
            baseline_m: 0.3,
            left: cam,
            right: cam,
            extrinsics: Extrinsics::default(),
        };
        let dir = tmp.path().join("set");
        let pair = Source::Pair {
            left: &img,
            right: &img,
        };
        write_injected(
            &dir,
            pair,
            &calib,
            Motion::Moving.into(),
            4,
            Resampling::Bicubic,
            &|_| {},
        )
        .unwrap();
        assert_eq!(fs::read_dir(dir.join("left")).unwrap().count(), 4);
        assert_eq!(fs::read_dir(dir.join("right")).unwrap().count(), 4);
        let truth = stereocal::output::verge_csv::read_truth_csv(&dir.join("truth.csv")).unwrap();
        let (al, ar) = Trajectory::from(Motion::Moving).yaws(2, 4);
        assert!((truth[2] - (al - ar).to_degrees()).abs() < 1e-6);
        let encoders = fs::read_to_string(dir.join("encoders.csv")).unwrap();
        let row: Vec<f64> = encoders
            .lines()
            .nth(3)
            .unwrap()
            .split(',')
            .skip(1)
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(
            encoders.lines().next(),
            Some("frame,left_yaw_deg,right_yaw_deg")
        );
        assert!((row[0] - al.to_degrees()).abs() < 1e-8 && (row[1] - ar.to_degrees()).abs() < 1e-8);
        let verges = stereocal::encoders::read_encoders_csv(&dir.join("encoders.csv"), 4).unwrap();
        assert!((verges[2].unwrap() - truth[2]).abs() < 1e-8);
        let written = Calibration::load(dir.join("calib.toml")).unwrap();
        let first = image::open(dir.join("left/000000.png")).unwrap();
        assert_eq!((first.width() % 8, first.height() % 8), (0, 0));
        assert!(first.width() < 64 && written.left.cx < cam.cx);
        assert_eq!(written.left.fx, cam.fx);
        // Only the finished directory is left beside it.
        assert_eq!(fs::read_dir(tmp.path()).unwrap().count(), 1);
        // A second run into the now non-empty directory is refused.
        let again = write_injected(
            &dir,
            pair,
            &calib,
            Motion::Fixed.into(),
            2,
            Resampling::Bicubic,
            &|_| {},
        );
        assert!(matches!(again, Err(SynthError::OutputNotEmpty(_))));
        // A phase that is not an angle is refused before anything is written.
        let nowhere = tmp.path().join("nowhere");
        let phase = write_injected(
            &nowhere,
            pair,
            &calib,
            Trajectory {
                motion: Motion::Swing,
                phase_deg: f64::NAN,
            },
            2,
            Resampling::Bicubic,
            &|_| {},
        );
        assert!(matches!(
            phase,
            Err(SynthError::InvalidConfig { field: "phase", .. })
        ));
        assert!(!nowhere.exists());
    }

    #[test]
    fn a_phase_starts_the_motion_later_in_its_period() {
        // A quarter period later: frame 0 at 90° has the yaws of frame 2 of 8 at 0°.
        for motion in [Motion::Moving, Motion::Fixed, Motion::Swing] {
            let later = Trajectory {
                motion,
                phase_deg: 90.0,
            };
            let (a, b) = (later.yaws(0, 8), Trajectory::from(motion).yaws(2, 8));
            assert!(
                (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12,
                "{motion:?}"
            );
        }
    }

    #[test]
    fn injects_into_every_frame_of_a_sequence() {
        use stereocal::image_sequence::{SizeLimits, StereoSequence};
        let tmp = tempfile::tempdir().unwrap();
        let (src_l, src_r) = (tmp.path().join("l"), tmp.path().join("r"));
        // Three different pairs, as a drive's content changes every frame.
        let frame = |k: u32, side: u32| {
            GrayImage::from_fn(64, 48, move |x, y| {
                image::Luma([((x * 7 + y * (3 + side) + k * 50) % 251) as u8])
            })
        };
        for (dir, side) in [(&src_l, 0), (&src_r, 1)] {
            fs::create_dir(dir).unwrap();
            for k in 0..3 {
                frame(k, side)
                    .save(dir.join(format!("{k:04}.png")))
                    .unwrap();
            }
        }
        let limits = SizeLimits {
            max_width: 4096,
            min_side: 16,
        };
        let seq = StereoSequence::open(&src_l, &src_r, limits).unwrap();
        let cam = CameraIntrinsics::pinhole(60.0, 60.0, 32.0, 24.0);
        let calib = Calibration {
            baseline_m: 0.3,
            left: cam,
            right: cam,
            extrinsics: Extrinsics::default(),
        };
        let dir = tmp.path().join("set");
        let source = Source::Sequence(&seq);
        write_injected(
            &dir,
            source,
            &calib,
            Motion::Swing.into(),
            3,
            Resampling::Bicubic,
            &|_| {},
        )
        .unwrap();
        let truth = stereocal::output::verge_csv::read_truth_csv(&dir.join("truth.csv")).unwrap();
        assert_eq!(truth.len(), 3);
        for (i, t) in truth.iter().enumerate() {
            let (al, ar) = Trajectory::from(Motion::Swing).yaws(i, 3);
            assert!((t - (al - ar).to_degrees()).abs() < 1e-6);
        }
        // One period of ±10°: frames 1 and 2 sit at ±10·sin(120°).
        assert!((truth[1] - 10.0 * 120f64.to_radians().sin()).abs() < 1e-6);
        assert!((truth[2] + truth[1]).abs() < 1e-6);
        let written = Calibration::load(dir.join("calib.toml")).unwrap();
        let (x0, y0) = (
            (cam.cx - written.left.cx) as u32,
            (cam.cy - written.left.cy) as u32,
        );
        // Output frame i is source pair i warped by frame i's yaw, cropped.
        for i in 0..3u32 {
            let (al, ar) = Trajectory::from(Motion::Swing).yaws(i as usize, 3);
            for (side, name, alpha) in [(0, "left", al), (1, "right", ar)] {
                let got = image::open(dir.join(format!("{name}/{i:06}.png")))
                    .unwrap()
                    .to_luma8();
                let want = YawWarp::new(&cam, alpha).apply(&frame(i, side));
                let want =
                    image::imageops::crop_imm(&want, x0, y0, got.width(), got.height()).to_image();
                assert_eq!(got, want, "{name} frame {i}");
            }
        }
        // More frames than the sequence holds are refused before anything is written.
        let more = write_injected(
            &tmp.path().join("more"),
            source,
            &calib,
            Motion::Fixed.into(),
            4,
            Resampling::Bicubic,
            &|_| {},
        );
        assert!(matches!(
            more,
            Err(SynthError::InvalidConfig {
                field: "frames",
                ..
            })
        ));
        assert!(!tmp.path().join("more").exists());
    }

    #[test]
    fn common_window_is_valid_in_every_warp() {
        let cam = CameraIntrinsics::pinhole(300.0, 300.0, 160.0, 120.0);
        let warps = [YawWarp::new(&cam, 0.05), YawWarp::new(&cam, -0.03)];
        let w = common_window(&warps, 320, 240, 8).unwrap();
        assert_eq!((w.width % 8, w.height % 8), (0, 0));
        // Turning by ±3° at f = 300 px shifts by about 15 px: most of the frame remains.
        assert!(w.width >= 256 && w.height >= 200, "{w:?}");
        for (x, y) in [
            (w.x, w.y),
            (w.x + w.width - 1, w.y),
            (w.x, w.y + w.height - 1),
            (w.x + w.width - 1, w.y + w.height - 1),
        ] {
            for warp in &warps {
                assert!(warp.source_inside(f64::from(x), f64::from(y), 320, 240, SOURCE_MARGIN));
            }
        }
    }

    #[test]
    fn fixed_motion_keeps_the_verge() {
        for i in 0..10 {
            let (al, ar) = Trajectory::from(Motion::Fixed).yaws(i, 10);
            assert!(((al - ar).to_degrees() - 1.5).abs() < 1e-12);
        }
    }
}
