//! The head's fixed misalignments learned online: a sliding-window joint fit over the last
//! frames' matches, with the right camera's pitch and roll (and optionally the baseline's
//! tilt) shared by every frame and two yaws per frame.
//!
//! One frame cannot tell a small pitch or roll from a change of verge: the thesis' model bends
//! the verge to explain them, by an amount that depends on where the matches lie, so the
//! error moves from view to view. Frames with different views constrain the shared angles
//! jointly, and the current frame's yaws are then refitted twice on its matches
//! ([`misaligned::refine_yaws`]): with the learned angles held and with the calibration's.
//! The difference of the two is what the learned misalignments move the frame's yaws by,
//! and it corrects the per-frame estimate ([`MisalignmentWindow::update`]): the refit alone
//! would also carry the difference between its robust fit of the consistent matches and the
//! estimator's of all of them (a few thousandths of a degree on rendered truth, where nothing
//! is misaligned), and with the calibration's angles learned the correction is exactly zero.
//! Each Gauss-Newton step eliminates the per-frame yaws by the Schur complement, so a step
//! costs one pass over the window's matches and a 3x3 solve. A
//! frame that leaves the window leaves its information about the shared angles behind, as a
//! Gaussian prior (marginalisation), so the window bounds the cost, not the memory.

use std::collections::VecDeque;

use nalgebra::{Matrix2, Matrix2x3, Matrix3, SMatrix, SVector, Vector2, Vector3};
use rayon::prelude::*;

use crate::calib::Extrinsics;
use crate::essential::constrained::VergeAngles;
use crate::essential::misaligned::{self, Misalignment, PitchPrior};
use crate::essential::{Correspondence, EssentialError, RefineConfig};

/// Which misalignments the window estimates (`--misalignment`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WindowConfig {
    /// Frames in the window.
    pub frames: usize,
    /// Whether the right camera's pitch is estimated (else held at the calibration's). A
    /// constant pitch moves every row alike, which on a forward-looking road view the yaws'
    /// depth-dependent terms nearly reproduce, so a learned pitch and the verge trade for
    /// each other as the view changes; a roll moves rows in proportion to the column, which
    /// the verge (row times column) does not (README, "The head's fixed misalignments").
    pub pitch: bool,
    /// Whether the baseline's tilt is estimated too (else held at the calibration's).
    pub tilt: bool,
    /// Whether each frame also gets its own pitch, refined with its yaws and held to the
    /// window's mean pitch by a normal prior whose variance is the frames' spread beyond their
    /// own noise, learned over the window. A head on a vehicle pitches its cameras against
    /// each other by a few thousandths of a degree from frame to frame (on the KITTI drive
    /// the frames spread by 0.005° beyond their fits' noise). A verge that ignores it absorbs
    /// it, as much as the view lets the two trade; where the frames do not spread beyond their
    /// noise the prior holds each pitch at the mean and the verge is the roll window's
    /// (README, "The head's fixed misalignments").
    pub frame_pitch: bool,
    /// Joint Gauss-Newton steps per new frame.
    pub steps: usize,
    /// Frames the prior of the marginalised frames remembers: each frame that leaves the
    /// window first discounts the prior by `1 - 1/memory`.
    pub memory: usize,
}

impl Default for WindowConfig {
    /// 30 frames: the shared angles' noise falls as 1/√N, to a fifth of one frame's at 30,
    /// while 30 frames of about 500 matches keep a step near a millisecond on two cores, and
    /// a misalignment that drifts (temperature, a knock) is forgotten within 30 frames. Two
    /// steps per frame: every frame stays in the window for 30 frames, so its yaws and the
    /// shared angles converge over 60 steps; two keep up with a drifting misalignment. A
    /// memory of 300 frames (half a minute at 10 Hz) lets the shared angles' noise fall to
    /// about 1/√300 of one frame's, while a misalignment that drifts with temperature, over
    /// minutes, is still followed.
    fn default() -> Self {
        Self {
            frames: 30,
            pitch: true,
            tilt: false,
            frame_pitch: false,
            steps: 2,
            memory: 300,
        }
    }
}

impl WindowConfig {
    /// The roll alone, the pitch held at the calibration's: the session's default
    /// (`--misalignment window-roll`). A roll and the verge do not trade on any view, so the
    /// window learns it without bending the verge. On the KITTI drive it halves the untouched
    /// run's scatter and more than halves the fixed head's span; on 200 frames of rendered
    /// truth without a roll it moves the raw errors by less than a thousandth of a degree
    /// (README, "The head's fixed misalignments").
    pub fn roll() -> Self {
        Self {
            pitch: false,
            ..Self::default()
        }
    }

    /// The roll learned as in [`Self::roll`], and each frame's own pitch about the frames'
    /// mean (`--misalignment window-frame-pitch`; see [`Self::frame_pitch`]).
    pub fn roll_and_frame_pitch() -> Self {
        Self {
            frame_pitch: true,
            ..Self::roll()
        }
    }
}

/// Frames whose own pitches the spread is taken over before it holds any frame's pitch: the
/// sample variance of `n` values has a relative standard error of `√(2 / (n - 1))`, 71 % at
/// five frames and more below, and a spread that uncertain would free or pin a frame's pitch
/// by chance.
const MIN_SPREAD_FRAMES: usize = 5;

/// The window's current estimate of the misalignments, degrees, with 1-σ from the joint
/// fit's covariance (0 for an angle held at the calibration's).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct MisalignmentEstimate {
    /// The right camera's pitch, the `Rx` angle of `R_01` (docs/ARCHITECTURE.md, "Frames and
    /// signs").
    pub pitch_deg: f64,
    /// The right camera's roll, the `Rz` angle of `R_01`.
    pub roll_deg: f64,
    /// The baseline's elevation, positive when the right camera sits lower (+y); the
    /// calibration's unless the window fits it (`window-tilt`).
    pub baseline_tilt_deg: f64,
    /// 1-σ of `pitch_deg`.
    pub pitch_sigma_deg: f64,
    /// 1-σ of `roll_deg`.
    pub roll_sigma_deg: f64,
    /// 1-σ of `baseline_tilt_deg`; 0 when it is held.
    pub baseline_tilt_sigma_deg: f64,
    /// With each frame's own pitch: how far the frames' pitches spread about `pitch_deg`
    /// beyond their own noise (1-σ, degrees); 0 otherwise, or while it is not yet learned.
    pub pitch_spread_deg: f64,
    /// Frames in the window that gave it.
    pub frames: usize,
}

/// A frame's own pitch, refined freely with its yaws: its offset from the shared pitch and
/// that offset's variance from the frame's fit (radians, radians²).
#[derive(Debug, Clone, Copy)]
struct FramePitch {
    offset: f64,
    variance: f64,
}

/// One frame in the window: its consistent matches and its current yaws.
#[derive(Debug, Clone)]
struct WindowFrame {
    matches: Vec<Correspondence>,
    angles: VergeAngles,
}

/// The window's frames' own pitches (radians): their mean offset from the shared pitch, their
/// sample variance, and that less the frames' mean noise variance (the spread of the pitches
/// themselves; negative when the noise explains it all).
struct PitchSpread {
    mean: f64,
    sample_variance: f64,
    variance: f64,
}

/// One frame's Gauss-Newton normal equations, split into its yaws (`a`) and the shared block
/// (`s`), in units of its own noise (divided by its robust σ²) so that frames of different
/// quality weigh by their information.
struct FrameNormal {
    aa: Matrix2<f64>,
    as_: Matrix2x3<f64>,
    ss: Matrix3<f64>,
    ba: Vector2<f64>,
    bs: Vector3<f64>,
}

impl FrameNormal {
    /// The frame's information and gradient on the shared block with its yaws eliminated
    /// (Schur complement), and the inverse of its yaw block; `None` when its yaws are not
    /// determined.
    fn reduced(&self) -> Option<(Matrix3<f64>, Vector3<f64>, Matrix2<f64>)> {
        let aa_inv = self.aa.try_inverse()?;
        let cross = self.as_.transpose() * aa_inv;
        Some((
            self.ss - cross * self.as_,
            self.bs - cross * self.ba,
            aa_inv,
        ))
    }
}

/// The sliding-window joint estimator of the head's fixed misalignments.
#[derive(Debug, Clone)]
pub struct MisalignmentWindow {
    config: WindowConfig,
    refine: RefineConfig,
    /// The calibration's misalignments, which the window starts from and the frames' shifts
    /// are taken against.
    calibration: Misalignment,
    shared: Misalignment,
    covariance: Matrix3<f64>,
    frames: VecDeque<WindowFrame>,
    /// What the frames that left the window said about the shared angles: information
    /// matrix and the angles it centres on.
    prior_information: Matrix3<f64>,
    prior_mean: Vector3<f64>,
    /// With each frame's own pitch: the pitches of the window's frames, oldest first.
    frame_pitches: VecDeque<FramePitch>,
}

impl MisalignmentWindow {
    /// Starts from the calibration's misalignments (zero for a rectified pair).
    pub fn new(extrinsics: &Extrinsics, config: WindowConfig, refine: RefineConfig) -> Self {
        let calibration = Misalignment::from_extrinsics(extrinsics);
        Self {
            config,
            refine,
            calibration,
            shared: calibration,
            covariance: Matrix3::zeros(),
            frames: VecDeque::with_capacity(config.frames + 1),
            prior_information: Matrix3::zeros(),
            prior_mean: Vector3::zeros(),
            frame_pitches: VecDeque::with_capacity(config.frames + 1),
        }
    }

    /// The current misalignment estimate.
    ///
    /// With each frame's own pitch, `pitch_deg` is the frames' mean pitch, its σ the mean's
    /// standard error, and `pitch_spread_deg` their spread.
    pub fn estimate(&self) -> MisalignmentEstimate {
        let sd = |i: usize| self.covariance[(i, i)].max(0.0).sqrt().to_degrees();
        let (mut pitch, mut pitch_sigma, mut spread) = (self.shared.pitch, sd(0), 0.0);
        if let Some(s) = self.pitch_spread() {
            pitch += s.mean;
            pitch_sigma = (s.sample_variance / self.frame_pitches.len() as f64)
                .sqrt()
                .to_degrees();
            spread = s.variance.max(0.0).sqrt().to_degrees();
        }
        MisalignmentEstimate {
            pitch_deg: pitch.to_degrees(),
            roll_deg: self.shared.roll.to_degrees(),
            baseline_tilt_deg: self.shared.tilt.to_degrees(),
            pitch_sigma_deg: pitch_sigma,
            roll_sigma_deg: sd(1),
            baseline_tilt_sigma_deg: sd(2),
            pitch_spread_deg: spread,
            frames: self.frames.len(),
        }
    }

    /// The window's frames' own pitches about the shared one; `None` without them or below
    /// [`MIN_SPREAD_FRAMES`].
    fn pitch_spread(&self) -> Option<PitchSpread> {
        let n = self.frame_pitches.len();
        if n < MIN_SPREAD_FRAMES {
            return None;
        }
        let nf = n as f64;
        let mean = self.frame_pitches.iter().map(|p| p.offset).sum::<f64>() / nf;
        let sample_variance = self
            .frame_pitches
            .iter()
            .map(|p| (p.offset - mean).powi(2))
            .sum::<f64>()
            / (nf - 1.0);
        let noise = self.frame_pitches.iter().map(|p| p.variance).sum::<f64>() / nf;
        Some(PitchSpread {
            mean,
            sample_variance,
            variance: sample_variance - noise,
        })
    }

    /// The newest frame's yaws refitted with its own pitch (see [`WindowConfig::frame_pitch`])
    /// from `start`, its yaws with the shared angles held: its free pitch joins the window's,
    /// and while the frames spread beyond their noise its pitch is refined again, held to
    /// their mean by the spread. A frame whose pitch cannot be refined keeps `start`.
    fn refit_with_frame_pitch(&mut self, start: VergeAngles) -> VergeAngles {
        let Some(newest) = self.frames.back() else {
            return start;
        };
        let shared = self.shared;
        let Ok(free) =
            misaligned::refine_yaws_and_pitch(&newest.matches, start, &shared, None, &self.refine)
        else {
            return start;
        };
        self.frame_pitches.push_back(FramePitch {
            offset: free.pitch - shared.pitch,
            variance: free.pitch_variance,
        });
        while self.frame_pitches.len() > self.config.frames {
            self.frame_pitches.pop_front();
        }
        let Some(spread) = self.pitch_spread().filter(|s| s.variance > 0.0) else {
            return start;
        };
        let prior = PitchPrior {
            centre: shared.pitch + spread.mean,
            variance: spread.variance,
        };
        misaligned::refine_yaws_and_pitch(
            &newest.matches,
            start,
            &shared,
            Some(prior),
            &self.refine,
        )
        .map_or(start, |fit| fit.angles)
    }

    /// Takes a new frame's consistent matches (calibrated, with the estimator's weights) and
    /// its yaws from the per-frame fit; moves the window on, refines the shared angles, and
    /// returns the frame's yaws moved by what the learned angles, against the calibration's,
    /// move its refit (the refit with them held, and with the frame's own pitch when
    /// [`WindowConfig::frame_pitch`], less the refit with the calibration's, on the same
    /// matches from the same start).
    pub fn update(
        &mut self,
        matches: Vec<Correspondence>,
        start: VergeAngles,
    ) -> Result<VergeAngles, EssentialError> {
        // The refit with the calibration's angles is the shift's reference and, the learned
        // angles being small corrections to them, the frame's start in the joint steps.
        let calibrated = misaligned::refine_yaws(&matches, start, &self.calibration, &self.refine)?;
        self.frames.push_back(WindowFrame {
            matches,
            angles: calibrated.angles,
        });
        while self.frames.len() > self.config.frames {
            if let Some(old) = self.frames.pop_front() {
                self.marginalise(&old);
            }
        }
        for _ in 0..self.config.steps {
            self.step();
        }
        let newest = self.frames.back_mut().ok_or(EssentialError::Degenerate)?;
        let learned =
            misaligned::refine_yaws(&newest.matches, newest.angles, &self.shared, &self.refine)?;
        newest.angles = learned.angles;
        let learned = if self.config.frame_pitch {
            self.refit_with_frame_pitch(learned.angles)
        } else {
            learned.angles
        };
        Ok(VergeAngles::new(
            start.alpha_l + (learned.alpha_l - calibrated.angles.alpha_l),
            start.alpha_r + (learned.alpha_r - calibrated.angles.alpha_r),
        ))
    }

    /// Folds what `frame` says about the shared angles, its yaws eliminated, into the prior,
    /// linearised at the current estimate, after discounting the prior by the memory.
    fn marginalise(&mut self, frame: &WindowFrame) {
        let Some((info, grad)) = frame_normal(frame, &self.shared, &self.refine)
            .and_then(|n| n.reduced().map(|(s, g, _)| (s, g)))
        else {
            return;
        };
        let keep = 1.0 - 1.0 / self.config.memory.max(1) as f64;
        let old = self.prior_information * keep;
        let total = old + info;
        let Some(total_inv) = total.try_inverse() else {
            return;
        };
        let s = self.shared.to_vector();
        self.prior_mean = total_inv * (old * self.prior_mean + info * s - grad);
        self.prior_information = total;
    }

    /// One robust Gauss-Newton step of the joint fit. A shared block the window does not
    /// constrain (too few frames or views, a singular system) leaves the shared angles and the
    /// yaws where they are.
    fn step(&mut self) {
        let shared = self.shared;
        let refine = self.refine;
        let normals: Vec<Option<FrameNormal>> = self
            .frames
            .par_iter()
            .map(|f| frame_normal(f, &shared, &refine))
            .collect();
        let mut s = self.prior_information;
        let mut g = self.prior_information * (self.shared.to_vector() - self.prior_mean);
        let mut reduced = Vec::with_capacity(normals.len());
        for n in &normals {
            match n.as_ref().and_then(FrameNormal::reduced) {
                Some((sj, gj, aa_inv)) => {
                    s += sj;
                    g += gj;
                    reduced.push(Some(aa_inv));
                }
                None => reduced.push(None),
            }
        }
        // Held angles: their rows and columns leave the system.
        let free = [self.config.pitch, true, self.config.tilt];
        for (i, &f) in free.iter().enumerate() {
            if !f {
                for j in 0..3 {
                    s[(i, j)] = 0.0;
                    s[(j, i)] = 0.0;
                }
                s[(i, i)] = 1.0;
                g[i] = 0.0;
            }
        }
        let Some(s_inv) = s.try_inverse() else {
            return;
        };
        let ds = -(s_inv * g);
        if !ds.iter().all(|v| v.is_finite()) {
            return;
        }
        let mut covariance = s_inv;
        for (i, &f) in free.iter().enumerate() {
            if !f {
                for j in 0..3 {
                    covariance[(i, j)] = 0.0;
                    covariance[(j, i)] = 0.0;
                }
            }
        }
        self.covariance = covariance;
        self.shared = Misalignment::from_vector(&(self.shared.to_vector() + ds));
        for ((frame, n), aa_inv) in self.frames.iter_mut().zip(&normals).zip(&reduced) {
            if let (Some(n), Some(aa_inv)) = (n, aa_inv) {
                let da = -(aa_inv * (n.ba + n.as_ * ds));
                frame.angles.alpha_l += da[0];
                frame.angles.alpha_r += da[1];
            }
        }
    }
}

/// The normal equations of one frame at the current shared angles (Cauchy IRLS weights on
/// its own robust scale); `None` when it has no usable residual.
fn frame_normal(
    frame: &WindowFrame,
    shared: &Misalignment,
    refine: &RefineConfig,
) -> Option<FrameNormal> {
    let (e, de) = misaligned::essential_and_derivatives(frame.angles, shared);
    let rg: Vec<(f64, SVector<f64, 5>)> = frame
        .matches
        .iter()
        .filter_map(|c| {
            let (r, g) = misaligned::residual_and_gradient(&e, &de, c)?;
            let s = c.weight.sqrt();
            Some((r * s, SVector::<f64, 5>::from(g) * s))
        })
        .collect();
    let residuals: Vec<f64> = rg.iter().map(|(r, _)| *r).collect();
    let sigma = crate::essential::mad_sigma(&residuals, refine.min_sigma);
    let mut h = SMatrix::<f64, 5, 5>::zeros();
    let mut b = SVector::<f64, 5>::zeros();
    for (r, g) in &rg {
        let w = refine.loss.weight(*r, sigma);
        h += w * g * g.transpose();
        b += w * g * *r;
    }
    if rg.is_empty() {
        return None;
    }
    let scale = 1.0 / (sigma * sigma);
    let (h, b) = (h * scale, b * scale);
    Some(FrameNormal {
        aa: h.fixed_view::<2, 2>(0, 0).into_owned(),
        as_: h.fixed_view::<2, 3>(0, 2).into_owned(),
        ss: h.fixed_view::<3, 3>(2, 2).into_owned(),
        ba: b.fixed_view::<2, 1>(0, 0).into_owned(),
        bs: b.fixed_view::<3, 1>(2, 0).into_owned(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::essential::constrained;
    use crate::essential::testutil::misaligned_synthetic;

    /// Frame `k`'s view: 1200 matches of a head at yaws `a` misaligned by `truth` (noise
    /// `noise_px` at focal length `f`, drawn with `seed`), of which it sees half of the field,
    /// a different half every frame, so that the per-frame model's error depends on where
    /// the matches lie.
    fn half_view(
        a: VergeAngles,
        truth: &Misalignment,
        noise_px: f64,
        f: f64,
        seed: u64,
        k: u64,
    ) -> Vec<Correspondence> {
        let side = [1.0, -1.0][k as usize % 2];
        misaligned_synthetic(a, truth, 1200, noise_px, f, seed)
            .into_iter()
            .filter(|c| c.left[(k as usize / 2) % 2] * side > 0.0)
            .collect()
    }

    /// A head with a fixed pitch and roll, its verge moving, the view new every frame (new
    /// points, and each frame sees only part of the field: the per-frame model's error
    /// depends on where the matches lie). The window recovers the pitch and roll, and its
    /// verge beats the per-frame model's once it has seen a few views.
    #[test]
    fn the_window_learns_a_fixed_pitch_and_roll_and_unbends_the_verge() {
        let truth = Misalignment {
            pitch: 0.15f64.to_radians(),
            roll: 0.1f64.to_radians(),
            tilt: 0.0,
        };
        let (f, noise_px) = (700.0, 0.15);
        let refine = RefineConfig::default();
        let mut window =
            MisalignmentWindow::new(&Extrinsics::default(), WindowConfig::default(), refine);
        let (mut plain_err, mut window_err) = (Vec::new(), Vec::new());
        for k in 0..40u64 {
            let t = k as f64 * 0.4;
            let a = VergeAngles::new(
                (1.0 + 0.5 * t.sin()).to_radians(),
                (-0.5 + 0.4 * (0.7 * t).cos()).to_radians(),
            );
            let m = half_view(a, &truth, noise_px, f, 100 + k, k);
            let plain = constrained::refine(&m, a, &refine).unwrap();
            let corrected = window.update(m, plain.angles).unwrap();
            if k >= 10 {
                plain_err.push((plain.angles.verge() - a.verge()).to_degrees().abs());
                window_err.push((corrected.verge() - a.verge()).to_degrees().abs());
            }
        }
        let est = window.estimate();
        assert!((est.pitch_deg - 0.15).abs() < 0.01, "{est:?}");
        assert!((est.roll_deg - 0.1).abs() < 0.01, "{est:?}");
        assert!(
            est.pitch_sigma_deg > 0.0 && est.pitch_sigma_deg < 0.01,
            "{est:?}"
        );
        assert_eq!((est.baseline_tilt_deg, est.frames), (0.0, 30));
        let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        assert!(
            max(&window_err) < 0.05 && mean(&window_err) < 0.1 * mean(&plain_err),
            "window {:.4}/{:.4}° vs per-frame {:.4}/{:.4}° (mean/max)",
            mean(&window_err),
            max(&window_err),
            mean(&plain_err),
            max(&plain_err)
        );
    }

    /// The estimate of a window `config` after 30 frames of a head misaligned by `truth`, its
    /// verge creeping, 600 matches a frame (0.1 px noise) drawn with seeds from `seed`.
    fn learned(truth: &Misalignment, config: WindowConfig, seed: u64) -> MisalignmentEstimate {
        let refine = RefineConfig::default();
        let mut window = MisalignmentWindow::new(&Extrinsics::default(), config, refine);
        for k in 0..30u64 {
            let a = VergeAngles::new((0.5 + 0.02 * k as f64).to_radians(), -0.3f64.to_radians());
            let m = misaligned_synthetic(a, truth, 600, 0.1, 700.0, seed + k);
            let plain = constrained::refine(&m, a, &refine).unwrap();
            window.update(m, plain.angles).unwrap();
        }
        window.estimate()
    }

    /// With the baseline's tilt free too, a tilted baseline is recovered as well.
    #[test]
    fn the_window_learns_a_baseline_tilt_when_asked() {
        let truth = Misalignment {
            pitch: -0.1f64.to_radians(),
            roll: 0.05f64.to_radians(),
            tilt: 0.3f64.to_radians(),
        };
        let config = WindowConfig {
            tilt: true,
            ..WindowConfig::default()
        };
        let est = learned(&truth, config, 200);
        assert!((est.pitch_deg + 0.1).abs() < 0.01, "{est:?}");
        assert!((est.roll_deg - 0.05).abs() < 0.01, "{est:?}");
        assert!((est.baseline_tilt_deg - 0.3).abs() < 0.05, "{est:?}");
    }

    /// With the pitch held, the window learns the roll alone and leaves the pitch at the
    /// calibration's, with no uncertainty.
    #[test]
    fn the_window_learns_the_roll_alone_when_the_pitch_is_held() {
        let truth = Misalignment {
            pitch: 0.0,
            roll: 0.08f64.to_radians(),
            tilt: 0.0,
        };
        let config = WindowConfig::roll();
        let est = learned(&truth, config, 400);
        assert_eq!((est.pitch_deg, est.pitch_sigma_deg), (0.0, 0.0), "{est:?}");
        assert!((est.roll_deg - 0.08).abs() < 0.01, "{est:?}");
        assert!(est.roll_sigma_deg > 0.0, "{est:?}");
    }

    /// The verges of 40 frames of a head whose right camera rolls by 0.1° and pitches by
    /// `wobble(k)` in frame `k`, each frame seeing half of the field (a different half every
    /// frame), through a window `config`: absolute errors (degrees) from frame 10 on, and the
    /// window's last estimate.
    fn wobbling(
        config: WindowConfig,
        wobble: impl Fn(u64) -> f64,
    ) -> (Vec<f64>, MisalignmentEstimate) {
        let refine = RefineConfig::default();
        let mut window = MisalignmentWindow::new(&Extrinsics::default(), config, refine);
        let mut errors = Vec::new();
        for k in 0..40u64 {
            let truth = Misalignment {
                pitch: wobble(k).to_radians(),
                roll: 0.1f64.to_radians(),
                tilt: 0.0,
            };
            let a = VergeAngles::new(
                (1.0 + 0.5 * (0.4 * k as f64).sin()).to_radians(),
                -0.5f64.to_radians(),
            );
            let m = half_view(a, &truth, 0.15, 700.0, 700 + k, k);
            let plain = constrained::refine(&m, a, &refine).unwrap();
            let corrected = window.update(m, plain.angles).unwrap();
            if k >= 10 {
                errors.push((corrected.verge() - a.verge()).to_degrees().abs());
            }
        }
        (errors, window.estimate())
    }

    /// A pitch that changes from frame to frame: with each frame's own pitch the window
    /// learns the pitches' spread and mean, and its verges beat the roll window's, which
    /// the pitches bend.
    #[test]
    fn each_frame_gets_its_own_pitch_where_the_frames_pitch_apart() {
        // ±0.05° in a fixed pseudo-random order about a mean of 0.02°.
        let wobble = |k: u64| 0.02 + 0.05 * ((k * 7919 % 13) as f64 / 6.0 - 1.0);
        let (own, est) = wobbling(WindowConfig::roll_and_frame_pitch(), wobble);
        let (roll, _) = wobbling(WindowConfig::roll(), wobble);
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        assert!(
            mean(&own) < 0.5 * mean(&roll),
            "own pitch {:.4}° vs roll window {:.4}° (mean)",
            mean(&own),
            mean(&roll)
        );
        assert!((est.pitch_spread_deg - 0.032).abs() < 0.01, "{est:?}");
        assert!((est.pitch_deg - 0.02).abs() < 0.01, "{est:?}");
        assert!((est.roll_deg - 0.1).abs() < 0.01, "{est:?}");
    }

    /// A pitch that holds: the frames' pitches spread no more than their noise, so the prior
    /// holds each at the mean and the verges are the roll window's.
    #[test]
    fn a_steady_pitch_leaves_the_roll_window_s_verges() {
        let (own, est) = wobbling(WindowConfig::roll_and_frame_pitch(), |_| 0.0);
        let (roll, _) = wobbling(WindowConfig::roll(), |_| 0.0);
        let worst = own
            .iter()
            .zip(&roll)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.002, "verges move by up to {worst}°; {est:?}");
        assert!(est.pitch_spread_deg < 0.005, "{est:?}");
    }

    /// Frames that leave a short window keep informing the shared angles through the prior:
    /// with a memory the estimate is as accurate as the long window's and surer than a window
    /// that forgets them at once.
    #[test]
    fn frames_that_leave_the_window_stay_in_its_prior() {
        let truth = Misalignment {
            pitch: 0.12f64.to_radians(),
            roll: -0.08f64.to_radians(),
            tilt: 0.0,
        };
        let refine = RefineConfig::default();
        let run = |memory: usize| {
            let config = WindowConfig {
                frames: 5,
                memory,
                ..WindowConfig::default()
            };
            let mut window = MisalignmentWindow::new(&Extrinsics::default(), config, refine);
            for k in 0..40u64 {
                let a = VergeAngles::new(
                    (1.0 + 0.3 * (k as f64 * 0.5).sin()).to_radians(),
                    -0.4f64.to_radians(),
                );
                let m = misaligned_synthetic(a, &truth, 400, 0.2, 700.0, 300 + k);
                let plain = constrained::refine(&m, a, &refine).unwrap();
                window.update(m, plain.angles).unwrap();
            }
            window.estimate()
        };
        let (remembering, forgetting) = (run(300), run(1));
        assert_eq!(remembering.frames, 5);
        assert!(
            (remembering.pitch_deg - 0.12).abs() < 0.01,
            "{remembering:?}"
        );
        assert!(
            (remembering.roll_deg + 0.08).abs() < 0.01,
            "{remembering:?}"
        );
        assert!(
            remembering.pitch_sigma_deg < 0.6 * forgetting.pitch_sigma_deg,
            "{remembering:?} vs {forgetting:?}"
        );
    }

    /// The window starts from the calibration's misalignments and, without tilt, holds its
    /// tilt there.
    #[test]
    fn the_window_starts_from_the_calibration() {
        let e = Extrinsics {
            pitch_deg: 0.2,
            roll_deg: -0.1,
            baseline_tilt_deg: 0.05,
            ..Extrinsics::default()
        };
        let w = MisalignmentWindow::new(&e, WindowConfig::default(), RefineConfig::default());
        let est = w.estimate();
        assert!((est.pitch_deg - 0.2).abs() < 1e-12 && (est.roll_deg + 0.1).abs() < 1e-12);
        assert!((est.baseline_tilt_deg - 0.05).abs() < 1e-12 && est.frames == 0);
    }
}
