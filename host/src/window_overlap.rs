//! How much the matches' shared refinement windows inflate an estimate's variance.
//!
//! A fit's covariance takes its matches' errors as independent, but two matches whose
//! sub-pixel windows overlap read the same pixels, and the pixels' noise and aliasing (the
//! larger part of a match's error, README "How much of a match's vertical position is the
//! pixels' own bias") move both alike. The guided matcher places its matches a few pixels from
//! the descriptor matches and from each other, so a frame's matches share much of their
//! windows, and a σ that takes them as independent counts them as more evidence than they are:
//! on the rendered road, whose truth is exact, its median |error| / σ is 0.90 where an honest
//! σ gives 0.674.
//!
//! The model: two matches' errors correlate as much as their windows overlap, `(1 - |dx|/s)
//! (1 - |dy|/s)` for windows of side `s` whose centres are `dx`, `dy` apart. A weighted fit's
//! variance then grows by `Σᵢⱼ wᵢ wⱼ ρᵢⱼ / Σᵢ wᵢ²` over its independent form, the factor of a
//! weighted mean, which stands in for the two-yaw fit's (whose leverage varies smoothly over the
//! image, so neighbours weigh in it alike). With it the rendered road's median |error| / σ is
//! 0.69.

/// The factor (≥ 1) by which the standard deviation of a fit to matches at left pixels
/// `points` with weights `weights` grows when each match's error correlates with another's as
/// much as their `side` x `side` windows overlap (see the module documentation). 1 without
/// points or weights.
pub fn sigma_inflation(points: &[[f64; 2]], weights: &[f64], side: f64) -> f64 {
    let mut order: Vec<usize> = (0..points.len().min(weights.len())).collect();
    order.sort_by(|&a, &b| points[a][0].total_cmp(&points[b][0]));
    let (mut alone, mut shared) = (0.0, 0.0);
    for (k, &i) in order.iter().enumerate() {
        alone += weights[i] * weights[i];
        // Sorted by column: the windows that overlap this one in x follow it directly.
        for &j in &order[k + 1..] {
            let dx = points[j][0] - points[i][0];
            if dx >= side {
                break;
            }
            let dy = (points[j][1] - points[i][1]).abs();
            if dy < side {
                shared += 2.0 * weights[i] * weights[j] * (1.0 - dx / side) * (1.0 - dy / side);
            }
        }
    }
    if alone > 0.0 && alone.is_finite() && shared.is_finite() {
        ((alone + shared) / alone).sqrt()
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_apart_change_nothing() {
        let points = [[0.0, 0.0], [20.0, 0.0], [0.0, 20.0], [40.0, 40.0]];
        assert_eq!(sigma_inflation(&points, &[1.0; 4], 15.0), 1.0);
    }

    #[test]
    fn one_window_counted_n_times_is_one_match() {
        // n matches on one window are one match's evidence: the σ of a mean of n copies is
        // √n times what n independent matches would give.
        let points = [[5.0, 5.0]; 9];
        let f = sigma_inflation(&points, &[1.0; 9], 15.0);
        assert!((f - 3.0).abs() < 1e-12, "{f}");
    }

    #[test]
    fn half_overlap_in_one_direction() {
        let points = [[0.0, 0.0], [7.5, 0.0]];
        let f = sigma_inflation(&points, &[1.0, 1.0], 15.0);
        // (2 + 2 · 0.5) / 2 = 1.5.
        assert!((f - 1.5f64.sqrt()).abs() < 1e-12, "{f}");
    }

    #[test]
    fn empty_or_weightless_is_one() {
        assert_eq!(sigma_inflation(&[], &[], 15.0), 1.0);
        assert_eq!(sigma_inflation(&[[0.0, 0.0]], &[0.0], 15.0), 1.0);
    }
}
