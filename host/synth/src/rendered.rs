//! Stereo sequences: a scene, a head trajectory and camera settings, rendered lazily frame by
//! frame, with the ground truth of every frame, and written to disk in the formats of
//! `docs/ARCHITECTURE.md`, "Files" (image directories, `calib.toml`, `truth.csv`).

use std::fmt::Write as _;
use std::fs;
use std::path::Path;

use image::GrayImage;
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::camera::{CameraPose, Intrinsics, Side};
use crate::render::{render, MotionBlur, RenderSpec, RowMap, Supersampling};
use crate::scene::{Scene, SceneKind};
use crate::trajectory::{HeadGeometry, HeadState, Trajectory, TrajectoryKind, FIXED_VERGE_DEG};
use crate::SynthError;
use stereocal::output::output_dir::StagingDir;

/// Distance between the optical centres (thesis head: 0.3 m), right camera at +x.
pub const BASELINE_M: f64 = 0.3;

/// Everything about a sequence except the scene.
#[derive(Debug, Clone, PartialEq)]
pub struct SequenceConfig {
    /// Frame size in pixels (an interlaced field is `width` x `height / 2`).
    pub width: u32,
    pub height: u32,
    pub frames: usize,
    /// Images per second (fields per second when interlaced).
    pub fps: f64,
    pub trajectory: TrajectoryKind,
    /// Seeds the scene layout (for built-in scenes), the trajectory, the sensor noise and the
    /// dropped frames.
    pub seed: u64,
    /// Sensor noise, standard deviation in grey levels.
    pub noise_sigma: f32,
    pub supersampling: Supersampling,
    /// Replaces `supersampling` by a uniform grid whose samples spread over the exposure.
    pub motion_blur: Option<MotionBlur>,
    /// Deliver 60 Hz-style interlaced fields (`height / 2` rows; even frames are the even
    /// field, odd frames the odd field), thesis 4.1.2.
    pub interlaced: bool,
    /// Probability that a frame is dropped (the grabber lost it: no images, truth kept).
    pub drop_rate: f64,
    /// Left optical centre at time 0 (world metres; the ground is y = 0, y points down).
    pub head_start: [f64; 3],
    /// Vehicle speed along +z.
    pub speed_mps: f64,
    /// Head pitch, positive looking down (degrees).
    pub tilt_deg: f64,
    /// Focal length of the left camera in pixels (the right one's is 3.5 px longer, scaled
    /// alike); `None`: a 56° horizontal field of view, 600 px at 640 px width.
    pub focal_px: Option<f64>,
    /// Distance between the optical centres, right camera at +x.
    pub baseline_m: f64,
    /// The verge the `fixed` trajectory holds, split evenly between the cameras (degrees).
    pub fixed_verge_deg: f64,
    /// The right camera's fixed pitch relative to the left one, `R_01 = Ry(-verge) Rx(pitch)`
    /// as the calibration's `[extrinsics]` define it (degrees). It is not written into
    /// `calib.toml`: it is the misalignment a head has and its calibration does not know.
    pub right_pitch_deg: f64,
}

impl SequenceConfig {
    /// The defaults for a built-in scene: the road is driven at 10 m/s, 30 fps, head 1.3 m
    /// above the road and tilted 2° down, verge fixed (fig. 5.2); the lab and sparse scenes
    /// stand still at 15 fps (the thesis' lab rate) with manual moves (fig. 5.1).
    pub fn for_scene(kind: SceneKind) -> Self {
        let base = SequenceConfig {
            width: 640,
            height: 480,
            frames: 300,
            fps: 30.0,
            trajectory: TrajectoryKind::Fixed,
            seed: 0,
            noise_sigma: 1.5,
            supersampling: Supersampling::default(),
            motion_blur: None,
            interlaced: false,
            drop_rate: 0.0,
            head_start: [0.0, -1.3, 0.0],
            speed_mps: 10.0,
            tilt_deg: 2.0,
            focal_px: None,
            baseline_m: BASELINE_M,
            fixed_verge_deg: FIXED_VERGE_DEG,
            right_pitch_deg: 0.0,
        };
        match kind {
            SceneKind::Road => base,
            SceneKind::Lab | SceneKind::Sparse => SequenceConfig {
                fps: 15.0,
                trajectory: TrajectoryKind::Manual,
                speed_mps: 0.0,
                tilt_deg: if kind == SceneKind::Lab { 6.0 } else { 0.0 },
                ..base
            },
        }
    }

    fn validate(&self) -> Result<(), SynthError> {
        let bad =
            |field: &'static str, reason: String| Err(SynthError::InvalidConfig { field, reason });
        if !(16..=8192).contains(&self.width) {
            return bad("width", format!("is {}, must be 16..=8192", self.width));
        }
        if !(16..=8192).contains(&self.height) {
            return bad("height", format!("is {}, must be 16..=8192", self.height));
        }
        if self.interlaced && self.height % 2 != 0 {
            return bad(
                "height",
                format!("is {}, must be even for interlaced fields", self.height),
            );
        }
        if self.frames == 0 {
            return bad("frames", "must be at least 1".into());
        }
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return bad("fps", format!("is {}, must be finite and > 0", self.fps));
        }
        if !(self.noise_sigma.is_finite() && self.noise_sigma >= 0.0) {
            return bad(
                "noise_sigma",
                format!("is {}, must be finite and >= 0", self.noise_sigma),
            );
        }
        let n = match self.supersampling {
            Supersampling::Adaptive { edge } => edge,
            Supersampling::Uniform { per_axis } => per_axis,
        };
        if !(1..=8).contains(&n) {
            return bad(
                "supersampling",
                format!("{n} samples per axis, must be 1..=8"),
            );
        }
        if let Some(blur) = &self.motion_blur {
            if !(1..=8).contains(&blur.per_axis) {
                return bad(
                    "motion_blur.per_axis",
                    format!("is {}, must be 1..=8", blur.per_axis),
                );
            }
            if !(blur.exposure_s.is_finite()
                && blur.exposure_s >= 0.0
                && blur.exposure_s <= 1.0 / self.fps)
            {
                return bad(
                    "motion_blur.exposure_s",
                    format!("is {}, must be within 0..=1/fps", blur.exposure_s),
                );
            }
        }
        if !(0.0..1.0).contains(&self.drop_rate) {
            return bad(
                "drop_rate",
                format!("is {}, must be in [0, 1)", self.drop_rate),
            );
        }
        if !self.head_start.iter().all(|v| v.is_finite()) {
            return bad("head_start", "must be finite".into());
        }
        if !self.speed_mps.is_finite() {
            return bad("speed_mps", "must be finite".into());
        }
        if let Some(f) = self.focal_px {
            if !(f.is_finite() && f > 0.0) {
                return bad("focal_px", format!("is {f}, must be finite and > 0"));
            }
        }
        if !(self.baseline_m.is_finite() && self.baseline_m > 0.0) {
            return bad(
                "baseline_m",
                format!("is {}, must be finite and > 0", self.baseline_m),
            );
        }
        if !(self.fixed_verge_deg.is_finite() && self.fixed_verge_deg.abs() < 60.0) {
            return bad(
                "fixed_verge_deg",
                format!("is {}, must be within ±60°", self.fixed_verge_deg),
            );
        }
        if !(self.right_pitch_deg.is_finite() && self.right_pitch_deg.abs() < 30.0) {
            return bad(
                "right_pitch_deg",
                format!("is {}, must be within ±30°", self.right_pitch_deg),
            );
        }
        if !(self.tilt_deg.is_finite() && self.tilt_deg.abs() < 80.0) {
            return bad(
                "tilt_deg",
                format!("is {}, must be within ±80°", self.tilt_deg),
            );
        }
        Ok(())
    }
}

impl Default for SequenceConfig {
    fn default() -> Self {
        Self::for_scene(SceneKind::Road)
    }
}

/// The ground truth of one frame (degrees; verge = alpha_l - alpha_r, toe-in positive).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Truth {
    pub alpha_l_deg: f64,
    pub alpha_r_deg: f64,
    pub verge_deg: f64,
    /// Head pitch (positive down) including the vehicle's bounce.
    pub tilt_deg: f64,
}

impl From<&HeadState> for Truth {
    fn from(s: &HeadState) -> Self {
        Truth {
            alpha_l_deg: s.alpha_l_rad.to_degrees(),
            alpha_r_deg: s.alpha_r_rad.to_degrees(),
            verge_deg: s.verge_deg(),
            tilt_deg: s.tilt_rad.to_degrees(),
        }
    }
}

/// The two images of a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct StereoImages {
    pub left: GrayImage,
    pub right: GrayImage,
}

/// One frame of a sequence.
#[derive(Debug, Clone, PartialEq)]
pub struct StereoFrame {
    pub index: usize,
    /// Capture time (mid-exposure), microseconds from the first frame.
    pub timestamp_us: u64,
    pub truth: Truth,
    /// `Some(0)` / `Some(1)` for the even / odd field of an interlaced sequence.
    pub field_parity: Option<u32>,
    /// `None` when the frame was dropped.
    pub images: Option<StereoImages>,
}

impl StereoFrame {
    pub fn dropped(&self) -> bool {
        self.images.is_none()
    }
}

/// A rendered-on-demand stereo sequence.
#[derive(Debug, Clone)]
pub struct Sequence {
    scene: Scene,
    config: SequenceConfig,
    trajectory: Trajectory,
    intrinsics: [Intrinsics; 2],
}

impl Sequence {
    /// A sequence through `scene`; fails on an invalid config or a head that would leave the
    /// part of the scene that is furnished.
    pub fn new(scene: Scene, config: SequenceConfig) -> Result<Self, SynthError> {
        config.validate()?;
        let duration_s = (config.frames - 1) as f64 / config.fps;
        let trajectory = Trajectory::new(
            config.trajectory,
            config.seed,
            duration_s,
            Vector3::from(config.head_start),
            config.speed_mps,
            config.tilt_deg,
            config.fixed_verge_deg,
        );
        let [z_lo, z_hi] = scene.extent_z();
        let (z0, z1) = (trajectory.z_at(0.0), trajectory.z_at(duration_s));
        if z0.min(z1) < z_lo || z0.max(z1) > z_hi {
            return Err(SynthError::OutsideScene {
                from_m: z0.min(z1),
                to_m: z0.max(z1),
                scene_from_m: z_lo,
                scene_to_m: z_hi,
            });
        }
        let intrinsics = [
            Intrinsics::for_sensor(config.width, config.height, config.focal_px, Side::Left),
            Intrinsics::for_sensor(config.width, config.height, config.focal_px, Side::Right),
        ];
        Ok(Sequence {
            scene,
            config,
            trajectory,
            intrinsics,
        })
    }

    /// A sequence through the built-in scene `kind`, laid out from `config.seed`.
    pub fn builtin(kind: SceneKind, config: SequenceConfig) -> Result<Self, SynthError> {
        Self::new(Scene::new(kind, config.seed), config)
    }

    pub fn len(&self) -> usize {
        self.config.frames
    }

    pub fn is_empty(&self) -> bool {
        self.config.frames == 0
    }

    pub fn config(&self) -> &SequenceConfig {
        &self.config
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    pub fn baseline_m(&self) -> f64 {
        self.config.baseline_m
    }

    /// Size of the delivered images (a field is half the frame height).
    pub fn image_size(&self) -> (u32, u32) {
        let c = &self.config;
        (c.width, if c.interlaced { c.height / 2 } else { c.height })
    }

    /// The intrinsics of the delivered images `[left, right]`, the ones `calib.toml` holds.
    /// For interlaced sequences these are the even field's; see [`Sequence::frame_intrinsics`].
    pub fn intrinsics(&self) -> [Intrinsics; 2] {
        self.intrinsics_for_parity(self.config.interlaced.then_some(0))
    }

    /// The exact intrinsics of frame `index`'s images: an odd field's principal point is
    /// half a field row above the even field's.
    pub fn frame_intrinsics(&self, index: usize) -> [Intrinsics; 2] {
        self.intrinsics_for_parity(self.parity(index))
    }

    fn intrinsics_for_parity(&self, parity: Option<u32>) -> [Intrinsics; 2] {
        match parity {
            Some(p) => self.intrinsics.map(|k| k.field(p)),
            None => self.intrinsics,
        }
    }

    /// The head's fixed geometry: baseline and the right camera's pitch.
    fn head(&self) -> HeadGeometry {
        HeadGeometry {
            baseline_m: self.config.baseline_m,
            right_pitch_rad: self.config.right_pitch_deg.to_radians(),
        }
    }

    fn parity(&self, index: usize) -> Option<u32> {
        self.config.interlaced.then_some((index % 2) as u32)
    }

    fn time_s(&self, index: usize) -> f64 {
        index as f64 / self.config.fps
    }

    pub fn timestamp_us(&self, index: usize) -> u64 {
        (self.time_s(index) * 1e6).round() as u64
    }

    fn check(&self, index: usize) -> Result<(), SynthError> {
        if index < self.len() {
            Ok(())
        } else {
            Err(SynthError::FrameOutOfRange {
                index,
                len: self.len(),
            })
        }
    }

    /// The truth of frame `index` without rendering it.
    pub fn truth(&self, index: usize) -> Result<Truth, SynthError> {
        self.check(index)?;
        Ok(Truth::from(&self.trajectory.state(self.time_s(index))))
    }

    /// Whether frame `index` is dropped (decided by the seed, independent of the others).
    pub fn is_dropped(&self, index: usize) -> bool {
        if self.config.drop_rate == 0.0 {
            return false;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(mix(self.config.seed, 0x64726f70, index as u64));
        rng.random::<f64>() < self.config.drop_rate
    }

    /// The cameras at frame `index` (mid-exposure), with the intrinsics of its images:
    /// [`CameraPose::project`] of a scene point is where it appears in the rendered image.
    pub fn camera_poses(&self, index: usize) -> Result<[CameraPose; 2], SynthError> {
        self.check(index)?;
        let [l, r] = self.frame_intrinsics(index);
        Ok(self
            .trajectory
            .state(self.time_s(index))
            .camera_poses(self.head(), l, r))
    }

    /// Render frame `index` (both cameras, each parallel over rows).
    pub fn frame(&self, index: usize) -> Result<StereoFrame, SynthError> {
        let truth = self.truth(index)?;
        let images = (!self.is_dropped(index)).then(|| self.render_pair(index));
        Ok(StereoFrame {
            index,
            timestamp_us: self.timestamp_us(index),
            truth,
            field_parity: self.parity(index),
            images,
        })
    }

    /// All frames in order, each rendered when the iterator reaches it.
    pub fn iter(&self) -> Frames<'_> {
        Frames {
            sequence: self,
            next: 0,
        }
    }

    fn render_pair(&self, index: usize) -> StereoImages {
        let c = &self.config;
        let t = self.time_s(index);
        // Full-frame cameras at each instant of the exposure; the field's rows are picked by
        // the row map, so the geometry is the frame's exactly.
        let (instants, supersampling) = match c.motion_blur {
            Some(blur) => {
                let m = usize::from(blur.per_axis) * usize::from(blur.per_axis);
                let times: Vec<f64> = (0..m)
                    .map(|j| t + blur.exposure_s * ((j as f64 + 0.5) / m as f64 - 0.5))
                    .collect();
                (
                    times,
                    Supersampling::Uniform {
                        per_axis: blur.per_axis,
                    },
                )
            }
            None => (vec![t], c.supersampling),
        };
        let poses: Vec<[CameraPose; 2]> = instants
            .iter()
            .map(|&ti| {
                let [l, r] = self.intrinsics;
                self.trajectory.state(ti).camera_poses(self.head(), l, r)
            })
            .collect();
        let rows = match self.parity(index) {
            Some(p) => RowMap { step: 2, offset: p },
            None => RowMap { step: 1, offset: 0 },
        };
        let (w, h) = self.image_size();
        let image = |side: usize| {
            let spec = RenderSpec {
                width: c.width,
                height: c.height,
                rows,
                supersampling,
                noise_sigma: c.noise_sigma,
                noise_seed: mix(c.seed, index as u64, side as u64),
            };
            let side_poses: Vec<CameraPose> = poses.iter().map(|p| p[side]).collect();
            let pixels = render(&self.scene, &side_poses, &spec);
            // `render` returns exactly w * h pixels.
            GrayImage::from_raw(w, h, pixels).expect("render produces width x rows pixels")
        };
        StereoImages {
            left: image(0),
            right: image(1),
        }
    }

    /// The calibration file (`docs/ARCHITECTURE.md`, "Calibration (TOML)") of the delivered
    /// images.
    pub fn calib_toml(&self) -> String {
        let [l, r] = self.intrinsics();
        let c = &self.config;
        let mut s = String::new();
        // Writing to a String cannot fail.
        let _ = writeln!(
            s,
            "# stereocal synthetic head: {} x {}{}, seed {}",
            self.image_size().0,
            self.image_size().1,
            if c.interlaced {
                " (even field; odd fields have cy - 0.5)"
            } else {
                ""
            },
            c.seed
        );
        let _ = writeln!(s, "baseline_m = {:?}", c.baseline_m);
        for (name, k) in [("left", l), ("right", r)] {
            let _ = writeln!(s, "\n[{name}]");
            let _ = writeln!(
                s,
                "fx = {:?}\nfy = {:?}\ncx = {:?}\ncy = {:?}",
                k.fx, k.fy, k.cx, k.cy
            );
        }
        s
    }

    /// `frame,verge_deg` for every frame (dropped ones included: the truth does not drop).
    pub fn truth_csv(&self) -> String {
        let mut s = String::from("frame,verge_deg\n");
        for i in 0..self.len() {
            let t = Truth::from(&self.trajectory.state(self.time_s(i)));
            let _ = writeln!(s, "{i},{:.9}", t.verge_deg);
        }
        s
    }

    /// `frame,left_yaw_deg,right_yaw_deg` for every frame: what the head's joint encoders read,
    /// exactly (the thesis' head had encoders on every axis), for `run --encoders`.
    pub fn encoders_csv(&self) -> String {
        let mut s = String::from("frame,left_yaw_deg,right_yaw_deg\n");
        for i in 0..self.len() {
            let t = Truth::from(&self.trajectory.state(self.time_s(i)));
            let _ = writeln!(s, "{i},{:.9},{:.9}", t.alpha_l_deg, t.alpha_r_deg);
        }
        s
    }

    /// Per-frame details: time, both yaws, tilt, dropped, field parity.
    pub fn frames_csv(&self) -> String {
        let mut s = String::from(
            "frame,timestamp_us,alpha_l_deg,alpha_r_deg,verge_deg,tilt_deg,dropped,field\n",
        );
        for i in 0..self.len() {
            let t = Truth::from(&self.trajectory.state(self.time_s(i)));
            let field = self.parity(i).map_or(String::new(), |p| p.to_string());
            let _ = writeln!(
                s,
                "{i},{},{:.9},{:.9},{:.9},{:.9},{},{field}",
                self.timestamp_us(i),
                t.alpha_l_deg,
                t.alpha_r_deg,
                t.verge_deg,
                t.tilt_deg,
                u8::from(self.is_dropped(i)),
            );
        }
        s
    }

    /// Write `left/NNNNNN.png`, `right/NNNNNN.png` (8-bit grey; no files for dropped frames,
    /// so the numbering shows the gap), `calib.toml`, `truth.csv`, `frames.csv` and
    /// `encoders.csv` into `dir`.
    /// `dir` must not exist or be empty; everything is written to a sibling staging directory
    /// that is renamed into place at the end, so a failure or Ctrl-C leaves nothing
    /// half-written.
    pub fn write_sequence(&self, dir: &Path) -> Result<(), SynthError> {
        self.write_sequence_with(dir, &|_| {})
    }

    /// [`Sequence::write_sequence`], calling `progress(frame)` as each frame is written
    /// (from worker threads, in no particular order).
    pub fn write_sequence_with(
        &self,
        dir: &Path,
        progress: &(dyn Fn(usize) + Sync),
    ) -> Result<(), SynthError> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| SynthError::Io { path, source }
        };
        if dir.exists() {
            let mut entries = fs::read_dir(dir).map_err(io(dir))?;
            if entries.next().is_some() {
                return Err(SynthError::OutputNotEmpty(dir.to_path_buf()));
            }
        }
        let parent = dir
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        fs::create_dir_all(parent).map_err(io(parent))?;
        // Removed when dropped: on an error here, and by Ctrl-C's handler.
        let staging = StagingDir::new_in(parent).map_err(io(parent))?;
        self.write_into(staging.path(), progress)?;
        staging.persist(dir).map_err(io(dir))
    }

    fn write_into(&self, dir: &Path, progress: &(dyn Fn(usize) + Sync)) -> Result<(), SynthError> {
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| SynthError::Io { path, source }
        };
        let (left, right) = (dir.join("left"), dir.join("right"));
        // `create_dir`, not `create_dir_all`: should Ctrl-C's handler have removed the
        // staging directory meanwhile, this fails instead of making it again for the exit to
        // leave behind.
        for d in [&left, &right] {
            fs::create_dir(d).map_err(io(d))?;
        }
        (0..self.len()).into_par_iter().try_for_each(|i| {
            let frame = self.frame(i)?;
            if let Some(images) = &frame.images {
                let name = format!("{i:06}.png");
                for (d, img) in [(&left, &images.left), (&right, &images.right)] {
                    let path = d.join(&name);
                    img.save(&path)
                        .map_err(|source| SynthError::Image { path, source })?;
                }
            }
            progress(i);
            Ok::<(), SynthError>(())
        })?;
        for (name, text) in [
            ("calib.toml", self.calib_toml()),
            ("truth.csv", self.truth_csv()),
            ("frames.csv", self.frames_csv()),
            ("encoders.csv", self.encoders_csv()),
        ] {
            let path = dir.join(name);
            fs::write(&path, text).map_err(io(&path))?;
        }
        Ok(())
    }
}

/// The hidden sibling `dir` is assembled in.
/// Lazily rendering iterator over a [`Sequence`].
#[derive(Debug, Clone)]
pub struct Frames<'a> {
    sequence: &'a Sequence,
    next: usize,
}

impl Iterator for Frames<'_> {
    type Item = StereoFrame;

    fn next(&mut self) -> Option<StereoFrame> {
        let frame = self.sequence.frame(self.next).ok()?;
        self.next += 1;
        Some(frame)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let left = self.sequence.len().saturating_sub(self.next);
        (left, Some(left))
    }
}

impl ExactSizeIterator for Frames<'_> {}

impl<'a> IntoIterator for &'a Sequence {
    type Item = StereoFrame;
    type IntoIter = Frames<'a>;
    fn into_iter(self) -> Frames<'a> {
        self.iter()
    }
}

/// SplitMix64-style mixing of a seed with two indices into an independent stream seed.
fn mix(seed: u64, a: u64, b: u64) -> u64 {
    let mut z =
        seed ^ a.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ b.wrapping_mul(0xd1b5_4a32_d192_ed03);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}
