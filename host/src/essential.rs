//! Essential-matrix estimation for a verging stereo head.
//!
//! Geometry (`docs/ARCHITECTURE.md`, "Frames and signs", derived here once): the head frame is the left
//! camera's frame at zero yaw; x right, y down, z forward; the right camera's centre is at
//! t = (b, 0, 0). A camera with yaw `alpha` about its own (downward) y axis has orientation
//! `Ry(alpha) = [[c, 0, s], [0, 1, 0], [-s, 0, c]]` (columns = camera axes in the head frame),
//! so `alpha > 0` turns its optical axis toward +x. A head point X has camera coordinates
//! `x_l = Ry(a_l)ᵀ X` and `x_r = Ry(a_r)ᵀ (X - t)`. X, X - t and t are coplanar, so
//! `(X - t) · (t × X) = 0`, i.e. `x_rᵀ E x_l = 0` with
//!
//! ```text
//! E = Ry(a_r)ᵀ [t]ₓ Ry(a_l) = | 0        -sin a_r   0        |
//!                             | sin a_l   0         -cos a_l |   (b = 1)
//!                             | 0         cos a_r    0        |
//! ```
//!
//! which is the thesis' form `[[0, e1, 0], [e2, 0, e4], [0, e3, 0]]` with
//! `e1 = -sin a_r, e2 = sin a_l, e3 = cos a_r, e4 = -cos a_l`. The verge angle is
//! `a_l - a_r` (toe-in positive). For the general model the relative rotation
//! `R = Ry(a_r)ᵀ Ry(a_l)` maps left to right camera coordinates and `E = [t_r]ₓ R` with
//! `t_r = Ry(a_r)ᵀ t`; `R_01 = Rᵀ = Ry(yaw) Rx(pitch) Rz(roll)` as in the real data sets'
//! `geometry.json` (`docs/ARCHITECTURE.md`, "Real data"), so `verge = -yaw`.

pub mod constrained;
pub mod general;
pub mod misaligned;

use nalgebra::{Matrix3, Vector3};

use crate::calib::Calibration;

/// One match in calibrated coordinates: the rays (x, y, 1) of the left and right camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Correspondence {
    /// The left camera's ray `(x, y)` at z = 1, undistorted.
    pub left: [f64; 2],
    /// The right camera's ray `(x, y)` at z = 1, undistorted.
    pub right: [f64; 2],
    /// Relative weight in the refinement (inverse variance, 1 = nominal).
    pub weight: f64,
}

impl Correspondence {
    /// Converts a pixel match (full-resolution pixels, distorted) to calibrated coordinates.
    pub fn from_pixels(calib: &Calibration, left_px: [f64; 2], right_px: [f64; 2]) -> Self {
        let (xl, yl) = calib.left.normalize(left_px[0], left_px[1]);
        let (xr, yr) = calib.right.normalize(right_px[0], right_px[1]);
        Self {
            left: [xl, yl],
            right: [xr, yr],
            weight: 1.0,
        }
    }

    fn left_h(&self) -> Vector3<f64> {
        Vector3::new(self.left[0], self.left[1], 1.0)
    }

    fn right_h(&self) -> Vector3<f64> {
        Vector3::new(self.right[0], self.right[1], 1.0)
    }
}

/// Why no essential matrix could be estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum EssentialError {
    /// Fewer matches than the model needs.
    #[error("{got} matches, the model needs at least {need}")]
    TooFewMatches {
        /// Matches given.
        got: usize,
        /// The model's minimum.
        need: usize,
    },
    /// The matches do not constrain the model (e.g. all on the horizon row, or NaN input).
    #[error("degenerate match configuration")]
    Degenerate,
}

/// Sampson (first-order geometric) epipolar error of one correspondence, signed, in
/// calibrated units (multiply by the focal length for pixels).
pub fn sampson_residual(e: &Matrix3<f64>, c: &Correspondence) -> f64 {
    let xl = c.left_h();
    let xr = c.right_h();
    let ex = e * xl;
    let etx = e.transpose() * xr;
    let num = xr.dot(&ex);
    let den = ex[0] * ex[0] + ex[1] * ex[1] + etx[0] * etx[0] + etx[1] * etx[1];
    if den > 0.0 {
        num / den.sqrt()
    } else {
        0.0
    }
}

/// The Cauchy loss's scale in units of the noise σ: 95 % asymptotic efficiency under Gaussian
/// noise, so that clean matches lose little against least squares while gross outliers weigh
/// almost nothing.
const CAUCHY_SCALE: f64 = 2.385;

/// Cauchy cost `Σ ln(1 + (r/c)²)` of the Sampson residuals of `e`, with `c = 2.385·sigma`:
/// compares candidate solutions on the same robust scale.
pub fn cauchy_cost(e: &Matrix3<f64>, matches: &[Correspondence], sigma: f64) -> f64 {
    let c = CAUCHY_SCALE * sigma;
    matches
        .iter()
        .map(|m| {
            let r = sampson_residual(e, m) / c;
            (1.0 + r * r).ln()
        })
        .sum()
}

/// The M-estimator used by the iterative refinements (IRLS weights).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RobustLoss {
    /// Plain least squares: every match counts fully (not robust to outliers).
    LeastSquares,
    /// Huber with threshold 1.345·σ (95 % efficiency under Gaussian noise).
    Huber,
    /// Cauchy with scale 2.385·σ (95 % efficiency); down-weights gross outliers to ~0.
    Cauchy,
}

impl RobustLoss {
    /// IRLS weight of a residual `r` given the noise scale `sigma`.
    pub(crate) fn weight(self, r: f64, sigma: f64) -> f64 {
        match self {
            RobustLoss::LeastSquares => 1.0,
            RobustLoss::Huber => {
                // Huber's 1.345 σ: 95 % asymptotic efficiency under Gaussian noise, as the
                // Cauchy scale.
                let k = 1.345 * sigma;
                if r.abs() <= k {
                    1.0
                } else {
                    k / r.abs()
                }
            }
            RobustLoss::Cauchy => {
                let c = CAUCHY_SCALE * sigma;
                1.0 / (1.0 + (r / c) * (r / c))
            }
        }
    }
}

/// Settings of the iterative (Gauss-Newton IRLS) refinements.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefineConfig {
    /// The M-estimator whose IRLS weights each iteration applies.
    pub loss: RobustLoss,
    /// Maximum Gauss-Newton iterations.
    pub max_iterations: usize,
    /// Lower bound of the robust noise scale, in calibrated units. The scale is otherwise
    /// re-estimated every iteration as 1.4826·median|r| (MAD).
    pub min_sigma: f64,
    /// A match is counted as an inlier when |r| < `inlier_sigmas` · σ.
    pub inlier_sigmas: f64,
}

impl Default for RefineConfig {
    fn default() -> Self {
        Self {
            loss: RobustLoss::Cauchy,
            // A bound, not a stop: every constrained refinement of the rendered road and the
            // KITTI drive stops on its step before it (60 changes no estimate), and 15 moves a
            // few of the drive's frames by < 0.0001° (README, "Sensitivity of the constants").
            max_iterations: 30,
            // 0.004 to 0.014 px at the 400 to 1400 px focal lengths the geometry tests cover
            // (README, "Geometry, not pixel constants"), below the few hundredths of a pixel the
            // sub-pixel refinement resolves; it keeps the robust scale of near-exact matches,
            // the divisor of the Cauchy weights, from zero.
            min_sigma: 1e-5,
            // A match with Gaussian noise lies within 3 σ with probability 99.7 %.
            inlier_sigmas: 3.0,
        }
    }
}

/// Robust noise scale from the median absolute residual.
pub(crate) fn mad_sigma(residuals: &[f64], floor: f64) -> f64 {
    let mut abs: Vec<f64> = residuals.iter().map(|r| r.abs()).collect();
    if abs.is_empty() {
        return floor;
    }
    let mid = abs.len() / 2;
    let (_, median, _) = abs.select_nth_unstable_by(mid, f64::total_cmp);
    // 1.4826 = 1 / Φ⁻¹(3/4): the median absolute residual of Gaussian noise times it is σ.
    (1.4826 * *median).max(floor)
}

/// Cross-product matrix `[t]ₓ` (`[t]ₓ v = t × v`).
fn skew(t: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -t[2], t[1], t[2], 0.0, -t[0], -t[1], t[0], 0.0)
}

/// Rotation about the y axis (camera yaw), see the module doc for the sign.
pub fn rot_y(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Rotation about the x axis (pitch).
pub fn rot_x(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Rotation about the z axis (roll).
pub fn rot_z(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

#[cfg(test)]
pub(crate) mod testutil {
    //! Synthetic correspondences: random 3D points projected through two cameras.
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Projects random points in front of a head with the given right-camera pose
    /// (`r_right` = orientation of the right camera in the head frame, left camera has
    /// orientation `r_left`), adds Gaussian-ish pixel noise `noise_px` at focal `f`.
    pub fn synthetic(
        r_left: Matrix3<f64>,
        r_right: Matrix3<f64>,
        baseline: f64,
        n: usize,
        noise_px: f64,
        f: f64,
        seed: u64,
    ) -> Vec<Correspondence> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let t = Vector3::new(baseline, 0.0, 0.0);
        let mut out = Vec::with_capacity(n);
        while out.len() < n {
            let z: f64 = rng.random_range(2.0..40.0);
            let x: f64 = rng.random_range(-0.5..0.5) * z;
            let y: f64 = rng.random_range(-0.35..0.35) * z;
            let p = Vector3::new(x, y, z);
            let pl = r_left.transpose() * p;
            let pr = r_right.transpose() * (p - t);
            if pl[2] <= 0.1 || pr[2] <= 0.1 {
                continue;
            }
            let mut noise = || {
                // Sum of uniforms: a cheap, bounded, near-Gaussian deviate with unit variance.
                let s: f64 = (0..4).map(|_| rng.random_range(-1.0..1.0)).sum();
                s * (3.0f64 / 4.0).sqrt() * noise_px / f
            };
            let l = [pl[0] / pl[2] + noise(), pl[1] / pl[2] + noise()];
            let r = [pr[0] / pr[2] + noise(), pr[1] / pr[2] + noise()];
            if l.iter().chain(r.iter()).any(|v| v.abs() > 0.6) {
                continue;
            }
            out.push(Correspondence {
                left: l,
                right: r,
                weight: 1.0,
            });
        }
        out
    }

    /// [`synthetic`] matches of a head with yaws `a` and misalignments `m` (baseline 0.3 m).
    /// The generator's baseline lies along x, so the tilt turns the whole head by `-tilt`
    /// about z: in the head's own frame the baseline then points along `(cos tilt, sin tilt,
    /// 0)`.
    pub fn misaligned_synthetic(
        a: super::constrained::VergeAngles,
        m: &super::misaligned::Misalignment,
        n: usize,
        noise_px: f64,
        f: f64,
        seed: u64,
    ) -> Vec<Correspondence> {
        let turn = rot_z(-m.tilt);
        let left = turn * rot_y(a.alpha_l);
        let right = turn * rot_y(a.alpha_r) * rot_x(m.pitch) * rot_z(m.roll);
        synthetic(left, right, 0.3, n, noise_px, f, seed)
    }
}
