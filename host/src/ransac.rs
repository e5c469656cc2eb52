//! RANSAC over minimal constrained hypotheses.
//!
//! How many matches does the constrained model need? E has four unknowns but only two
//! degrees of freedom: `p = (sin a_r, cos a_r)` and `q = (sin a_l, cos a_l)` are unit vectors.
//! Each match gives one equation, linear in both (see [`crate::essential`] for E):
//!
//! ```text
//! a·p + b·q = 0,   a = (-u_r v_l, v_l),   b = (v_r u_l, -v_r)
//! ```
//!
//! Two matches stack to `A p = -B q`, so `p = M q` with `M = -A⁻¹ B`, and `|p| = |q| = 1`
//! leaves the quadratic form `qᵀ (MᵀM - I) q = 0` on the unit circle: a quadratic in
//! `tan a_l` with at most two real roots (each up to the sign of E, fixed by requiring
//! forward-looking cameras). So **two matches** are the minimal sample, giving ≤ 2 hypotheses,
//! against three matches for the plain linear 4-unknown solve.

use nalgebra::Matrix2;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::essential::constrained::{residual, VergeAngles};
use crate::essential::{Correspondence, EssentialError};

/// Matches in a minimal sample of the constrained model.
pub const MINIMAL_SAMPLE: usize = 2;

/// RANSAC settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RansacConfig {
    /// Inlier threshold on the |Sampson error|, in calibrated units (pixels / focal length).
    pub threshold: f64,
    /// Upper bound of the number of samples drawn.
    pub max_iterations: usize,
    /// Desired probability of having drawn one all-inlier sample (adaptive stopping).
    pub confidence: f64,
    /// Seed of the ChaCha RNG: the same input and seed give the same result.
    pub seed: u64,
    /// Hypotheses whose |alpha| exceeds this (radians) are discarded: a head cannot turn its
    /// cameras sideways, and near-degenerate samples produce such solutions. The default lies
    /// beyond the head's whole range ([`crate::epipolar_band::MAX_ANGLE_DEG`]).
    pub max_abs_angle: f64,
}

impl Default for RansacConfig {
    fn default() -> Self {
        Self {
            // One pixel at a 700 px focal length, that of the synthetic cameras the fits'
            // tests draw their matches with, for callers that hold no calibration;
            // `VergeEstimator` replaces it with its `ransac_threshold_px` over the
            // calibration's focal length.
            threshold: 1.0 / 700.0,
            // Enough for `confidence` down to an inlier fraction of about 12 %:
            // ln(1 - 0.999) / ln(1 - 0.12²) ≈ 477 two-match samples.
            max_iterations: 500,
            // One frame in a thousand may lack an all-inlier sample (the stopping rule below,
            // after Fischler and Bolles); RANSAC only starts the robust refinement, and 0.99 or
            // 0.9999 changes no estimate of the rendered road or the KITTI drive
            // (README, "Sensitivity of the constants").
            confidence: 0.999,
            seed: 0x5eed,
            // Ten degrees beyond the head's range, for the scatter of two-match hypotheses about
            // a head at its edge; the near-degenerate samples' sideways solutions lie towards
            // ±90°. A margin of 5° or 20° changes no estimate of the rendered road or the
            // KITTI drive (README, "Sensitivity of the constants").
            max_abs_angle: (crate::epipolar_band::MAX_ANGLE_DEG + 10.0).to_radians(),
        }
    }
}

/// What RANSAC found.
#[derive(Debug, Clone, PartialEq)]
pub struct RansacResult {
    /// The best-supported hypothesis.
    pub angles: VergeAngles,
    /// Per match: consistent with `angles` within the threshold.
    pub inliers: Vec<bool>,
    /// Matches in `inliers` that are true.
    pub inlier_count: usize,
    /// Samples drawn.
    pub iterations: usize,
}

/// The ≤ 2 constrained hypotheses through two matches (module doc).
pub(crate) fn minimal_solutions(c0: &Correspondence, c1: &Correspondence) -> heapless_pair::Pair {
    let row = |c: &Correspondence| {
        let [ul, vl] = c.left;
        let [ur, vr] = c.right;
        ([-ur * vl, vl], [vr * ul, -vr])
    };
    let (a0, b0) = row(c0);
    let (a1, b1) = row(c1);
    let a = Matrix2::new(a0[0], a0[1], a1[0], a1[1]);
    let b = Matrix2::new(b0[0], b0[1], b1[0], b1[1]);
    let mut out = heapless_pair::Pair::default();
    let Some(ai) = a.try_inverse() else {
        return out;
    };
    let m = -(ai * b);
    let s = m.transpose() * m - Matrix2::identity();
    // q = (sin, cos) = cos·(t, 1) with t = tan a_l:  s00 t² + 2 s01 t + s11 = 0.
    let (qa, qb, qc) = (s[(0, 0)], 2.0 * s[(0, 1)], s[(1, 1)]);
    let disc = qb * qb - 4.0 * qa * qc;
    // A leading coefficient this small (k / qa overflows, or lands at alpha_l = ±90°) marks a
    // degenerate sample: it gives no hypothesis.
    if disc.is_nan() || disc < 0.0 || qa.abs() < 1e-300 {
        return out;
    }
    let sq = disc.sqrt();
    // Numerically stable roots.
    let k = -0.5 * (qb + qb.signum() * sq);
    for t in [k / qa, if k != 0.0 { qc / k } else { f64::NAN }] {
        if !t.is_finite() {
            continue;
        }
        let alpha_l = t.atan(); // cos a_l > 0: forward-looking left camera
        let q = nalgebra::Vector2::new(alpha_l.sin(), alpha_l.cos());
        let p = m * q;
        let mut alpha_r = p[0].atan2(p[1]);
        let mut al = alpha_l;
        if p[1] < 0.0 {
            // The sign of E flips both cameras: pick the forward-looking pair.
            alpha_r = (-p[0]).atan2(-p[1]);
            al = (-q[0]).atan2(-q[1]);
        }
        if p[1] < 0.0 && q[1] > 0.0 {
            // Mixed forward/backward solutions are not a head.
            continue;
        }
        out.push(VergeAngles::new(al, alpha_r));
    }
    out
}

/// A tiny fixed-capacity list of at most two hypotheses (no allocation in the hot loop).
pub(crate) mod heapless_pair {
    use crate::essential::constrained::VergeAngles;

    #[derive(Debug, Default, Clone, Copy)]
    pub struct Pair {
        items: [Option<VergeAngles>; 2],
    }

    impl Pair {
        pub(super) fn push(&mut self, v: VergeAngles) {
            if let Some(slot) = self.items.iter_mut().find(|s| s.is_none()) {
                *slot = Some(v);
            }
        }

        pub fn iter(&self) -> impl Iterator<Item = VergeAngles> + '_ {
            self.items.iter().flatten().copied()
        }
    }
}

/// Runs RANSAC with two-match hypotheses and returns the best-supported one (ties broken by
/// the smaller summed truncated error, i.e. MSAC scoring).
pub fn ransac(
    matches: &[Correspondence],
    config: &RansacConfig,
) -> Result<RansacResult, EssentialError> {
    if matches.len() < MINIMAL_SAMPLE {
        return Err(EssentialError::TooFewMatches {
            got: matches.len(),
            need: MINIMAL_SAMPLE,
        });
    }
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    let n = matches.len();
    let thr2 = config.threshold * config.threshold;
    let mut best: Option<(f64, VergeAngles)> = None;
    let mut needed = config.max_iterations;
    let mut iterations = 0;
    while iterations < needed.min(config.max_iterations) {
        iterations += 1;
        let i = rng.random_range(0..n);
        let mut j = rng.random_range(0..n - 1);
        if j >= i {
            j += 1;
        }
        for h in minimal_solutions(&matches[i], &matches[j]).iter() {
            if h.alpha_l.abs() > config.max_abs_angle || h.alpha_r.abs() > config.max_abs_angle {
                continue;
            }
            let e = h.unknowns();
            let mut cost = 0.0;
            let mut count = 0usize;
            for c in matches {
                let r = residual(&e, c);
                let r2 = r * r;
                if r2 < thr2 {
                    count += 1;
                    cost += r2;
                } else {
                    cost += thr2;
                }
            }
            if best.is_none_or(|(b, _)| cost < b) {
                best = Some((cost, h));
                let w = count as f64 / n as f64;
                let p_good = w * w;
                needed = if p_good >= 1.0 {
                    1
                } else if p_good <= 0.0 {
                    config.max_iterations
                } else {
                    let k = (1.0 - config.confidence).ln() / (1.0 - p_good).ln();
                    // A floor of samples: with nearly every match an inlier one sample would
                    // do, but the score is MSAC's summed error, which later all-inlier samples
                    // can still lower. RANSAC only starts the robust refinement: a floor of 4
                    // or 16 changes no estimate of the rendered road or the KITTI drive
                    // (README, "Sensitivity of the constants").
                    (k.ceil() as usize).max(8)
                };
            }
        }
    }
    let (_, angles) = best.ok_or(EssentialError::Degenerate)?;
    let e = angles.unknowns();
    let inliers: Vec<bool> = matches
        .iter()
        .map(|c| residual(&e, c).abs() < config.threshold)
        .collect();
    let inlier_count = inliers.iter().filter(|&&b| b).count();
    Ok(RansacResult {
        angles,
        inliers,
        inlier_count,
        iterations,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::essential::rot_y;
    use crate::essential::testutil::synthetic;

    #[test]
    fn two_matches_give_the_true_angles_among_the_hypotheses() {
        let truth = VergeAngles::new(0.03, -0.05);
        let m = synthetic(
            rot_y(truth.alpha_l),
            rot_y(truth.alpha_r),
            0.3,
            20,
            0.0,
            700.0,
            11,
        );
        let mut found = 0;
        for k in 0..10 {
            let hs = minimal_solutions(&m[2 * k], &m[2 * k + 1]);
            if hs.iter().any(|h| {
                (h.alpha_l - truth.alpha_l).abs() < 1e-7 && (h.alpha_r - truth.alpha_r).abs() < 1e-7
            }) {
                found += 1;
            }
        }
        assert_eq!(found, 10);
    }

    #[test]
    fn ransac_is_deterministic_and_rejects_outliers() {
        let truth = VergeAngles::new(1f64.to_radians(), -2f64.to_radians());
        let f = 700.0;
        let mut m = synthetic(
            rot_y(truth.alpha_l),
            rot_y(truth.alpha_r),
            0.3,
            300,
            0.3,
            f,
            5,
        );
        for c in m.iter_mut().step_by(3) {
            c.right[1] += 0.02; // 14 px: one third gross outliers
        }
        let cfg = RansacConfig::default();
        let a = ransac(&m, &cfg).unwrap();
        let b = ransac(&m, &cfg).unwrap();
        assert_eq!(a, b);
        assert!(
            (a.angles.verge() - truth.verge()).to_degrees().abs() < 0.3,
            "{a:?}"
        );
        assert!(a.inliers.iter().step_by(3).all(|&x| !x));
        assert!(a.inlier_count >= 180, "{}", a.inlier_count);
        let other = ransac(&m, &RansacConfig { seed: 99, ..cfg }).unwrap();
        assert!((other.angles.verge() - truth.verge()).to_degrees().abs() < 0.3);
    }

    #[test]
    fn too_few_matches_is_an_error() {
        let c = Correspondence {
            left: [0.0, 0.1],
            right: [0.0, 0.1],
            weight: 1.0,
        };
        assert!(matches!(
            ransac(&[c], &RansacConfig::default()),
            Err(EssentialError::TooFewMatches { got: 1, need: 2 })
        ));
    }
}
