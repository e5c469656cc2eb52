//! One frame pair in, one verge measurement out: descriptors → matching → sub-pixel
//! refinement → calibrated coordinates → RANSAC → robust refinement (constrained or general).
//!
//! The defaults are the most accurate settings for a verge head: every match that passes the
//! ratio test and the left-right check is used (not the thesis' best 20), matches are
//! re-localised on the octave-0 Sobel planes when the frame carries them, RANSAC provides the
//! starting point and a Cauchy-weighted Gauss-Newton refinement over all matches gives the
//! answer and its uncertainty.

use std::num::NonZeroU16;
use std::sync::{Arc, Mutex, OnceLock};

use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use stereocal_hdl::regs::MAX_OCTAVES;

use crate::calib::Calibration;
use crate::descriptor::{describe, DescriptorConfig, DescriptorSet};
use crate::epipolar_band::{EpipolarBand, PoseRange};
use crate::essential::constrained::{self, VergeAngles};
use crate::essential::general::{self, RelativePose, YawPitchRoll};
use crate::essential::{cauchy_cost, Correspondence, EssentialError, RefineConfig};
use crate::essential::{rot_x, rot_y, rot_z};
use crate::features::{FeatureFrame, Keypoint, SobelPlane};
use crate::matching::{match_descriptors, Gate, Match, MatchConfig};
use crate::ransac::{ransac, RansacConfig};
use crate::subpixel::{guided_pair, refine_pair, RefinedPair, SubpixelConfig, Warp};
use crate::window_overlap::sigma_inflation;

/// A matched point pair in full-resolution pixels: (left, right).
pub type PixelPair = ([f64; 2], [f64; 2]);

/// A point pair consistent with a frame's estimate, as `matches.csv` gives it: where each
/// camera saw the point (full-resolution pixels as the fabric delivered them, so distorted)
/// and the weight the refinement gave the pair (1 = a typical match).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConsistentPair {
    /// The left camera's pixel.
    pub left: [f64; 2],
    /// The right camera's pixel.
    pub right: [f64; 2],
    /// The pair's relative weight in the refinement.
    pub weight: f64,
}

/// Which essential-matrix model gives the verge angle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Model {
    /// Both cameras only yaw (thesis): two unknowns, least noise.
    #[default]
    Constrained,
    /// Free relative rotation and baseline direction (heads that also tilt).
    General,
}

impl Model {
    /// The relative pitch and roll, beyond the calibration's, that the matching gate lets
    /// through (degrees). The constrained model explains none: a head whose calibration misses
    /// more than a degree of either is outside what it can fit, so a wider gate would only let
    /// in false candidates. The general model fits them, for heads assembled within a few
    /// degrees.
    pub fn misalignment_allowance_deg(self) -> f64 {
        match self {
            Model::Constrained => 1.0,
            Model::General => 3.0,
        }
    }
}

/// Settings of the whole per-frame estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimatorConfig {
    /// Descriptor layout and rotation.
    pub descriptor: DescriptorConfig,
    /// Descriptor matching: the vertical band, the ratio test, the left-right check.
    pub matching: MatchConfig,
    /// Sub-pixel refinement on the octave-0 Sobel planes (skipped for patch frames).
    pub subpixel: Option<SubpixelConfig>,
    /// RANSAC start (its `threshold` is replaced by `ransac_threshold_px` / focal length).
    pub ransac: Option<RansacConfig>,
    /// RANSAC inlier threshold in pixels: localisation noise is a matter of pixels, so it
    /// enters the fit divided by the focal length and holds for any camera (README, "Geometry,
    /// not pixel constants"). The default's 1.5 px only picks RANSAC's hypothesis, which starts
    /// the robust refinement: halving or doubling it changes no estimate of the rendered road
    /// or of the KITTI drive (README, "Sensitivity of the constants").
    pub ransac_threshold_px: f64,
    /// The robust refinement that gives the estimate and its uncertainty.
    pub refine: RefineConfig,
    /// The essential-matrix model the refinement fits.
    pub model: Model,
    /// Fewer matches (after refinement) or inliers than this → no estimate for the frame. The
    /// default's 12: the frame's σ, which the filter weighs it by, comes from the MAD of its
    /// residuals, whose relative error under Gaussian noise is about 1.17/√n, over a third
    /// below 12. Halving or doubling it changes no estimate of the rendered road or the KITTI
    /// drive, whose frames keep about two hundred matches (README, "Sensitivity of the constants").
    pub min_matches: usize,
    /// Guided matching of the keypoints the descriptors left unmatched (needs Sobel planes).
    pub guided: Option<GuidedConfig>,
    /// Relative pitch and roll beyond the calibration's that the epipolar gate allows
    /// (degrees); `None`: the model's own (see [`Model::misalignment_allowance_deg`]).
    pub misalignment_allowance_deg: Option<f64>,
    /// Weigh each refined match by the inverse variance of its vertical position,
    /// `1 / max(σ_v, floor)²`, with this floor in pixels; `None`: every match alike.
    ///
    /// The verge lives in the vertical disparities, and the sub-pixel refinement knows how well
    /// it placed each one vertically (σ_v spans a decade between a corner and a weak edge), so
    /// equal weights let the vaguest matches add as much noise as the sharpest. σ_v is the
    /// noise bound of one window, blind to the interpolation bias that stays at a few
    /// hundredths of a pixel, so the floor keeps one sharp match from outweighing the rest.
    pub weight_floor_px: Option<f32>,
}

/// Guided matching: every left keypoint without a descriptor match is searched for in the
/// right magnitude plane around the position its matched neighbours predict. More matches
/// lower the noise of the verge estimate roughly as 1/√N.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GuidedConfig {
    /// Matched neighbours whose median parallax (displacement beyond the rotation homography's)
    /// predicts the position (the default's five: with up to two of them false, their median
    /// stays within the true ones' parallaxes).
    pub neighbours: usize,
    /// Horizontal search range around the prediction (pixels). The default's 6: halving or
    /// doubling it moves the rendered road's raw median error by < 0.0003° and the KITTI
    /// drive's by < 0.001° (README, "Sensitivity of the constants").
    pub search_px: i32,
    /// Only neighbours within this distance (pixels) are used. The default's 80: halving it
    /// raises the rendered road's raw median error by 0.0007° and the KITTI drive's by up to
    /// 0.0015°; doubling it moves the road's by 0.0001° and the drive's by < 0.002°
    /// (README, "Sensitivity of the constants").
    pub max_neighbour_distance_px: f32,
    /// Also searches, in every `grid_px` x `grid_px` cell of the left magnitude plane, its
    /// strongest pixel that no match lies within half a cell of. Where the matches' sub-pixel
    /// noise limits the verge (a noisy sensor, an exact rendering) the extra points lower it;
    /// where errors shared by neighbouring points do (the real drive), they do not, and they
    /// cost a refinement each. `None` (the default): keypoints only (README, "Grid points").
    pub grid_px: Option<NonZeroU16>,
}

impl Default for GuidedConfig {
    fn default() -> Self {
        Self {
            neighbours: 5,
            search_px: 6,
            max_neighbour_distance_px: 80.0,
            grid_px: None,
        }
    }
}

impl Default for EstimatorConfig {
    fn default() -> Self {
        Self {
            descriptor: DescriptorConfig::default(),
            matching: MatchConfig::default(),
            subpixel: Some(SubpixelConfig::default()),
            ransac: Some(RansacConfig::default()),
            ransac_threshold_px: 1.5,
            refine: RefineConfig::default(),
            model: Model::Constrained,
            min_matches: 12,
            guided: Some(GuidedConfig::default()),
            misalignment_allowance_deg: None,
            weight_floor_px: Some(0.02),
        }
    }
}

/// Why a frame pair gave no verge estimate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum EstimateError {
    /// Fewer point pairs entered the estimate, or fewer were consistent with it, than
    /// `min_matches`.
    #[error("only {got} usable matches (need {need})")]
    TooFewMatches {
        /// Point pairs, or inliers of the estimate.
        got: usize,
        /// `EstimatorConfig::min_matches`.
        need: usize,
    },
    /// The essential-matrix solve or RANSAC failed.
    #[error(transparent)]
    Essential(#[from] EssentialError),
}

/// The verge measurement of one frame pair.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameEstimate {
    /// Verge angle, degrees, toe-in positive.
    pub verge_deg: f64,
    /// Its 1-σ uncertainty from the refinement's covariance (degrees), widened by the overlap
    /// of the matches' sub-pixel windows when they were refined (`window_overlap`).
    pub sigma_deg: f64,
    /// Constrained model: the two camera yaws. General model: `None`.
    pub angles: Option<VergeAngles>,
    /// General model: `R_01` angles. Constrained model: `None`.
    pub pose: Option<YawPitchRoll>,
    /// The two yaws (the general model's: its verge split as its baseline direction says);
    /// [`VergeEstimator::estimate`]'s first fit centres its second pass on them.
    pub yaws: VergeAngles,
    /// Descriptor matches found.
    pub matches: usize,
    /// Matches that entered the estimate (after sub-pixel rejection).
    pub used: usize,
    /// Point pairs (descriptor and guided matches) consistent with the final estimate.
    pub inliers: usize,
    /// Robust residual scale in pixels (quality of the matches).
    pub residual_px: f64,
    /// Left keypoints the fabric detected, by octave (index 0 = full resolution); empty when
    /// estimated from pixel pairs. The thesis' fig. 5.3 "input data".
    pub keypoints_per_octave: Vec<usize>,
    /// The descriptor matches by the octave of their left keypoint; sums to `matches`, empty
    /// when estimated from pixel pairs. Fig. 5.3 asks how much the coarse octaves contribute.
    pub matches_per_octave: Vec<usize>,
    /// Constrained model: the matches consistent with the estimate, calibrated and weighted as
    /// the refinement took them; the misalignment window fits its shared angles to them.
    /// General model: empty.
    pub consistent: Vec<Correspondence>,
    /// Either model: the point pairs consistent with the estimate, in pixels, with their
    /// weights; `inliers` of them.
    pub consistent_pairs: Vec<ConsistentPair>,
}

/// The per-frame verge estimator.
#[derive(Debug, Clone)]
pub struct VergeEstimator {
    calib: Calibration,
    config: EstimatorConfig,
    /// The epipolar band over the head's whole range for the image size first seen: a head's
    /// frames keep their size.
    band: OnceLock<((u32, u32), Arc<EpipolarBand>)>,
    /// The bands near the first fit's yaws used last, most recent first, with their image size
    /// and rounded yaws: a head that holds its verge reuses them frame after frame.
    near_band: Arc<Mutex<NearBands>>,
}

/// Bands near recent estimates, most recent first, by what they were built for.
type NearBands = Vec<(NearKey, Arc<EpipolarBand>)>;

/// What a band near a first fit is built for: image size and yaws in [`YAW_QUANTUM_DEG`]
/// steps.
type NearKey = (u32, u32, i64, i64);

/// Bands near recent estimates kept for reuse: a still head's verge is well determined, but
/// how it splits between the two yaws wanders by a degree or two from frame to frame (the
/// split only shows in the near points' parallax), so its rounded yaws cycle through a few
/// values.
const NEAR_BANDS: usize = 8;

/// The step the yaws are rounded to before a pair is matched near them: a head that holds
/// still keeps its rounded yaws, so its band is built once, and the band's reach grows by one
/// step to cover the rounding (half a step per yaw, a whole one for the verge).
const YAW_QUANTUM_DEG: f64 = 0.5;

/// How far from the first fit's yaws the second pass's band reaches (degrees, each yaw and the
/// verge; see [`VergeEstimator::estimate`]): the keypoints' fit splits the verge between the
/// yaws only to within a degree or two on a real drive (the split shows only in the near
/// points' parallax), and a false split must not cut true matches.
pub const REACH_DEG: f64 = 5.0;

/// How far, in full-resolution pixels, a keypoint's row may be from its true one on each side:
/// the fabric's quadratic fit places an extremum within half a sample of its octave's grid,
/// and both keypoints of a match carry that error.
fn localisation_px(k: &Keypoint) -> f32 {
    f32::from(1u16 << k.octave.min(15))
}

impl VergeEstimator {
    /// An estimator for the head `calib` describes.
    pub fn new(calib: Calibration, config: EstimatorConfig) -> Self {
        Self {
            calib,
            config,
            band: OnceLock::new(),
            near_band: Arc::default(),
        }
    }

    /// The settings it was made with.
    pub fn config(&self) -> &EstimatorConfig {
        &self.config
    }

    fn misalignment_allowance_deg(&self) -> f64 {
        self.config
            .misalignment_allowance_deg
            .unwrap_or(self.config.model.misalignment_allowance_deg())
    }

    /// The epipolar band of `width` x `height` frames over the poses near `near` (see
    /// [`YAW_QUANTUM_DEG`]), or over the head's whole range when `None`.
    fn band(&self, width: u32, height: u32, near: Option<VergeAngles>) -> Arc<EpipolarBand> {
        let allowance = self.misalignment_allowance_deg();
        let Some(yaws) = near else {
            let range = PoseRange::verge_head(allowance);
            let build = || Arc::new(EpipolarBand::new(&self.calib, width, height, &range));
            let (size, band) = self.band.get_or_init(|| ((width, height), build()));
            return if *size == (width, height) {
                band.clone()
            } else {
                build()
            };
        };
        let step = |a: f64| (a.to_degrees() / YAW_QUANTUM_DEG).round() as i64;
        let key = (width, height, step(yaws.alpha_l), step(yaws.alpha_r));
        // A poisoned lock only means another thread panicked while building: build anew.
        let mut cache = self.near_band.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(at) = cache.iter().position(|(k, _)| *k == key) {
            let hit = cache.remove(at);
            cache.insert(0, hit.clone());
            return hit.1;
        }
        let rounded = |s: i64| (s as f64 * YAW_QUANTUM_DEG).to_radians();
        let range = PoseRange::around(
            VergeAngles::new(rounded(key.2), rounded(key.3)),
            REACH_DEG + YAW_QUANTUM_DEG,
            allowance,
        );
        let band = Arc::new(EpipolarBand::new(&self.calib, width, height, &range));
        cache.truncate(NEAR_BANDS - 1);
        cache.insert(0, (key, band.clone()));
        band
    }

    /// The map `K_r R K_l⁻¹` of left pixels to right pixels that turning the cameras to
    /// `near`'s yaws (the calibration's when `None`), with the calibration's pitch and roll,
    /// makes for distant points: what the sub-pixel refinement warps its windows by.
    fn rotation_homography(&self, near: Option<VergeAngles>) -> Matrix3<f64> {
        let e = &self.calib.extrinsics;
        let yaws = near.unwrap_or_else(|| VergeAngles::from_extrinsics(e));
        let right =
            rot_y(yaws.alpha_r) * rot_x(e.pitch_deg.to_radians()) * rot_z(e.roll_deg.to_radians());
        let k = |c: &crate::calib::CameraIntrinsics| {
            Matrix3::new(c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0)
        };
        let k_left_inv = k(&self.calib.left)
            .try_inverse()
            .unwrap_or_else(Matrix3::identity);
        k(&self.calib.right) * right.transpose() * rot_y(yaws.alpha_l) * k_left_inv
    }

    /// The descriptor matches of two frames, in the band of the poses near `near` (the whole
    /// range's when `None`).
    fn matches(
        &self,
        left: &FeatureFrame,
        right: &FeatureFrame,
        (dl, dr): (&DescriptorSet, &DescriptorSet),
        near: Option<VergeAngles>,
    ) -> Vec<Match> {
        let config = &self.config.matching;
        let (lk, rk) = (left.keypoints(), right.keypoints());
        match config.gate {
            Gate::Epipolar => {
                let band = self.band(left.width, left.height, near);
                let rows = |k: &Keypoint| band.rows(k.x, k.y, localisation_px(k));
                match_descriptors(dl, lk, dr, rk, config, &rows)
            }
            Gate::Rows(px) => {
                let rows = |k: &Keypoint| [k.y - px, k.y + px];
                match_descriptors(dl, lk, dr, rk, config, &rows)
            }
            Gate::Off => {
                let rows = |_: &Keypoint| [f32::NEG_INFINITY, f32::INFINITY];
                match_descriptors(dl, lk, dr, rk, config, &rows)
            }
        }
    }

    /// The matched full-resolution point pairs, refined to sub-pixel precision through the
    /// warp of the yaws `near` (the calibration's when `None`) when configured and possible,
    /// each with its vertical 1-σ in pixels when refined.
    fn point_pairs(
        &self,
        left: &FeatureFrame,
        right: &FeatureFrame,
        matches: &[Match],
        near: Option<VergeAngles>,
    ) -> Vec<(PixelPair, Option<f32>)> {
        let planes = left.plane(0).zip(right.plane(0));
        let homography = self.rotation_homography(near);
        matches
            .par_iter()
            .filter_map(|m| {
                let kl = left.keypoints()[m.left as usize];
                let kr = right.keypoints()[m.right as usize];
                match (self.config.subpixel, planes) {
                    (Some(cfg), Some((pl, pr))) => {
                        let warp = local_warp(&homography, kl.x, kl.y);
                        refine_pair(pl, pr, [kl.x, kl.y], [kr.x, kr.y], &warp, &cfg).map(refined)
                    }
                    _ => Some((
                        ([kl.x as f64, kl.y as f64], [kr.x as f64, kr.y as f64]),
                        None,
                    )),
                }
            })
            .collect()
    }

    /// Estimates the verge angle of one frame pair, from that pair alone.
    ///
    /// First the head's yaws: a fit to the descriptor matches in the band of the head's whole
    /// range, at their keypoints' positions. It fixes the verge to a few hundredths of a
    /// degree and its split between the yaws to a degree or two, which is all the second pass
    /// needs: only the matches in the band of the poses within [`REACH_DEG`] of those yaws
    /// (near the image corners much narrower than the whole range's, so it drops the false
    /// matches the wider band let in), refined through sub-pixel windows warped as those yaws
    /// turn the cameras (unrounded: the band's rounding to `YAW_QUANTUM_DEG` serves its
    /// cache, and would move the warp's verge by up to a whole step). When
    /// that gives no estimate, or the first fit failed, the whole range's matches are refined
    /// as they are.
    pub fn estimate(
        &self,
        left: &FeatureFrame,
        right: &FeatureFrame,
    ) -> Result<FrameEstimate, EstimateError> {
        // The two images are independent: both cores describe them.
        let (dl, dr) = rayon::join(
            || describe(left, &self.config.descriptor),
            || describe(right, &self.config.descriptor),
        );
        let descriptors = (&dl, &dr);
        let whole = self.matches(left, right, descriptors, None);
        let keypoint_pairs: Vec<PixelPair> = whole
            .iter()
            .map(|m| {
                let (kl, kr) = (
                    left.keypoints()[m.left as usize],
                    right.keypoints()[m.right as usize],
                );
                ([kl.x as f64, kl.y as f64], [kr.x as f64, kr.y as f64])
            })
            .collect();
        let first = self
            .estimate_weighted(&keypoint_pairs, &vec![1.0; keypoint_pairs.len()], None)
            .ok()
            .map(|e| e.yaws);
        if let Some(first) = first {
            let yaws = rounded(first);
            let near = match self.config.matching.gate {
                // The near band lies inside the whole range's, so its matches are the whole
                // range's whose right keypoint lies in it; the ratio test already held against
                // the wider band's candidates.
                Gate::Epipolar => {
                    let band = self.band(left.width, left.height, Some(yaws));
                    whole
                        .iter()
                        .filter(|m| {
                            let (kl, kr) = (
                                &left.keypoints()[m.left as usize],
                                &right.keypoints()[m.right as usize],
                            );
                            let [lo, hi] = band.rows(kl.x, kl.y, localisation_px(kl));
                            (lo..=hi).contains(&kr.y)
                        })
                        .copied()
                        .collect()
                }
                Gate::Rows(_) | Gate::Off => whole.clone(),
            };
            if let Ok(est) = self.estimate_from(left, right, near, Some(first)) {
                return Ok(est);
            }
        }
        self.estimate_from(left, right, whole, None)
    }

    /// The estimate from `matches`, refined through the warp of `near` (see
    /// [`VergeEstimator::point_pairs`]), with the guided matches added.
    fn estimate_from(
        &self,
        left: &FeatureFrame,
        right: &FeatureFrame,
        matches: Vec<Match>,
        near: Option<VergeAngles>,
    ) -> Result<FrameEstimate, EstimateError> {
        let mut pairs = self.point_pairs(left, right, &matches, near);
        // Refined pairs carry their windows, which the σ accounts for where they overlap.
        let window_side = match (self.config.subpixel, left.plane(0), right.plane(0)) {
            (Some(sub), Some(_), Some(_)) => Some(sub.window_side() as f64),
            _ => None,
        };
        if let (Some(g), Some(sub), Some(pl), Some(pr)) = (
            self.config.guided,
            self.config.subpixel,
            left.plane(0),
            right.plane(0),
        ) {
            let homography = self.rotation_homography(near);
            let extra = guided_pairs(left, &matches, &pairs, pl, pr, &homography, &g, &sub);
            pairs.extend(extra);
        }
        let weights = match_weights(&pairs, self.config.weight_floor_px);
        let pairs: Vec<PixelPair> = pairs.into_iter().map(|(p, _)| p).collect();
        let mut est = self.estimate_weighted(&pairs, &weights, window_side)?;
        est.matches = matches.len();
        let keypoints = left.keypoints();
        est.keypoints_per_octave = per_octave(keypoints.iter().map(|k| k.octave));
        est.matches_per_octave =
            per_octave(matches.iter().map(|m| keypoints[m.left as usize].octave));
        Ok(est)
    }

    /// Estimates the verge angle from matched pixel pairs (full resolution, distorted).
    pub fn estimate_from_pixels(
        &self,
        pairs: &[PixelPair],
    ) -> Result<FrameEstimate, EstimateError> {
        self.estimate_weighted(pairs, &vec![1.0; pairs.len()], None)
    }

    /// The estimate from `pairs` weighted by `weights`; `window_side`: the side (pixels) of
    /// the sub-pixel windows the pairs were refined on, whose overlaps widen the σ
    /// ([`sigma_inflation`]), or `None` for pairs without windows.
    fn estimate_weighted(
        &self,
        pairs: &[PixelPair],
        weights: &[f64],
        window_side: Option<f64>,
    ) -> Result<FrameEstimate, EstimateError> {
        let need = self.config.min_matches;
        if pairs.len() < need {
            return Err(EstimateError::TooFewMatches {
                got: pairs.len(),
                need,
            });
        }
        let corr: Vec<Correspondence> = pairs
            .iter()
            .zip(weights)
            .map(|((l, r), w)| Correspondence {
                weight: *w,
                ..Correspondence::from_pixels(&self.calib, *l, *r)
            })
            .collect();
        let focal = 0.5 * (self.calib.left.focal_px() + self.calib.right.focal_px());
        // The thesis' solve (4.5): e1..e4 by SVD, rank 2 enforced, the 180° ambiguity
        // resolved, over RANSAC's consensus set (or every match without RANSAC), each match
        // weighted as the refinement weighs it. Its angles start the refinement, and so does
        // RANSAC's own hypothesis (or the calibrated head): on a near-planar scene the linear
        // system loses rank and its solution can be far off, and without RANSAC it also saw
        // the outliers. The lower robust cost wins.
        let (consensus, fallback) = match self.config.ransac {
            Some(cfg) => {
                let cfg = RansacConfig {
                    threshold: self.config.ransac_threshold_px / focal,
                    ..cfg
                };
                let found = ransac(&corr, &cfg)?;
                (found.inliers, found.angles)
            }
            None => (
                vec![true; corr.len()],
                VergeAngles::from_extrinsics(&self.calib.extrinsics),
            ),
        };
        let linear_weights: Vec<f64> = corr
            .iter()
            .zip(&consensus)
            .map(|(c, &inlier)| if inlier { c.weight } else { 0.0 })
            .collect();
        // A degenerate linear system leaves the fallback as the only start.
        let linear = constrained::linear_weighted(&corr, &linear_weights).ok();
        let cfit = lowest_cost(
            linear
                .into_iter()
                .chain([fallback])
                .map(|s| constrained::refine(&corr, s, &self.config.refine)),
            &corr,
            |f| (f.residual_sigma, f.angles.essential()),
        )?;
        let mut est = FrameEstimate {
            verge_deg: cfit.angles.verge_deg(),
            sigma_deg: cfit.verge_sigma.to_degrees(),
            angles: Some(cfit.angles),
            pose: None,
            yaws: cfit.angles,
            matches: pairs.len(),
            used: pairs.len(),
            inliers: cfit.inlier_count(),
            residual_px: cfit.residual_sigma * focal,
            keypoints_per_octave: Vec::new(),
            matches_per_octave: Vec::new(),
            consistent: corr
                .iter()
                .zip(&cfit.inliers)
                .filter_map(|(c, &inlier)| inlier.then_some(*c))
                .collect(),
            consistent_pairs: Vec::new(),
        };
        let mut inliers = cfit.inliers;
        if self.config.model == Model::General {
            // Two starts: the constrained solution (right when the head only verges) and the
            // calibrated head with its fixed misalignments (right when a tilt misleads the
            // constrained fit); the lower robust cost on a common scale wins.
            let starts = [
                RelativePose::from_verge(cfit.angles),
                RelativePose::from_extrinsics(&self.calib.extrinsics),
            ];
            let gfit = lowest_cost(
                starts
                    .iter()
                    .map(|s| general::refine(&corr, *s, &self.config.refine)),
                &corr,
                |f| (f.residual_sigma, f.pose.essential()),
            )?;
            est.verge_deg = gfit.pose.verge().to_degrees();
            est.sigma_deg = gfit.verge_sigma.to_degrees();
            est.angles = None;
            est.consistent = Vec::new();
            est.pose = Some(gfit.pose.yaw_pitch_roll());
            est.yaws = gfit.pose.yaws();
            est.inliers = gfit.inlier_count();
            est.residual_px = gfit.residual_sigma * focal;
            inliers = gfit.inliers;
        }
        est.consistent_pairs = pairs
            .iter()
            .zip(weights)
            .zip(&inliers)
            .filter(|(_, &inlier)| inlier)
            .map(|(((left, right), &weight), _)| ConsistentPair {
                left: *left,
                right: *right,
                weight,
            })
            .collect();
        if let Some(side) = window_side {
            let (points, inlier_weights): (Vec<[f64; 2]>, Vec<f64>) = est
                .consistent_pairs
                .iter()
                .map(|p| (p.left, p.weight))
                .unzip();
            est.sigma_deg *= sigma_inflation(&points, &inlier_weights, side);
        }
        if est.inliers < need {
            return Err(EstimateError::TooFewMatches {
                got: est.inliers,
                need,
            });
        }
        Ok(est)
    }
}

/// Of refinements from several starts, the one with the lowest robust (Cauchy) cost, every
/// cost taken at the smallest residual scale among them so that they share one yardstick;
/// `scale_and_e` gives a fit's residual σ and essential matrix. When every start failed, the
/// first failure.
fn lowest_cost<F>(
    fits: impl Iterator<Item = Result<F, EssentialError>>,
    corr: &[Correspondence],
    scale_and_e: impl Fn(&F) -> (f64, Matrix3<f64>),
) -> Result<F, EssentialError> {
    let mut first_err = None;
    let fits: Vec<F> = fits
        .filter_map(|f| f.map_err(|e| *first_err.get_or_insert(e)).ok())
        .collect();
    let scale = fits
        .iter()
        .map(|f| scale_and_e(f).0)
        .fold(f64::INFINITY, f64::min);
    fits.into_iter()
        .map(|f| (cauchy_cost(&scale_and_e(&f).1, corr, scale), f))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, f)| f)
        .ok_or(first_err.unwrap_or(EssentialError::Degenerate))
}

/// `yaws` rounded to [`YAW_QUANTUM_DEG`].
fn rounded(yaws: VergeAngles) -> VergeAngles {
    let round = |a: f64| (a.to_degrees() / YAW_QUANTUM_DEG).round() * YAW_QUANTUM_DEG;
    VergeAngles::new(
        round(yaws.alpha_l).to_radians(),
        round(yaws.alpha_r).to_radians(),
    )
}

/// The local linear map (Jacobian) of the homography `h` at the left pixel (`x`, `y`): how a
/// window around it appears in the right image.
fn local_warp(h: &Matrix3<f64>, x: f32, y: f32) -> Warp {
    let (x, y) = (f64::from(x), f64::from(y));
    let w = h[(2, 0)] * x + h[(2, 1)] * y + h[(2, 2)];
    let u = (h[(0, 0)] * x + h[(0, 1)] * y + h[(0, 2)]) / w;
    let v = (h[(1, 0)] * x + h[(1, 1)] * y + h[(1, 2)]) / w;
    let j = |r: usize, c: usize, p: f64| ((h[(r, c)] - p * h[(2, c)]) / w) as f32;
    [j(0, 0, u), j(0, 1, u), j(1, 0, v), j(1, 1, v)]
}

/// Where `h` maps the pixel (`x`, `y`).
fn map_point(h: &Matrix3<f64>, x: f32, y: f32) -> [f32; 2] {
    let p = h * Vector3::new(f64::from(x), f64::from(y), 1.0);
    [(p[0] / p[2]) as f32, (p[1] / p[2]) as f32]
}

/// A refined match as the estimator takes it: the pixel pair and its vertical 1-σ.
fn refined(r: RefinedPair) -> (PixelPair, Option<f32>) {
    (
        (
            [f64::from(r.left[0]), f64::from(r.left[1])],
            [f64::from(r.right[0]), f64::from(r.right[1])],
        ),
        Some(r.sigma_v),
    )
}

/// The refinement weight of each pair (see [`EstimatorConfig::weight_floor_px`]), scaled so
/// that the median weight is 1: the robust scale of the residuals, and with it the refinement's
/// residual floor and inlier limit, keep their meaning in pixels of a typical match.
fn match_weights(pairs: &[(PixelPair, Option<f32>)], floor_px: Option<f32>) -> Vec<f64> {
    let weights: Vec<f64> = pairs
        .iter()
        .map(|(_, sigma)| match (sigma, floor_px) {
            (Some(s), Some(floor)) => 1.0 / f64::from(s.max(floor)).powi(2),
            _ => 1.0,
        })
        .collect();
    let mut sorted = weights.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(1.0);
    weights.iter().map(|w| w / median).collect()
}

/// How many of `octaves` fall in each octave: at least the fabric's maximum octave count long,
/// so frames line up, and longer if a frame carries a higher octave.
fn per_octave(octaves: impl Iterator<Item = u8>) -> Vec<usize> {
    let mut counts = vec![0; MAX_OCTAVES as usize];
    for o in octaves.map(usize::from) {
        if o >= counts.len() {
            counts.resize(o + 1, 0);
        }
        counts[o] += 1;
    }
    counts
}

/// Guided matches for the left keypoints that have no descriptor match, and for the grid
/// points when configured (see [`GuidedConfig`]): each searched where `homography` maps it
/// plus its neighbours' median parallax, and refined through `homography`'s local warp.
#[allow(clippy::too_many_arguments)]
fn guided_pairs(
    left: &FeatureFrame,
    matches: &[Match],
    pairs: &[(PixelPair, Option<f32>)],
    pl: &SobelPlane,
    pr: &SobelPlane,
    homography: &Matrix3<f64>,
    g: &GuidedConfig,
    sub: &SubpixelConfig,
) -> Vec<(PixelPair, Option<f32>)> {
    if pairs.len() < g.neighbours {
        return Vec::new();
    }
    let mut matched = vec![false; left.keypoints().len()];
    for m in matches {
        matched[m.left as usize] = true;
    }
    let max_d2 = g.max_neighbour_distance_px * g.max_neighbour_distance_px;
    let described: Vec<[f32; 2]> = pairs
        .iter()
        .map(|((l, _), _)| [l[0] as f32, l[1] as f32])
        .collect();
    // Each match's displacement beyond the rotation homography's: the parallax of its depth,
    // which neighbours share. The homography's own part changes with the position, near a
    // verged image's edge by up to a tenth of a pixel per pixel (the horizontal scale is 1/cos²
    // of the angle off the axis), which a neighbour up to `max_neighbour_distance_px` away
    // does not carry over.
    let parallax: Vec<[f32; 2]> = pairs
        .iter()
        .map(|((l, r), _)| {
            let at = map_point(homography, l[0] as f32, l[1] as f32);
            [r[0] as f32 - at[0], r[1] as f32 - at[1]]
        })
        .collect();
    // The search for the left point `p`; `near` is room for its neighbours.
    let search = |near: &mut Vec<(f32, usize)>, p: [f32; 2]| {
        near.clear();
        near.extend(pairs.iter().enumerate().filter_map(|(i, ((l, _), _))| {
            let d2 = (l[0] as f32 - p[0]).powi(2) + (l[1] as f32 - p[1]).powi(2);
            (d2 <= max_d2).then_some((d2, i))
        }));
        if near.len() < g.neighbours {
            return None;
        }
        near.select_nth_unstable_by(g.neighbours - 1, |a, b| a.0.total_cmp(&b.0));
        let median = |axis: usize| {
            let mut v: Vec<f32> = near[..g.neighbours]
                .iter()
                .map(|&(_, i)| parallax[i][axis])
                .collect();
            v.sort_by(f32::total_cmp);
            v[v.len() / 2]
        };
        let at = map_point(homography, p[0], p[1]);
        let guess = [at[0] + median(0), at[1] + median(1)];
        let warp = local_warp(homography, p[0], p[1]);
        guided_pair(pl, pr, p, guess, g.search_px, &warp, sub)
    };
    // Several keypoints (octaves) can sit on the same pixel: each location is used once.
    // Within a pixel in each direction (the snapped points' 3x3 neighbourhood), with half a
    // pixel to spare for a keypoint off the octave-0 grid: such points share nearly all of
    // their 15x15 windows, so they are one location.
    let one_location = |taken: &[[f32; 2]], p: [f32; 2]| near_any(taken, p, 1.5);
    // The searches are independent: both cores run them. Which of them a location already
    // taken by an earlier guided match rules out is settled afterwards, in keypoint order,
    // which gives the matches a one-by-one loop would.
    let found: Vec<([f32; 2], RefinedPair)> = left
        .keypoints()
        .par_iter()
        .enumerate()
        .filter(|&(k, kp)| !matched[k] && !one_location(&described, [kp.x, kp.y]))
        .map_init(
            || Vec::with_capacity(pairs.len()),
            |near, (_, kp)| search(near, [kp.x, kp.y]).map(|r| ([kp.x, kp.y], r)),
        )
        .flatten()
        .collect();
    let mut taken = Vec::new();
    let mut out = Vec::new();
    for (p, r) in found {
        if one_location(&taken, p) {
            continue;
        }
        taken.push(r.left);
        out.push(refined(r));
    }
    if let Some(cell) = g.grid_px.map(NonZeroU16::get) {
        // A point closer than half a cell to another has a window that overlaps the other's:
        // the grid's points keep to the spacing of its cells.
        let half_cell = f32::from(cell) / 2.0;
        let mut occupied = described;
        occupied.extend_from_slice(&taken);
        let found: Vec<RefinedPair> = grid_points(pl, usize::from(cell))
            .par_iter()
            .filter(|&&p| !near_any(&occupied, p, half_cell))
            .map_init(
                || Vec::with_capacity(pairs.len()),
                |near, &p| search(near, p),
            )
            .flatten()
            .collect();
        // A grid point's refined left point is the grid point itself (a whole pixel), which
        // the filter above kept clear of the matches: only the grid's own points can be near.
        let mut added = Vec::new();
        for r in found {
            if near_any(&added, r.left, half_cell) {
                continue;
            }
            added.push(r.left);
            out.push(refined(r));
        }
    }
    out
}

/// Whether a point of `taken` lies within `reach` of `p` in both directions.
fn near_any(taken: &[[f32; 2]], p: [f32; 2], reach: f32) -> bool {
    taken
        .iter()
        .any(|t| (t[0] - p[0]).abs() < reach && (t[1] - p[1]).abs() < reach)
}

/// The strongest pixel of every whole `cell` x `cell` cell of `plane` (the first in row order
/// among equals), in full-resolution pixels; cells with no gradient at all give none.
fn grid_points(plane: &SobelPlane, cell: usize) -> Vec<[f32; 2]> {
    let (w, h) = (plane.width() as usize, plane.height() as usize);
    let m = plane.magnitude();
    let mut points = Vec::new();
    for y0 in (0..h / cell).map(|i| i * cell) {
        for x0 in (0..w / cell).map(|i| i * cell) {
            let mut best = (0u8, 0, 0);
            for y in y0..y0 + cell {
                for (dx, &v) in m[y * w + x0..][..cell].iter().enumerate() {
                    if v > best.0 {
                        best = (v, x0 + dx, y);
                    }
                }
            }
            if best.0 > 0 {
                points.push([best.1 as f32, best.2 as f32]);
            }
        }
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calib::{CameraIntrinsics, Extrinsics};
    use crate::essential::rot_y;
    use crate::essential::testutil::synthetic;

    /// `n` exact matches of a head verged by `truth`, in the pixels of `calib`'s cameras
    /// (distortion applied), as the matcher would hand them over.
    fn pixel_matches(
        calib: &Calibration,
        truth: VergeAngles,
        n: usize,
        seed: u64,
    ) -> Vec<([f64; 2], [f64; 2])> {
        let (l, r) = (calib.left, calib.right);
        synthetic(
            rot_y(truth.alpha_l),
            rot_y(truth.alpha_r),
            calib.baseline_m,
            n,
            0.0,
            l.fx,
            seed,
        )
        .iter()
        .map(|c| {
            let (a, b) = l.project(c.left[0], c.left[1]);
            let (d, e) = r.project(c.right[0], c.right[1]);
            ([a, b], [d, e])
        })
        .collect()
    }

    #[test]
    fn pixel_pipeline_recovers_verge_with_distortion() {
        let cam = CameraIntrinsics {
            k1: -0.28,
            k2: 0.07,
            p1: 2e-4,
            p2: 2e-5,
            ..CameraIntrinsics::pinhole(458.0, 457.0, 367.0, 248.0)
        };
        let calib = Calibration {
            baseline_m: 0.11,
            left: cam,
            right: cam,
            extrinsics: Extrinsics::default(),
        };
        let truth = VergeAngles::new(1.2f64.to_radians(), -0.7f64.to_radians());
        let pairs = pixel_matches(&calib, truth, 600, 9);
        let est = VergeEstimator::new(calib, EstimatorConfig::default())
            .estimate_from_pixels(&pairs)
            .unwrap();
        assert!((est.verge_deg - 1.9).abs() < 1e-4, "{est:?}");
        let general = VergeEstimator::new(
            calib,
            EstimatorConfig {
                model: Model::General,
                ..EstimatorConfig::default()
            },
        )
        .estimate_from_pixels(&pairs)
        .unwrap();
        assert!((general.verge_deg - 1.9).abs() < 1e-3, "{general:?}");
        assert!(matches!(
            VergeEstimator::new(calib, EstimatorConfig::default())
                .estimate_from_pixels(&pairs[..5]),
            Err(EstimateError::TooFewMatches { got: 5, need: 12 })
        ));
    }

    /// The refinement starts from the linear SVD solve (thesis 4.5): on exact matches of a
    /// strongly verged head one Gauss-Newton step leaves that start where it is, on the
    /// truth, with or without RANSAC; one step from the parallel head would not get there.
    #[test]
    fn refinement_starts_from_the_linear_svd_solve() {
        let cam = CameraIntrinsics::pinhole(700.0, 700.0, 320.0, 240.0);
        let calib = Calibration {
            baseline_m: 0.3,
            left: cam,
            right: cam,
            extrinsics: Extrinsics::default(),
        };
        let truth = VergeAngles::new(9f64.to_radians(), -6f64.to_radians());
        let pairs = pixel_matches(&calib, truth, 200, 4);
        let one_step = RefineConfig {
            max_iterations: 1,
            ..RefineConfig::default()
        };
        for ransac in [Some(RansacConfig::default()), None] {
            let config = EstimatorConfig {
                ransac,
                refine: one_step,
                ..EstimatorConfig::default()
            };
            let est = VergeEstimator::new(calib, config)
                .estimate_from_pixels(&pairs)
                .unwrap();
            assert!((est.verge_deg - 15.0).abs() < 1e-6, "{ransac:?}: {est:?}");
        }
        let from_parallel = constrained::refine(
            &pairs
                .iter()
                .map(|(l, r)| Correspondence::from_pixels(&calib, *l, *r))
                .collect::<Vec<_>>(),
            VergeAngles::new(0.0, 0.0),
            &one_step,
        )
        .unwrap();
        assert!((from_parallel.angles.verge_deg() - 15.0).abs() > 1e-3);
    }

    #[test]
    fn grid_points_are_each_whole_cells_strongest_pixel() {
        // A 10x7 plane in 4x4 cells: two whole cells across, one down (the last columns and
        // rows make no whole cell).
        let mut mag = vec![0u8; 70];
        mag[10 + 2] = 9; // cell (0, 0): (2, 1)
        mag[30 + 1] = 9; // the same cell, as strong but later in row order
        mag[20 + 5] = 3; // cell (1, 0): (5, 2)
        mag[60 + 9] = 200; // outside every whole cell
        let plane = SobelPlane::new(0, 10, 7, mag, vec![0; 70]).unwrap();
        assert_eq!(grid_points(&plane, 4), vec![[2.0, 1.0], [5.0, 2.0]]);
        // A cell without gradient gives no point.
        let flat = SobelPlane::new(0, 8, 4, vec![0; 32], vec![0; 32]).unwrap();
        assert!(grid_points(&flat, 4).is_empty());
    }
}
