//! The constrained model with the head's fixed misalignments: both cameras yaw per frame
//! (`alpha_l`, `alpha_r`), and the right camera also carries a constant pitch and roll and the
//! baseline a constant tilt.
//!
//! Geometry (`docs/ARCHITECTURE.md`, "Frames and signs"): the left camera has orientation
//! `Ry(a_l)`, the right one `R_r = Ry(a_r) Rx(pitch) Rz(roll)`, and the right camera's centre
//! sits in the head frame along `t = (cos tilt, sin tilt, 0)`. Then `R_01 = Ry(-verge)
//! Rx(pitch) Rz(roll)` and the centre's direction in the left camera's frame is that of
//! [`Extrinsics`], so a calibration's extrinsics are exactly a point of this model, and
//! `E = R_rᵀ [t]ₓ Ry(a_l)` with `x_rᵀ E x_l = 0`. With the three misalignments zero it is the
//! thesis' model ([`super::constrained`]).

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};

use super::constrained::{VergeAngles, YAW_MIN_MATCHES};
use super::{mad_sigma, rot_x, rot_y, rot_z, skew, Correspondence, EssentialError, RefineConfig};
use crate::calib::Extrinsics;

/// The head's fixed misalignments, radians: the right camera's pitch and roll (the `Rx` and
/// `Rz` angles of `R_01`) and the baseline's elevation, positive when the right camera sits
/// lower (+y).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Misalignment {
    /// The right camera's pitch, the `Rx` angle of `R_01`.
    pub pitch: f64,
    /// The right camera's roll, the `Rz` angle of `R_01`.
    pub roll: f64,
    /// The baseline's elevation, positive when the right camera sits lower (+y).
    pub tilt: f64,
}

impl Misalignment {
    /// The misalignments a calibration measured (zero for a rectified pair).
    pub fn from_extrinsics(e: &Extrinsics) -> Self {
        Self {
            pitch: e.pitch_deg.to_radians(),
            roll: e.roll_deg.to_radians(),
            tilt: e.baseline_tilt_deg.to_radians(),
        }
    }

    /// As a vector `(pitch, roll, tilt)`, the order of the shared block of the joint fit.
    pub fn to_vector(self) -> Vector3<f64> {
        Vector3::new(self.pitch, self.roll, self.tilt)
    }

    /// From a vector `(pitch, roll, tilt)`, the inverse of [`Self::to_vector`].
    pub(crate) fn from_vector(v: &Vector3<f64>) -> Self {
        Self {
            pitch: v[0],
            roll: v[1],
            tilt: v[2],
        }
    }
}

/// Derivative of [`rot_y`] (and of `rot_x`, `rot_z`) with respect to its angle.
fn d_rot_y(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(-s, 0.0, c, 0.0, 0.0, 0.0, -c, 0.0, -s)
}

fn d_rot_x(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(0.0, 0.0, 0.0, 0.0, -s, -c, 0.0, c, -s)
}

fn d_rot_z(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(-s, -c, 0.0, c, -s, 0.0, 0.0, 0.0, 0.0)
}

/// The essential matrix of yaws `a` on a head misaligned by `m`, and its derivatives along
/// `(alpha_l, alpha_r, pitch, roll, tilt)`.
pub fn essential_and_derivatives(
    a: VergeAngles,
    m: &Misalignment,
) -> (Matrix3<f64>, [Matrix3<f64>; 5]) {
    let (ry_r, rx, rz) = (rot_y(a.alpha_r), rot_x(m.pitch), rot_z(m.roll));
    let r_l = rot_y(a.alpha_l);
    let (st, ct) = m.tilt.sin_cos();
    let tx = skew(&Vector3::new(ct, st, 0.0));
    let dtx = skew(&Vector3::new(-st, ct, 0.0));
    let r_r = ry_r * rx * rz;
    let tail = tx * r_l;
    let e = r_r.transpose() * tail;
    let de = [
        r_r.transpose() * tx * d_rot_y(a.alpha_l),
        (d_rot_y(a.alpha_r) * rx * rz).transpose() * tail,
        (ry_r * d_rot_x(m.pitch) * rz).transpose() * tail,
        (ry_r * rx * d_rot_z(m.roll)).transpose() * tail,
        r_r.transpose() * dtx * r_l,
    ];
    (e, de)
}

/// Sampson residual of `c` under `e` and its derivatives along the directions `de` of E.
#[inline]
pub fn residual_and_gradient<const K: usize>(
    e: &Matrix3<f64>,
    de: &[Matrix3<f64>; K],
    c: &Correspondence,
) -> Option<(f64, [f64; K])> {
    let xl = c.left_h();
    let xr = c.right_h();
    let ex = e * xl;
    let etx = e.tr_mul(&xr);
    let n = xr.dot(&ex);
    let d = ex[0] * ex[0] + ex[1] * ex[1] + etx[0] * etx[0] + etx[1] * etx[1];
    if d <= 0.0 {
        return None;
    }
    let sd = d.sqrt();
    let g = std::array::from_fn(|k| {
        let dex = de[k] * xl;
        let detx = de[k].tr_mul(&xr);
        let dn = xr.dot(&dex);
        let dd = 2.0 * (ex[0] * dex[0] + ex[1] * dex[1] + etx[0] * detx[0] + etx[1] * detx[1]);
        dn / sd - 0.5 * n * dd / (d * sd)
    });
    Some((n / sd, g))
}

/// The yaws of one frame refined with the misalignments held.
#[derive(Debug, Clone, PartialEq)]
pub struct YawFit {
    /// The refined yaws of both cameras.
    pub angles: VergeAngles,
    /// Standard deviation of the verge from the Gauss-Newton covariance, radians; it treats
    /// the misalignments as known.
    pub verge_sigma: f64,
    /// Robust noise scale of the Sampson residuals (calibrated units).
    pub residual_sigma: f64,
}

/// Robust Gauss-Newton (IRLS, `config.loss`) refinement of one frame's two yaws from `init`
/// with the misalignments `m` held: the frame's verge once the window knows the head's
/// fixed errors.
pub fn refine_yaws(
    matches: &[Correspondence],
    init: VergeAngles,
    m: &Misalignment,
    config: &RefineConfig,
) -> Result<YawFit, EssentialError> {
    let fit = refine_frame::<2>(matches, init, m, None, config)?;
    let cov = fit.covariance()?;
    let verge_var = cov[(0, 0)] + cov[(1, 1)] - 2.0 * cov[(0, 1)];
    Ok(YawFit {
        angles: fit.angles,
        verge_sigma: verge_var.max(0.0).sqrt(),
        residual_sigma: fit.sigma,
    })
}

/// Where a frame's own pitch is held when it is refined with its yaws: a normal prior of
/// this centre and variance (radians, radians²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PitchPrior {
    /// The pitch the frames share.
    pub centre: f64,
    /// How far the frames' pitches spread about it, as a variance; positive (a prior of no
    /// variance leaves the refinement [`EssentialError::Degenerate`]).
    pub variance: f64,
}

/// One frame's yaws and its own pitch refined with the roll and tilt held.
#[derive(Debug, Clone, PartialEq)]
pub struct PitchFit {
    /// The refined yaws of both cameras.
    pub angles: VergeAngles,
    /// The frame's pitch (radians).
    pub pitch: f64,
    /// Its variance from the Gauss-Newton covariance (radians²), the prior's part included.
    pub pitch_variance: f64,
}

/// Robust Gauss-Newton refinement of one frame's yaws and its own pitch from `init` and
/// `m`'s pitch, with `m`'s roll and tilt held and, when given, `prior` on the pitch.
pub fn refine_yaws_and_pitch(
    matches: &[Correspondence],
    init: VergeAngles,
    m: &Misalignment,
    prior: Option<PitchPrior>,
    config: &RefineConfig,
) -> Result<PitchFit, EssentialError> {
    let fit = refine_frame::<3>(matches, init, m, prior, config)?;
    let cov = fit.covariance()?;
    Ok(PitchFit {
        angles: fit.angles,
        pitch: fit.pitch,
        pitch_variance: cov[(2, 2)].max(0.0),
    })
}

/// A frame's refinement: its yaws, its pitch, the information matrix of the `K` refined
/// parameters in units of the residuals' robust scale, and that scale.
struct FrameFit<const K: usize> {
    angles: VergeAngles,
    pitch: f64,
    information: SMatrix<f64, K, K>,
    sigma: f64,
}

impl<const K: usize> FrameFit<K> {
    /// The refined parameters' covariance (radians²).
    fn covariance(&self) -> Result<SMatrix<f64, K, K>, EssentialError> {
        let inv = self
            .information
            .try_inverse()
            .ok_or(EssentialError::Degenerate)?;
        Ok(inv * self.sigma * self.sigma)
    }
}

/// Robust Gauss-Newton (IRLS) over the first `K` of `(alpha_l, alpha_r, pitch)`, the rest of
/// `m` held; `prior` adds its normal term on the pitch when the pitch is refined (`K` = 3).
fn refine_frame<const K: usize>(
    matches: &[Correspondence],
    init: VergeAngles,
    m: &Misalignment,
    prior: Option<PitchPrior>,
    config: &RefineConfig,
) -> Result<FrameFit<K>, EssentialError> {
    if matches.len() < YAW_MIN_MATCHES {
        return Err(EssentialError::TooFewMatches {
            got: matches.len(),
            need: YAW_MIN_MATCHES,
        });
    }
    let mut angles = init;
    let mut m = *m;
    let mut residuals = vec![0.0; matches.len()];
    let mut jac = vec![SVector::<f64, K>::zeros(); matches.len()];
    let mut sigma = config.min_sigma;
    let mut info = SMatrix::<f64, K, K>::zeros();
    for _ in 0..config.max_iterations.max(1) {
        let (e, de_all) = essential_and_derivatives(angles, &m);
        let de: [Matrix3<f64>; K] = std::array::from_fn(|i| de_all[i]);
        for (i, c) in matches.iter().enumerate() {
            let (r, g) = residual_and_gradient(&e, &de, c).unwrap_or((0.0, [0.0; K]));
            let s = c.weight.sqrt();
            residuals[i] = r * s;
            jac[i] = SVector::<f64, K>::from(g) * s;
        }
        sigma = mad_sigma(&residuals, config.min_sigma);
        let mut h = SMatrix::<f64, K, K>::zeros();
        let mut b = SVector::<f64, K>::zeros();
        for (r, g) in residuals.iter().zip(&jac) {
            let w = config.loss.weight(*r, sigma);
            h += w * g * g.transpose();
            b += w * g * *r;
        }
        if let (Some(p), true) = (prior, K == 3) {
            // The prior's cost (pitch - centre)² / variance, in the units of `h`, whose
            // inverse times σ² is the covariance.
            let lambda = sigma * sigma / p.variance;
            h[(2, 2)] += lambda;
            b[2] += lambda * (m.pitch - p.centre);
        }
        info = h;
        let step = h
            .try_inverse()
            .map(|hi| -(hi * b))
            .ok_or(EssentialError::Degenerate)?;
        angles.alpha_l += step[0];
        angles.alpha_r += step[1];
        if K == 3 {
            m.pitch += step[2];
        }
        if !(angles.alpha_l.is_finite() && angles.alpha_r.is_finite() && m.pitch.is_finite()) {
            return Err(EssentialError::Degenerate);
        }
        // 1e-10 rad is 6e-9°, as in the constrained refinement.
        if step.norm() < 1e-10 {
            break;
        }
    }
    Ok(FrameFit {
        angles,
        pitch: m.pitch,
        information: info,
        sigma,
    })
}

#[cfg(test)]
mod tests {
    use super::super::testutil::misaligned_synthetic as misaligned_matches;
    use super::super::{constrained, sampson_residual};
    use super::*;

    fn head(a: VergeAngles, m: &Misalignment) -> (Matrix3<f64>, Matrix3<f64>, f64) {
        (
            rot_y(a.alpha_l),
            rot_y(a.alpha_r) * rot_x(m.pitch) * rot_z(m.roll),
            m.tilt,
        )
    }

    #[test]
    fn zero_misalignment_is_the_constrained_model() {
        let a = VergeAngles::new(0.03, -0.01);
        let (e, de) = essential_and_derivatives(a, &Misalignment::default());
        assert!((e - a.essential()).norm() < 1e-15);
        assert!(de.iter().all(|d| d.iter().all(|v| v.is_finite())));
    }

    #[test]
    fn the_model_explains_a_misaligned_head_and_its_calibration() {
        let a = VergeAngles::new(0.02, -0.01);
        let m = Misalignment {
            pitch: 0.004,
            roll: -0.003,
            tilt: 0.002,
        };
        let (e, _) = essential_and_derivatives(a, &m);
        for c in misaligned_matches(a, &m, 50, 0.0, 500.0, 3) {
            assert!(sampson_residual(&e, &c).abs() < 1e-12);
        }
        // The calibration tool's R, T of that head give back the same misalignment.
        let (rl, rr, _) = head(a, &m);
        let t = Vector3::new(m.tilt.cos(), m.tilt.sin(), 0.0) * 0.3;
        let (r, tr) = (rr.transpose() * rl, -(rr.transpose() * t));
        let (x, _) = Extrinsics::from_rotation_translation(&r, &tr).unwrap();
        let back = Misalignment::from_extrinsics(&x);
        assert!(
            (back.to_vector() - m.to_vector()).norm() < 1e-12,
            "{back:?}"
        );
    }

    #[test]
    fn derivatives_match_central_differences() {
        let a = VergeAngles::new(0.04, -0.02);
        let m = Misalignment {
            pitch: 0.01,
            roll: -0.02,
            tilt: 0.005,
        };
        let (e, de) = essential_and_derivatives(a, &m);
        let h = 1e-6;
        let at = |k: usize, s: f64| {
            let mut p = [a.alpha_l, a.alpha_r, m.pitch, m.roll, m.tilt];
            p[k] += s;
            let mm = Misalignment {
                pitch: p[2],
                roll: p[3],
                tilt: p[4],
            };
            essential_and_derivatives(VergeAngles::new(p[0], p[1]), &mm).0
        };
        let c = misaligned_matches(a, &m, 5, 1.0, 500.0, 1);
        for k in 0..5 {
            let num = (at(k, h) - at(k, -h)) / (2.0 * h);
            assert!((num - de[k]).norm() < 1e-8, "{k}");
            let (_, g) = residual_and_gradient(&e, &de, &c[0]).unwrap();
            let rn = (sampson_residual(&at(k, h), &c[0]) - sampson_residual(&at(k, -h), &c[0]))
                / (2.0 * h);
            assert!((g[k] - rn).abs() < 1e-7, "{k}: {} vs {rn}", g[k]);
        }
    }

    /// A head at yaws 1° and -0.5° whose right camera pitches by 0.3° and rolls by 0.2°, and
    /// 500 of its matches (0.1 px noise at f = 700 px).
    fn pitched_and_rolled() -> (VergeAngles, Misalignment, Vec<Correspondence>) {
        let a = VergeAngles::new(1.0f64.to_radians(), -0.5f64.to_radians());
        let m = Misalignment {
            pitch: 0.3f64.to_radians(),
            roll: 0.2f64.to_radians(),
            tilt: 0.0,
        };
        (a, m, misaligned_matches(a, &m, 500, 0.1, 700.0, 5))
    }

    /// With the true misalignment held, the yaw refit recovers the verge the thesis' model
    /// bends by the pitch and roll.
    #[test]
    fn held_misalignment_unbends_the_verge() {
        let (a, m, c) = pitched_and_rolled();
        let cfg = RefineConfig::default();
        let plain = constrained::refine(&c, a, &cfg).unwrap();
        let held = refine_yaws(&c, plain.angles, &m, &cfg).unwrap();
        let (ep, eh) = (
            (plain.angles.verge() - a.verge()).to_degrees().abs(),
            (held.angles.verge() - a.verge()).to_degrees().abs(),
        );
        assert!(eh < 0.01 && eh < 0.2 * ep, "held {eh}° vs plain {ep}°");
    }

    /// With the pitch free the refit finds the frame's own pitch and its verge from the roll
    /// alone; a prior pulls the pitch towards its centre as far as its variance lets it, and
    /// a prior of no variance is refused.
    #[test]
    fn a_frame_s_own_pitch_is_refined_with_its_yaws() {
        let (a, m, c) = pitched_and_rolled();
        let cfg = RefineConfig::default();
        let start = constrained::refine(&c, a, &cfg).unwrap().angles;
        let roll_only = Misalignment { pitch: 0.0, ..m };
        let free = refine_yaws_and_pitch(&c, start, &roll_only, None, &cfg).unwrap();
        assert!((free.pitch.to_degrees() - 0.3).abs() < 0.01, "{free:?}");
        assert!(
            (free.angles.verge() - a.verge()).to_degrees().abs() < 0.01,
            "{free:?}"
        );
        // A prior four of the fit's σ away.
        let sd = free.pitch_variance.sqrt();
        let centre = free.pitch - 4.0 * sd;
        let held = |variance: f64| {
            let prior = PitchPrior { centre, variance };
            refine_yaws_and_pitch(&c, start, &roll_only, Some(prior), &cfg)
        };
        // As sure as the fit, it meets it half way.
        let half = held(free.pitch_variance).unwrap();
        assert!(
            ((free.pitch - half.pitch) / sd - 2.0).abs() < 0.3,
            "{half:?}, σ {sd}"
        );
        // Far surer than the fit, it holds the pitch at its centre.
        let pinned = held(1e-6 * free.pitch_variance).unwrap();
        assert!(
            (pinned.pitch - centre).abs() < 0.01 * sd,
            "{pinned:?}, σ {sd}"
        );
        assert!(matches!(held(0.0), Err(EssentialError::Degenerate)));
    }
}
