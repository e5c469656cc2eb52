//! The general 5-DOF model for heads that also tilt or roll: a free relative rotation (3 DOF)
//! and a free baseline direction (2 DOF), refined robustly on the Sampson error.
//!
//! The constrained model explains a relative pitch or roll only by bending the verge angle;
//! this model absorbs them, at the cost of three more unknowns (more noise per frame).

use nalgebra::{Matrix3, Rotation3, SMatrix, SVector, Unit, Vector3};

use super::constrained::VergeAngles;
use super::{
    mad_sigma, rot_y, sampson_residual, skew, Correspondence, EssentialError, RefineConfig,
};
use crate::calib::Extrinsics;

/// Relative pose of the right camera with respect to the left one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelativePose {
    /// Maps left-camera coordinates of a direction to right-camera coordinates.
    pub rotation: Rotation3<f64>,
    /// Baseline direction (left → right camera centre) in right-camera coordinates.
    pub baseline: Unit<Vector3<f64>>,
}

/// Yaw, pitch and roll (radians) of `R_01 = Ry(yaw) Rx(pitch) Rz(roll)`, the orientation of
/// the right camera in the left camera's frame (the convention of the real data sets'
/// `geometry.json`: `docs/ARCHITECTURE.md`, "Real data").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct YawPitchRoll {
    /// Rotation about y; `-yaw` is the verge, toe-in positive.
    pub yaw: f64,
    /// Rotation about x, applied after roll.
    pub pitch: f64,
    /// Rotation about z (the optical axis), applied first.
    pub roll: f64,
}

impl RelativePose {
    /// The pose of a head that only verges.
    pub fn from_verge(a: VergeAngles) -> Self {
        let r = rot_y(a.alpha_r).transpose() * rot_y(a.alpha_l);
        let t = rot_y(a.alpha_r).transpose() * Vector3::x();
        Self {
            rotation: Rotation3::from_matrix_unchecked(r),
            baseline: Unit::new_normalize(t),
        }
    }

    /// A pose from `R_01` angles and the right camera centre direction in the left frame.
    pub fn from_r01(ypr: YawPitchRoll, centre_in_left: Vector3<f64>) -> Self {
        let r01 = rot_y(ypr.yaw) * super::rot_x(ypr.pitch) * super::rot_z(ypr.roll);
        let r = r01.transpose();
        Self {
            rotation: Rotation3::from_matrix_unchecked(r),
            baseline: Unit::new_normalize(r * centre_in_left),
        }
    }

    /// The pose the calibration describes. A head that only verges (no pitch, roll or baseline
    /// tilt) takes the yaw-only form, so a rectified pair starts exactly where it always did.
    pub fn from_extrinsics(e: &Extrinsics) -> Self {
        if e.pitch_deg == 0.0 && e.roll_deg == 0.0 && e.baseline_tilt_deg == 0.0 {
            return Self::from_verge(VergeAngles::from_extrinsics(e));
        }
        let ypr = YawPitchRoll {
            yaw: -e.verge_deg.to_radians(),
            pitch: e.pitch_deg.to_radians(),
            roll: e.roll_deg.to_radians(),
        };
        Self::from_r01(ypr, e.centre_direction())
    }

    /// `E = [t_r]ₓ R` with `x_rᵀ E x_l = 0`.
    pub fn essential(&self) -> Matrix3<f64> {
        skew(self.baseline.as_ref()) * self.rotation.matrix()
    }

    /// Decomposes `R_01 = Rᵀ`.
    pub fn yaw_pitch_roll(&self) -> YawPitchRoll {
        let r01 = self.rotation.matrix().transpose();
        YawPitchRoll {
            yaw: r01[(0, 2)].atan2(r01[(2, 2)]),
            pitch: (-r01[(1, 2)]).clamp(-1.0, 1.0).asin(),
            roll: r01[(1, 0)].atan2(r01[(1, 1)]),
        }
    }

    /// The yaws of the verge head nearest this pose: the left one is the azimuth of the right
    /// camera's centre in the left camera's frame (the constrained model's `alpha_l`, see
    /// [`Extrinsics`]), the right one that less the verge.
    pub fn yaws(&self) -> VergeAngles {
        let centre = self.rotation.inverse() * self.baseline.as_ref();
        let alpha_l = centre.z.atan2(centre.x);
        VergeAngles::new(alpha_l, alpha_l - self.verge())
    }

    /// The verge angle (radians, toe-in positive) = `-yaw` of `R_01`.
    pub fn verge(&self) -> f64 {
        -self.yaw_pitch_roll().yaw
    }

    /// Applies a 5-vector update: rotation increment ω (left-multiplied) and a tangent step of
    /// the baseline direction.
    fn updated(&self, d: &SVector<f64, 5>) -> Self {
        let (b1, b2) = tangent_basis(&self.baseline);
        let rotation = Rotation3::new(Vector3::new(d[0], d[1], d[2])) * self.rotation;
        let t = self.baseline.as_ref() + b1 * d[3] + b2 * d[4];
        Self {
            rotation,
            baseline: Unit::new_normalize(t),
        }
    }
}

fn tangent_basis(t: &Unit<Vector3<f64>>) -> (Vector3<f64>, Vector3<f64>) {
    // Any helper far from parallel to `t` will do: with |t_y| < 0.9 the cross product with y
    // keeps at least sin(acos 0.9) ≈ 0.44 of unit length. A head's baseline lies near x, so y
    // is the helper but for baselines that point almost straight up or down.
    let helper = if t[1].abs() < 0.9 {
        Vector3::y()
    } else {
        Vector3::x()
    };
    let b1 = t.cross(&helper).normalize();
    let b2 = t.cross(&b1);
    (b1, b2)
}

/// The result of the general refinement.
#[derive(Debug, Clone, PartialEq)]
pub struct GeneralFit {
    /// The refined relative pose.
    pub pose: RelativePose,
    /// Standard deviation of the verge angle from the Gauss-Newton covariance (radians).
    pub verge_sigma: f64,
    /// Robust noise scale of the Sampson residuals (calibrated units).
    pub residual_sigma: f64,
    /// Per match: weighted |Sampson residual| below `inlier_sigmas`·σ.
    pub inliers: Vec<bool>,
    /// Gauss-Newton iterations run.
    pub iterations: usize,
}

impl GeneralFit {
    /// Matches counted as inliers.
    pub fn inlier_count(&self) -> usize {
        self.inliers.iter().filter(|&&b| b).count()
    }
}

/// Minimum matches for 5 unknowns.
pub const GENERAL_MIN_MATCHES: usize = 5;

/// Central-difference step of the Jacobians (radians, in the tangent space of the pose). E's
/// entries are of unit scale, so the derivatives' rounding error is about ε/STEP ≈ 2e-9 of
/// their size and the truncation error about STEP² = 1e-14: both far below what a
/// Gauss-Newton step or the covariance needs (the optimum, ε^(1/3) ≈ 6e-6, gains nothing
/// that matters). A step ten times smaller or larger moves the general model's median errors
/// on the rendered road and the KITTI drive by < 0.00001° (README, "Sensitivity of the
/// constants").
const STEP: f64 = 1e-7;

/// Robust Gauss-Newton (IRLS) refinement of the 5-DOF pose from `init` (typically the
/// constrained estimate); Jacobians by central differences on the manifold.
pub fn refine(
    matches: &[Correspondence],
    init: RelativePose,
    config: &RefineConfig,
) -> Result<GeneralFit, EssentialError> {
    if matches.len() < GENERAL_MIN_MATCHES {
        return Err(EssentialError::TooFewMatches {
            got: matches.len(),
            need: GENERAL_MIN_MATCHES,
        });
    }
    let mut pose = init;
    let mut sigma = config.min_sigma;
    let mut info = SMatrix::<f64, 5, 5>::zeros();
    let mut iterations = 0;
    let mut residuals = vec![0.0; matches.len()];
    for it in 0..config.max_iterations.max(1) {
        iterations = it + 1;
        let e = pose.essential();
        let de: [Matrix3<f64>; 5] = std::array::from_fn(|k| {
            let mut d = SVector::<f64, 5>::zeros();
            d[k] = STEP;
            let plus = pose.updated(&d).essential();
            d[k] = -STEP;
            let minus = pose.updated(&d).essential();
            (plus - minus) / (2.0 * STEP)
        });
        for (r, c) in residuals.iter_mut().zip(matches) {
            *r = sampson_residual(&e, c) * c.weight.sqrt();
        }
        sigma = mad_sigma(&residuals, config.min_sigma);
        let mut h = SMatrix::<f64, 5, 5>::zeros();
        let mut b = SVector::<f64, 5>::zeros();
        for (c, r) in matches.iter().zip(&residuals) {
            // The Sampson residual is linear in E to first order: differentiate through E.
            let g = SVector::<f64, 5>::from_fn(|k, _| sampson_derivative(&e, &de[k], c))
                * c.weight.sqrt();
            let w = config.loss.weight(*r, sigma);
            h += w * g * g.transpose();
            b += w * g * *r;
        }
        info = h;
        let step = h
            .try_inverse()
            .map(|hi| -(hi * b))
            .ok_or(EssentialError::Degenerate)?;
        pose = pose.updated(&step);
        if !step.iter().all(|v| v.is_finite()) {
            return Err(EssentialError::Degenerate);
        }
        // 1e-12 rad is 6e-11°, far below any accuracy that matters, and still thousands of
        // times f64's rounding (ε ≈ 2.2e-16) of the unit-scale angles and direction it updates.
        // 1e-13 or 1e-10 moves the general model's median errors on the rendered road and the
        // KITTI drive by < 0.00001°.
        if step.norm() < 1e-12 {
            break;
        }
    }
    let cov = info.try_inverse().ok_or(EssentialError::Degenerate)? * sigma * sigma;
    let grad = SVector::<f64, 5>::from_fn(|k, _| {
        let mut d = SVector::<f64, 5>::zeros();
        d[k] = STEP;
        let plus = pose.updated(&d).verge();
        d[k] = -STEP;
        let minus = pose.updated(&d).verge();
        (plus - minus) / (2.0 * STEP)
    });
    let verge_var = (grad.transpose() * cov * grad)[(0, 0)];
    let e = pose.essential();
    let limit = config.inlier_sigmas * sigma;
    let inliers = matches
        .iter()
        .map(|c| sampson_residual(&e, c).abs() * c.weight.sqrt() < limit)
        .collect();
    Ok(GeneralFit {
        pose,
        verge_sigma: verge_var.max(0.0).sqrt(),
        residual_sigma: sigma,
        inliers,
        iterations,
    })
}

/// Derivative of the Sampson residual of `c` along the direction `de` of E.
fn sampson_derivative(e: &Matrix3<f64>, de: &Matrix3<f64>, c: &Correspondence) -> f64 {
    let xl = c.left_h();
    let xr = c.right_h();
    let ex = e * xl;
    let etx = e.transpose() * xr;
    let n = xr.dot(&ex);
    let d = ex[0] * ex[0] + ex[1] * ex[1] + etx[0] * etx[0] + etx[1] * etx[1];
    if d <= 0.0 {
        return 0.0;
    }
    let dex = de * xl;
    let detx = de.transpose() * xr;
    let dn = xr.dot(&dex);
    let dd = 2.0 * (ex[0] * dex[0] + ex[1] * dex[1] + etx[0] * detx[0] + etx[1] * detx[1]);
    let sd = d.sqrt();
    dn / sd - 0.5 * n * dd / (d * sd)
}

#[cfg(test)]
mod tests {
    use super::super::constrained;
    use super::super::testutil::synthetic;
    use super::*;

    #[test]
    fn verge_pose_matches_the_constrained_essential() {
        let a = VergeAngles::new(0.05, -0.02);
        let p = RelativePose::from_verge(a);
        let back = p.yaws();
        assert!(
            (back.alpha_l - a.alpha_l).abs() < 1e-14 && (back.alpha_r - a.alpha_r).abs() < 1e-14
        );
        assert!((p.essential() - a.essential()).norm() < 1e-14);
        assert!((p.verge() - a.verge()).abs() < 1e-14);
        let ypr = p.yaw_pitch_roll();
        assert!(ypr.pitch.abs() < 1e-15 && ypr.roll.abs() < 1e-15);
    }

    /// The pose a calibration tool's R, T describe (`x_r = R x_l + T`) must explain the
    /// matches of that head exactly, whatever its verge, misalignments and baseline tilt.
    #[test]
    fn the_calibrated_pose_explains_its_head() {
        use super::super::{rot_x, rot_z, sampson_residual};
        let r_left = rot_y(0.01) * rot_x(0.004);
        let r01 = rot_y(-0.03) * rot_x(0.006) * rot_z(-0.002);
        let r_right = r_left * r01;
        let t = Vector3::new(0.11, 0.0, 0.0);
        let (r, tr) = (r_right.transpose() * r_left, -(r_right.transpose() * t));
        let (e, b) = crate::calib::Extrinsics::from_rotation_translation(&r, &tr).unwrap();
        assert!((b - 0.11).abs() < 1e-15);
        let pose = RelativePose::from_extrinsics(&e);
        assert!((pose.verge() - 0.03).abs() < 1e-12, "{}", pose.verge());
        let essential = pose.essential();
        for c in synthetic(r_left, r_right, 0.11, 50, 0.0, 500.0, 5) {
            let res = sampson_residual(&essential, &c);
            assert!(res.abs() < 1e-12, "{res}");
        }
        // A rectified calibration starts from the parallel head, to the bit.
        let parallel = RelativePose::from_extrinsics(&crate::calib::Extrinsics::default());
        assert_eq!(
            parallel,
            RelativePose::from_verge(VergeAngles::new(0.0, 0.0))
        );
    }

    #[test]
    fn general_model_beats_constrained_when_the_head_tilts() {
        // Right camera: yaw -0.5° (verge +0.5° with a straight left camera), pitch 0.8°,
        // roll 0.13° - the EuRoC rig's kind of misalignment.
        let f = 460.0;
        let r01 = rot_y(-0.5f64.to_radians())
            * super::super::rot_x(0.8f64.to_radians())
            * super::super::rot_z(0.13f64.to_radians());
        let m = synthetic(Matrix3::identity(), r01, 0.11, 1000, 0.05, f, 3);
        let init = crate::ransac::ransac(&m, &crate::ransac::RansacConfig::default()).unwrap();
        let cfit = constrained::refine(&m, init.angles, &RefineConfig::default()).unwrap();
        let gfit = refine(
            &m,
            RelativePose::from_verge(cfit.angles),
            &RefineConfig::default(),
        )
        .unwrap();
        let ypr = gfit.pose.yaw_pitch_roll();
        let g_err = (gfit.pose.verge().to_degrees() - 0.5).abs();
        let c_err = (cfit.angles.verge_deg() - 0.5).abs();
        assert!(g_err < 0.02, "general verge error {g_err}°");
        assert!((ypr.pitch.to_degrees() - 0.8).abs() < 0.02, "{ypr:?}");
        assert!((ypr.roll.to_degrees() - 0.13).abs() < 0.02, "{ypr:?}");
        assert!(g_err < c_err, "general {g_err}° vs constrained {c_err}°");
    }

    #[test]
    fn from_r01_reproduces_its_angles() {
        let ypr = YawPitchRoll {
            yaw: -0.01,
            pitch: 0.014,
            roll: 0.002,
        };
        let p = RelativePose::from_r01(ypr, Vector3::new(0.11, 0.0, 0.001));
        let back = p.yaw_pitch_roll();
        assert!((back.yaw - ypr.yaw).abs() < 1e-12);
        assert!((back.pitch - ypr.pitch).abs() < 1e-12);
        assert!((back.roll - ypr.roll).abs() < 1e-12);
    }
}
