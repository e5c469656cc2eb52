//! The thesis' constrained model: both cameras only yaw, `E = [[0,e1,0],[e2,0,e4],[0,e3,0]]`.
//!
//! Pipeline: a linear least-squares solve of the four unknowns (null vector by SVD), the
//! rank-2 / equal-singular-value projection, the sign (180°) ambiguity resolved from U, then a
//! robust Gauss-Newton refinement of the two angles on the Sampson error over all matches.

use nalgebra::{Matrix2, Matrix3, Matrix4, Vector2, Vector3};

use super::{mad_sigma, Correspondence, EssentialError, RefineConfig};
use crate::calib::Extrinsics;

/// The two camera yaws of a verging head, in radians (signs: `docs/ARCHITECTURE.md`, "Frames
/// and signs").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VergeAngles {
    /// Yaw of the left camera; positive turns it toward the right camera.
    pub alpha_l: f64,
    /// Yaw of the right camera; positive turns it away from the left camera.
    pub alpha_r: f64,
}

impl VergeAngles {
    /// The yaws `alpha_l` and `alpha_r`, in radians.
    pub fn new(alpha_l: f64, alpha_r: f64) -> Self {
        Self { alpha_l, alpha_r }
    }

    /// `alpha_l - alpha_r` in radians: toe-in positive.
    pub fn verge(&self) -> f64 {
        self.alpha_l - self.alpha_r
    }

    /// The yaws of the head the calibration describes (a rectified pair: both zero). Its
    /// pitch, roll and baseline tilt are beyond this model.
    pub fn from_extrinsics(e: &Extrinsics) -> Self {
        let alpha_l = e.left_yaw_deg.to_radians();
        Self::new(alpha_l, alpha_l - e.verge_deg.to_radians())
    }

    /// The verge angle in degrees.
    pub fn verge_deg(&self) -> f64 {
        self.verge().to_degrees()
    }

    /// The unknowns `[e1, e2, e3, e4]` (unit baseline).
    pub fn unknowns(&self) -> [f64; 4] {
        let (sl, cl) = self.alpha_l.sin_cos();
        let (sr, cr) = self.alpha_r.sin_cos();
        [-sr, sl, cr, -cl]
    }

    /// `E = Ry(a_r)ᵀ [x]ₓ Ry(a_l)` with `x_rᵀ E x_l = 0`.
    pub fn essential(&self) -> Matrix3<f64> {
        from_unknowns(self.unknowns())
    }

    /// Reads the angles from the unknowns (any positive scale; the sign must already be resolved).
    pub fn from_unknowns(e: [f64; 4]) -> Self {
        Self {
            alpha_l: e[1].atan2(-e[3]),
            alpha_r: (-e[0]).atan2(e[2]),
        }
    }
}

fn from_unknowns(e: [f64; 4]) -> Matrix3<f64> {
    Matrix3::new(0.0, e[0], 0.0, e[1], 0.0, e[3], 0.0, e[2], 0.0)
}

/// One row of the linear system `x_rᵀ E x_l = [u_r v_l, v_r u_l, v_l, v_r] · e = 0`.
pub(crate) fn design_row(c: &Correspondence) -> [f64; 4] {
    let [ul, vl] = c.left;
    let [ur, vr] = c.right;
    [ur * vl, vr * ul, vl, vr]
}

/// Minimum number of matches for the linear 4-unknown solve (3 equations fix a direction in R⁴).
pub const LINEAR_MIN_MATCHES: usize = 3;

/// Minimum number of matches for a refinement of the two yaws (one equation each for two
/// unknowns).
pub const YAW_MIN_MATCHES: usize = 2;

/// Linear solve of e1..e4 (thesis 4.5.1): the right singular vector of the N×4 design matrix
/// with the smallest singular value (computed through the 4×4 normal matrix, which has the same
/// singular vectors), projected to a valid essential matrix and sign-resolved.
pub fn linear(matches: &[Correspondence]) -> Result<VergeAngles, EssentialError> {
    let weights = vec![1.0; matches.len()];
    linear_weighted(matches, &weights)
}

/// [`linear`] with a non-negative weight per match (the estimator's start: RANSAC's inliers
/// at their refinement weights, the others at zero).
pub fn linear_weighted(
    matches: &[Correspondence],
    weights: &[f64],
) -> Result<VergeAngles, EssentialError> {
    if matches.len() < LINEAR_MIN_MATCHES {
        return Err(EssentialError::TooFewMatches {
            got: matches.len(),
            need: LINEAR_MIN_MATCHES,
        });
    }
    let mut ata = Matrix4::<f64>::zeros();
    for (c, &w) in matches.iter().zip(weights) {
        let a = design_row(c);
        for i in 0..4 {
            for j in 0..4 {
                ata[(i, j)] += w * a[i] * a[j];
            }
        }
    }
    if !ata.iter().all(|v| v.is_finite()) {
        return Err(EssentialError::Degenerate);
    }
    let svd = ata.svd(false, true);
    let v_t = svd.v_t.ok_or(EssentialError::Degenerate)?;
    let (imin, _) = svd
        .singular_values
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .ok_or(EssentialError::Degenerate)?;
    let row = v_t.row(imin);
    let e = [row[0], row[1], row[2], row[3]];
    enforce_and_resolve(e)
}

/// Rank-2 enforcement with equal non-zero singular values (`E' = U diag(m, m, 0) Vᵀ`), then the
/// 180° ambiguity resolved from U (thesis 4.5.2).
///
/// For this structure `E` maps the y axis to `(e1, 0, e3)` and the x-z plane to the y axis, so
/// one right singular vector is ±y and its left partner is `±(e1, 0, e3)/n = ±(-sin a_r, 0,
/// cos a_r)`. With the V column fixed to +y, that U column must point forward (z > 0) for a
/// camera looking forward; otherwise `E` describes the head rotated 180° and is negated
/// (the thesis' 180° rotation about x).
pub fn enforce_and_resolve(e: [f64; 4]) -> Result<VergeAngles, EssentialError> {
    let m = from_unknowns(e);
    let svd = m.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Err(EssentialError::Degenerate);
    };
    let s = svd.singular_values;
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| s[b].total_cmp(&s[a]));
    let mean = 0.5 * (s[order[0]] + s[order[1]]);
    if !(mean.is_finite() && mean > 0.0) {
        return Err(EssentialError::Degenerate);
    }
    let mut d = Vector3::zeros();
    d[order[0]] = mean;
    d[order[1]] = mean;
    let e2 = u * Matrix3::from_diagonal(&d) * v_t;
    // The singular pair that belongs to the y axis: the V column with the largest |y|.
    let (iy, _) = (0..3)
        .map(|i| (i, v_t[(i, 1)].abs()))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .ok_or(EssentialError::Degenerate)?;
    let flip_v = v_t[(iy, 1)].signum();
    let forward = u[(2, iy)] * flip_v;
    let sign = if forward >= 0.0 { 1.0 } else { -1.0 };
    let unknowns = [
        sign * e2[(0, 1)],
        sign * e2[(1, 0)],
        sign * e2[(2, 1)],
        sign * e2[(1, 2)],
    ];
    Ok(VergeAngles::from_unknowns(unknowns))
}

/// The result of the robust refinement.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstrainedFit {
    /// The refined yaws of both cameras.
    pub angles: VergeAngles,
    /// Standard deviation of the verge angle from the Gauss-Newton covariance (radians).
    pub verge_sigma: f64,
    /// Robust noise scale of the Sampson residuals (calibrated units).
    pub residual_sigma: f64,
    /// Per match: |Sampson residual| below `inlier_sigmas`·σ.
    pub inliers: Vec<bool>,
    /// Gauss-Newton iterations run.
    pub iterations: usize,
}

impl ConstrainedFit {
    /// Matches counted as inliers.
    pub fn inlier_count(&self) -> usize {
        self.inliers.iter().filter(|&&b| b).count()
    }
}

/// Sampson residual of one match for the unknowns `e`, written out for the sparse structure
/// of E (the hot loop of RANSAC scoring and of the refinement).
#[inline]
pub fn residual(e: &[f64; 4], c: &Correspondence) -> f64 {
    let [ul, vl] = c.left;
    let [ur, vr] = c.right;
    let [e1, e2, e3, e4] = *e;
    let ex1 = e2 * ul + e4;
    let etx1 = e1 * ur + e3;
    let n = ur * e1 * vl + vr * ex1 + e3 * vl;
    let d = (e1 * vl).powi(2) + ex1 * ex1 + (e2 * vr).powi(2) + etx1 * etx1;
    if d > 0.0 {
        n / d.sqrt()
    } else {
        0.0
    }
}

/// Sampson residual and its gradient with respect to (alpha_l, alpha_r). With
/// `e = (-sin a_r, sin a_l, cos a_r, -cos a_l)`: `∂e/∂a_l = (0, -e4, 0, e2)` and
/// `∂e/∂a_r = (-e3, 0, e1, 0)`.
#[inline]
fn residual_and_gradient(e: &[f64; 4], c: &Correspondence) -> Option<(f64, Vector2<f64>)> {
    let [ul, vl] = c.left;
    let [ur, vr] = c.right;
    let [e1, e2, e3, e4] = *e;
    let ex0 = e1 * vl;
    let ex1 = e2 * ul + e4;
    let etx0 = e2 * vr;
    let etx1 = e1 * ur + e3;
    let n = ur * ex0 + vr * ex1 + e3 * vl;
    let d = ex0 * ex0 + ex1 * ex1 + etx0 * etx0 + etx1 * etx1;
    if d <= 0.0 {
        return None;
    }
    let sd = d.sqrt();
    // Along a_l.
    let dex1 = -e4 * ul + e2;
    let dn_l = vr * dex1;
    let dd_l = 2.0 * (ex1 * dex1 + etx0 * (-e4 * vr));
    // Along a_r.
    let dn_r = vl * (e1 - e3 * ur);
    let dd_r = 2.0 * (ex0 * (-e3 * vl) + etx1 * (-e3 * ur + e1));
    let g = |dn: f64, dd: f64| dn / sd - 0.5 * n * dd / (d * sd);
    Some((n / sd, Vector2::new(g(dn_l, dd_l), g(dn_r, dd_r))))
}

/// Robust Gauss-Newton (IRLS) refinement of (alpha_l, alpha_r) on the Sampson error of all
/// matches, started from `init` (e.g. [`linear`] or RANSAC).
pub fn refine(
    matches: &[Correspondence],
    init: VergeAngles,
    config: &RefineConfig,
) -> Result<ConstrainedFit, EssentialError> {
    if matches.len() < YAW_MIN_MATCHES {
        return Err(EssentialError::TooFewMatches {
            got: matches.len(),
            need: YAW_MIN_MATCHES,
        });
    }
    let mut angles = init;
    let mut residuals = vec![0.0; matches.len()];
    let mut jac = vec![Vector2::zeros(); matches.len()];
    let mut sigma = config.min_sigma;
    let mut info = Matrix2::zeros();
    let mut iterations = 0;
    for it in 0..config.max_iterations.max(1) {
        iterations = it + 1;
        let e = angles.unknowns();
        for (i, c) in matches.iter().enumerate() {
            let (r, g) = residual_and_gradient(&e, c).unwrap_or_default();
            let s = c.weight.sqrt();
            residuals[i] = r * s;
            jac[i] = g * s;
        }
        sigma = mad_sigma(&residuals, config.min_sigma);
        let mut h = Matrix2::zeros();
        let mut b = Vector2::zeros();
        for (r, g) in residuals.iter().zip(&jac) {
            let w = config.loss.weight(*r, sigma);
            h += w * g * g.transpose();
            b += w * g * *r;
        }
        info = h;
        let Some(step) = h.try_inverse().map(|hi| -(hi * b)) else {
            return Err(EssentialError::Degenerate);
        };
        angles.alpha_l += step[0];
        angles.alpha_r += step[1];
        if !(angles.alpha_l.is_finite() && angles.alpha_r.is_finite()) {
            return Err(EssentialError::Degenerate);
        }
        // 1e-10 rad is 6e-9°: far below any accuracy that matters.
        if step.norm() < 1e-10 {
            break;
        }
    }
    let cov = info.try_inverse().ok_or(EssentialError::Degenerate)? * sigma * sigma;
    let verge_var = cov[(0, 0)] + cov[(1, 1)] - 2.0 * cov[(0, 1)];
    let e = angles.unknowns();
    let limit = config.inlier_sigmas * sigma;
    let inliers = matches
        .iter()
        .map(|c| residual(&e, c).abs() * c.weight.sqrt() < limit)
        .collect();
    Ok(ConstrainedFit {
        angles,
        verge_sigma: verge_var.max(0.0).sqrt(),
        residual_sigma: sigma,
        inliers,
        iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::super::testutil::synthetic;
    use super::super::{rot_y, sampson_residual, skew, RobustLoss};
    use super::*;

    /// A verged head's R, T give the two yaws whose essential matrix explains its matches.
    #[test]
    fn the_calibrated_yaws_explain_a_verged_head() {
        let (r_left, r_right) = (rot_y(0.02), rot_y(-0.015));
        let t = Vector3::new(0.3, 0.0, 0.0);
        let (r, tr) = (r_right.transpose() * r_left, -(r_right.transpose() * t));
        let (e, _) = crate::calib::Extrinsics::from_rotation_translation(&r, &tr).unwrap();
        let a = VergeAngles::from_extrinsics(&e);
        assert!(
            (a.alpha_l - 0.02).abs() < 1e-12 && (a.alpha_r + 0.015).abs() < 1e-12,
            "{a:?}"
        );
        for c in synthetic(r_left, r_right, 0.3, 50, 0.0, 500.0, 6) {
            let res = sampson_residual(&a.essential(), &c);
            assert!(res.abs() < 1e-12, "{res}");
        }
    }

    #[test]
    fn sparse_residual_and_gradient_match_the_matrix_form() {
        let a = VergeAngles::new(0.04, -0.02);
        let m = synthetic(rot_y(0.05), rot_y(-0.01), 0.3, 20, 2.0, 700.0, 4);
        let h = 1e-7;
        for c in &m {
            let (r, g) = residual_and_gradient(&a.unknowns(), c).unwrap();
            assert!((r - sampson_residual(&a.essential(), c)).abs() < 1e-15);
            assert!((r - residual(&a.unknowns(), c)).abs() < 1e-15);
            let num = |dl: f64, dr: f64| {
                let p = VergeAngles::new(a.alpha_l + dl, a.alpha_r + dr);
                let q = VergeAngles::new(a.alpha_l - dl, a.alpha_r - dr);
                (sampson_residual(&p.essential(), c) - sampson_residual(&q.essential(), c))
                    / (2.0 * h)
            };
            assert!(
                (g[0] - num(h, 0.0)).abs() < 1e-6,
                "{} vs {}",
                g[0],
                num(h, 0.0)
            );
            assert!(
                (g[1] - num(0.0, h)).abs() < 1e-6,
                "{} vs {}",
                g[1],
                num(0.0, h)
            );
        }
    }

    #[test]
    fn essential_matches_the_derivation() {
        // E = Ry(a_r)ᵀ [x]ₓ Ry(a_l) must equal the closed form in `unknowns`.
        let a = VergeAngles::new(0.07, -0.03);
        let direct = rot_y(a.alpha_r).transpose() * skew(&Vector3::x()) * rot_y(a.alpha_l);
        assert!((direct - a.essential()).norm() < 1e-15);
    }

    #[test]
    fn synthetic_projections_satisfy_the_constraint_with_the_right_sign() {
        // Toe-in: left turns toward +x (alpha_l > 0), right toward -x: verge > 0.
        let truth = VergeAngles::new(2f64.to_radians(), -1.5f64.to_radians());
        let m = synthetic(
            rot_y(truth.alpha_l),
            rot_y(truth.alpha_r),
            0.3,
            200,
            0.0,
            700.0,
            1,
        );
        let e = truth.essential();
        assert!(m.iter().all(|c| sampson_residual(&e, c).abs() < 1e-12));
        let wrong = VergeAngles::new(truth.alpha_r, truth.alpha_l).essential();
        assert!(m.iter().any(|c| sampson_residual(&wrong, c).abs() > 1e-4));
        let est = linear(&m).unwrap();
        assert!((est.alpha_l - truth.alpha_l).abs() < 1e-9, "{est:?}");
        assert!((est.alpha_r - truth.alpha_r).abs() < 1e-9, "{est:?}");
        assert!((est.verge_deg() - 3.5).abs() < 1e-7);
    }

    #[test]
    fn sign_ambiguity_is_resolved_for_both_signs_of_e() {
        let truth = VergeAngles::new(0.1, 0.05);
        let e = truth.unknowns();
        for s in [1.0, -1.0, 3.7, -0.2] {
            let got = enforce_and_resolve(e.map(|v| v * s)).unwrap();
            assert!((got.alpha_l - truth.alpha_l).abs() < 1e-12, "{s}: {got:?}");
            assert!((got.alpha_r - truth.alpha_r).abs() < 1e-12, "{s}: {got:?}");
        }
    }

    #[test]
    fn enforcement_equalises_singular_values() {
        // Unequal blocks (as a noisy linear solve gives) are projected to equal norms.
        let got = enforce_and_resolve([-0.2, 0.3, 2.0, -1.0]).unwrap();
        let e = got.essential();
        let s = e.svd(false, false).singular_values;
        let mut s: Vec<f64> = s.iter().copied().collect();
        s.sort_by(f64::total_cmp);
        assert!(s[0].abs() < 1e-12 && (s[1] - s[2]).abs() < 1e-12, "{s:?}");
    }

    #[test]
    fn refinement_recovers_verge_under_noise_and_outliers() {
        let truth = VergeAngles::new(0.8f64.to_radians(), -1.1f64.to_radians());
        let f = 700.0;
        let mut m = synthetic(
            rot_y(truth.alpha_l),
            rot_y(truth.alpha_r),
            0.3,
            400,
            0.3,
            f,
            7,
        );
        // 10 % gross outliers: right points moved vertically by 5-20 px.
        for (i, c) in m.iter_mut().enumerate().filter(|(i, _)| i % 10 == 0) {
            c.right[1] += (5.0 + (i % 16) as f64) / f;
        }
        let init = crate::ransac::ransac(&m, &crate::ransac::RansacConfig::default())
            .unwrap()
            .angles;
        let fit = refine(&m, init, &RefineConfig::default()).unwrap();
        let err = (fit.angles.verge() - truth.verge()).to_degrees().abs();
        // 360 inliers at 0.3 px constrain the verge to σ ≈ 0.04° in this wide-depth scene; the
        // estimate must agree with its own covariance.
        let sigma = fit.verge_sigma.to_degrees();
        assert!(sigma > 0.01 && sigma < 0.06, "σ {sigma}°");
        assert!(err < 3.0 * sigma, "verge error {err}° (init {init:?})");
        assert!(fit.inlier_count() >= 340 && fit.inlier_count() <= 365);
        let ls = RefineConfig {
            loss: RobustLoss::LeastSquares,
            ..RefineConfig::default()
        };
        let fit_ls = refine(&m, init, &ls).unwrap();
        let err_ls = (fit_ls.angles.verge() - truth.verge()).to_degrees().abs();
        assert!(err < err_ls, "robust {err} vs least squares {err_ls}");
    }

    #[test]
    fn inverse_variance_weights_favour_the_precise_matches() {
        let f = 700.0;
        let truth = VergeAngles::new(1.0f64.to_radians(), -0.5f64.to_radians());
        let (rl, rr) = (rot_y(truth.alpha_l), rot_y(truth.alpha_r));
        // Mean error over seeds: 50 matches at 0.05 px among 200 at 1 px.
        let (mut equal, mut weighted) = (0.0, 0.0);
        for seed in 0..10 {
            let mut m = synthetic(rl, rr, 0.3, 50, 0.05, f, seed);
            m.extend(synthetic(rl, rr, 0.3, 200, 1.0, f, seed + 100));
            let fit = |m: &[Correspondence]| {
                let fit = refine(m, VergeAngles::new(0.0, 0.0), &RefineConfig::default()).unwrap();
                (fit.angles.verge() - truth.verge()).to_degrees().abs()
            };
            equal += fit(&m);
            for (i, c) in m.iter_mut().enumerate() {
                c.weight = if i < 50 { 400.0 } else { 1.0 };
            }
            weighted += fit(&m);
        }
        assert!(
            weighted < 0.5 * equal,
            "weighted {weighted}° vs equal {equal}°"
        );
    }

    #[test]
    fn too_few_and_degenerate_inputs_are_errors() {
        let c = Correspondence {
            left: [0.1, 0.0],
            right: [0.05, 0.0],
            weight: 1.0,
        };
        assert!(matches!(
            linear(&[c, c]),
            Err(EssentialError::TooFewMatches { got: 2, need: 3 })
        ));
        let nan = Correspondence {
            left: [f64::NAN, 0.0],
            right: [0.0, 0.0],
            weight: 1.0,
        };
        assert!(linear(&[nan; 5]).is_err());
    }
}
