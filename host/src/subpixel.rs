//! Sub-pixel refinement of matches on the octave-0 Sobel magnitude planes.
//!
//! A verge change of 0.01° moves points vertically by only `u·v·Δα/f`, a few hundredths of a
//! pixel at the image corners, while DoG extrema are localised to a few tenths of a pixel
//! (and at 2ᵒ-pixel steps in octave `o`). So each match is re-localised: the left point is
//! snapped to its nearest octave-0 pixel, and the right point is moved to where a window of
//! the right magnitude plane best matches the left window (Lucas-Kanade, translation only,
//! inverse-compositional, with gain and offset compensation, since the two cameras' exposures
//! differ). Only the geometry of the point pair matters to the estimator, so fixing the left
//! point at an integer pixel loses nothing and keeps the interpolation on one side.
//!
//! Matches whose window has too little vertical structure (the vertical position would be
//! uncertain), that do not converge, that move too far or whose windows do not agree after
//! alignment are rejected.

use crate::frame::SobelPlane;

/// Settings of the refinement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SubpixelConfig {
    /// Window half size in octave-0 pixels (window side `2·half + 1`).
    pub half_window: usize,
    /// Lucas-Kanade iterations.
    pub max_iterations: usize,
    /// Reject when the refined right point moved more than this from its start (pixels).
    pub max_shift_px: f32,
    /// Reject when the estimated 1-σ vertical position error exceeds this (pixels).
    pub max_sigma_v_px: f32,
    /// Reject when the aligned windows' normalised cross-correlation is below this.
    pub min_correlation: f32,
}

impl Default for SubpixelConfig {
    fn default() -> Self {
        Self {
            half_window: 7,
            max_iterations: 12,
            max_shift_px: 2.0,
            max_sigma_v_px: 0.15,
            min_correlation: 0.8,
        }
    }
}

/// A refined point pair in octave-0 (full-resolution) pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefinedPair {
    pub left: [f32; 2],
    pub right: [f32; 2],
    /// Estimated 1-σ vertical position error of `right` (pixels).
    pub sigma_v: f32,
}

/// Samples the `side` x `side` window of `p`'s magnitude centred on (`x`, `y`) into `out`,
/// bilinearly. The window is a pure translation, so every sample shares one pair of
/// fractional weights: the bounds are checked once and the loop is four loads and a blend.
/// `None` when the window (plus its interpolation neighbours) leaves the plane.
fn sample_window(p: &SobelPlane, x: f32, y: f32, half: i32, out: &mut [f32]) -> Option<()> {
    let (w, h) = (p.width() as i32, p.height() as i32);
    let (x0, y0) = ((x - half as f32).floor(), (y - half as f32).floor());
    let (ix, iy) = (x0 as i32, y0 as i32);
    let side = 2 * half + 1;
    if !(x0.is_finite() && y0.is_finite()) || ix < 0 || iy < 0 || ix + side >= w || iy + side >= h {
        return None;
    }
    let (fx, fy) = (x - half as f32 - x0, y - half as f32 - y0);
    let (w00, w01) = ((1.0 - fx) * (1.0 - fy), fx * (1.0 - fy));
    let (w10, w11) = ((1.0 - fx) * fy, fx * fy);
    let (m, stride, side) = (p.magnitude(), w as usize, side as usize);
    for (r, row_out) in out.chunks_exact_mut(side).enumerate() {
        let top = &m[(iy as usize + r) * stride + ix as usize..][..side + 1];
        let bottom = &m[(iy as usize + r + 1) * stride + ix as usize..][..side + 1];
        for (c, o) in row_out.iter_mut().enumerate() {
            *o = w00 * f32::from(top[c])
                + w01 * f32::from(top[c + 1])
                + w10 * f32::from(bottom[c])
                + w11 * f32::from(bottom[c + 1]);
        }
    }
    Some(())
}

/// Refines one match: `left` / `right` in full-resolution pixels. `None` when rejected.
pub fn refine_pair(
    left_plane: &SobelPlane,
    right_plane: &SobelPlane,
    left: [f32; 2],
    right: [f32; 2],
    config: &SubpixelConfig,
) -> Option<RefinedPair> {
    let half = config.half_window as i32;
    let side = (2 * half + 1) as usize;
    let n = side * side;
    let (lx, ly) = (left[0].round() as i32, left[1].round() as i32);
    let (w, h) = (left_plane.width() as i32, left_plane.height() as i32);
    if lx - half - 1 < 0 || ly - half - 1 < 0 || lx + half + 1 >= w || ly + half + 1 >= h {
        return None;
    }
    // Template, its gradient (central differences) and zero-mean form.
    let mut t = vec![0f32; n];
    let mut gx = vec![0f32; n];
    let mut gy = vec![0f32; n];
    let at = |x: i32, y: i32| left_plane.magnitude()[(y * w + x) as usize] as f32;
    for r in 0..side {
        for c in 0..side {
            let (x, y) = (lx + c as i32 - half, ly + r as i32 - half);
            let i = r * side + c;
            t[i] = at(x, y);
            gx[i] = 0.5 * (at(x + 1, y) - at(x - 1, y));
            gy[i] = 0.5 * (at(x, y + 1) - at(x, y - 1));
        }
    }
    let t_mean = t.iter().sum::<f32>() / n as f32;
    t.iter_mut().for_each(|v| *v -= t_mean);
    let t_norm = t.iter().map(|v| v * v).sum::<f32>().sqrt();
    let (mut hxx, mut hxy, mut hyy) = (0f32, 0f32, 0f32);
    for i in 0..n {
        hxx += gx[i] * gx[i];
        hxy += gx[i] * gy[i];
        hyy += gy[i] * gy[i];
    }
    let det = hxx * hyy - hxy * hxy;
    if det.is_nan() || det <= 1e-6 * (hxx + hyy).powi(2) || t_norm <= 0.0 {
        return None;
    }
    // Start: the right point shifted by the same amount the left one was snapped.
    let start = [
        right[0] + (lx as f32 - left[0]),
        right[1] + (ly as f32 - left[1]),
    ];
    let mut p = start;
    let mut warped = vec![0f32; n];
    let mut converged = false;
    for _ in 0..config.max_iterations {
        sample_window(right_plane, p[0], p[1], half, &mut warped)?;
        let mean = warped.iter().sum::<f32>() / n as f32;
        let norm = warped
            .iter()
            .map(|v| (v - mean).powi(2))
            .sum::<f32>()
            .sqrt();
        if norm <= 0.0 {
            return None;
        }
        let gain = t_norm / norm;
        let (mut bx, mut by) = (0f32, 0f32);
        for i in 0..n {
            let e = (warped[i] - mean) * gain - t[i];
            bx += gx[i] * e;
            by += gy[i] * e;
        }
        // Inverse compositional: Δ = H⁻¹ Σ ∇T·e, p ← p - Δ.
        let dx = (hyy * bx - hxy * by) / det;
        let dy = (hxx * by - hxy * bx) / det;
        p[0] -= dx;
        p[1] -= dy;
        if (p[0] - start[0]).abs() > config.max_shift_px
            || (p[1] - start[1]).abs() > config.max_shift_px
        {
            return None;
        }
        if dx * dx + dy * dy < 1e-6 {
            converged = true;
            break;
        }
    }
    if !converged {
        return None;
    }
    // Quality at the solution: correlation and the vertical position uncertainty.
    sample_window(right_plane, p[0], p[1], half, &mut warped)?;
    let mean = warped.iter().sum::<f32>() / n as f32;
    let norm = warped
        .iter()
        .map(|v| (v - mean).powi(2))
        .sum::<f32>()
        .sqrt();
    if norm <= 0.0 {
        return None;
    }
    let mut dot = 0f32;
    let mut sse = 0f32;
    for i in 0..n {
        let wv = (warped[i] - mean) * t_norm / norm;
        dot += wv * t[i];
        sse += (wv - t[i]).powi(2);
    }
    let ncc = dot / (t_norm * t_norm);
    let noise_var = sse / (n as f32 - 4.0);
    let sigma_v = (noise_var * hxx / det).sqrt();
    if ncc < config.min_correlation || sigma_v > config.max_sigma_v_px {
        return None;
    }
    Some(RefinedPair {
        left: [lx as f32, ly as f32],
        right: p,
        sigma_v,
    })
}

/// Normalised cross-correlation of the `(2·half+1)²` windows of two planes at integer centres,
/// `None` when a window leaves its plane or is flat.
fn ncc_at(
    a: &SobelPlane,
    ax: i32,
    ay: i32,
    b: &SobelPlane,
    bx: i32,
    by: i32,
    half: i32,
) -> Option<f32> {
    let inside = |p: &SobelPlane, x: i32, y: i32| {
        x - half >= 0
            && y - half >= 0
            && x + half < p.width() as i32
            && y + half < p.height() as i32
    };
    if !inside(a, ax, ay) || !inside(b, bx, by) {
        return None;
    }
    let (wa, wb) = (a.width() as i32, b.width() as i32);
    let (ma, mb) = (a.magnitude(), b.magnitude());
    // Integer sums: exact, and loops over `u8` rows the compiler vectorises. Up to the default
    // 15x15 window every sum stays below 2^24 (225 products of at most 255²), so they convert
    // to `f32` exactly and the result equals a float accumulation's; u32 holds them up to
    // windows of 257x257.
    let (mut sa, mut sb, mut saa, mut sbb, mut sab) = (0u32, 0u32, 0u32, 0u32, 0u32);
    let len = (2 * half + 1) as usize;
    for dy in -half..=half {
        let ra = ((ay + dy) * wa + ax - half) as usize;
        let rb = ((by + dy) * wb + bx - half) as usize;
        let (Some(row_a), Some(row_b)) = (ma.get(ra..ra + len), mb.get(rb..rb + len)) else {
            return None;
        };
        for (&x, &y) in row_a.iter().zip(row_b) {
            let (x, y) = (u32::from(x), u32::from(y));
            sa += x;
            sb += y;
            saa += x * x;
            sbb += y * y;
            sab += x * y;
        }
    }
    let (sa, sb, saa, sbb, sab) = (sa as f32, sb as f32, saa as f32, sbb as f32, sab as f32);
    let n = ((2 * half + 1) * (2 * half + 1)) as f32;
    let va = saa - sa * sa / n;
    let vb = sbb - sb * sb / n;
    if va <= 0.0 || vb <= 0.0 {
        return None;
    }
    Some((sab - sa * sb / n) / (va * vb).sqrt())
}

/// Guided matching for a left point without a descriptor match: searches `±search_px`
/// horizontally around the predicted right position `guess` (from neighbouring matches) for
/// the best correlation of the magnitude windows, requires it to beat every other local
/// maximum clearly, then refines it with [`refine_pair`].
pub fn guided_pair(
    left_plane: &SobelPlane,
    right_plane: &SobelPlane,
    left: [f32; 2],
    guess: [f32; 2],
    search_px: i32,
    config: &SubpixelConfig,
) -> Option<RefinedPair> {
    let half = config.half_window as i32;
    let (lx, ly) = (left[0].round() as i32, left[1].round() as i32);
    let gy = (guess[1] + (ly as f32 - left[1])).round() as i32;
    let gx = (guess[0] + (lx as f32 - left[0])).round() as i32;
    let scores: Vec<(i32, f32)> = (-search_px..=search_px)
        .filter_map(|dx| {
            Some((
                dx,
                ncc_at(left_plane, lx, ly, right_plane, gx + dx, gy, half)?,
            ))
        })
        .collect();
    let (best_i, &(best_dx, best)) = scores
        .iter()
        .enumerate()
        .max_by(|a, b| a.1 .1.total_cmp(&b.1 .1))?;
    // The strongest other local maximum of the correlation: a second peak means repetitive
    // texture along the search line.
    let runner_up = (0..scores.len())
        .filter(|&i| i != best_i)
        .filter(|&i| {
            let v = scores[i].1;
            (i == 0 || scores[i - 1].1 < v) && (i + 1 == scores.len() || scores[i + 1].1 <= v)
        })
        .map(|i| scores[i].1)
        .fold(-1.0f32, f32::max);
    if best < config.min_correlation || runner_up > best - GUIDED_PEAK_MARGIN {
        return None;
    }
    refine_pair(
        left_plane,
        right_plane,
        [lx as f32, ly as f32],
        [(gx + best_dx) as f32, gy as f32],
        config,
    )
}

/// A guided match's correlation peak must beat any other peak by this much (ambiguity test,
/// the analogue of the descriptor ratio test).
const GUIDED_PEAK_MARGIN: f32 = 0.1;

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth blob field sampled at a sub-pixel shift.
    fn plane(w: u32, h: u32, sx: f32, sy: f32, gain: f32) -> SobelPlane {
        let mut mag = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let (xf, yf) = (x as f32 - sx, y as f32 - sy);
                let v = 100.0
                    + 60.0 * (xf * 0.31).sin() * (yf * 0.23).cos()
                    + 40.0 * ((xf + 2.0 * yf) * 0.17).sin();
                mag.push((v * gain).round().clamp(0.0, 255.0) as u8);
            }
        }
        SobelPlane::new(0, w, h, mag, vec![0; (w * h) as usize]).unwrap()
    }

    #[test]
    fn recovers_a_subpixel_shift_under_a_gain_change() {
        let l = plane(80, 60, 0.0, 0.0, 1.0);
        let r = plane(80, 60, -3.37, 0.21, 0.9);
        let mut worst = 0f32;
        for &(x, y) in &[(30.3f32, 25.6f32), (40.0, 30.0), (50.7, 35.2)] {
            let got = refine_pair(
                &l,
                &r,
                [x, y],
                [x - 3.0, y + 0.5],
                &SubpixelConfig::default(),
            )
            .unwrap();
            let want = [got.left[0] - 3.37, got.left[1] + 0.21];
            worst = worst
                .max((got.right[0] - want[0]).abs())
                .max((got.right[1] - want[1]).abs());
        }
        // Quantisation to u8 limits the precision; a few hundredths of a pixel remain.
        assert!(worst < 0.05, "worst error {worst} px");
    }

    #[test]
    fn guided_search_finds_a_shift_beyond_the_lucas_kanade_basin() {
        let l = plane(100, 60, 0.0, 0.0, 1.0);
        let r = plane(100, 60, -6.4, 0.3, 1.0);
        let got = guided_pair(
            &l,
            &r,
            [50.0, 30.0],
            [47.0, 30.0],
            8,
            &SubpixelConfig::default(),
        )
        .unwrap();
        assert!((got.right[0] - (got.left[0] - 6.4)).abs() < 0.05, "{got:?}");
        assert!((got.right[1] - (got.left[1] + 0.3)).abs() < 0.05, "{got:?}");
    }

    #[test]
    fn rejects_featureless_and_border_windows() {
        let flat = SobelPlane::new(0, 40, 40, vec![50; 1600], vec![0; 1600]).unwrap();
        assert!(refine_pair(
            &flat,
            &flat,
            [20.0, 20.0],
            [20.0, 20.0],
            &SubpixelConfig::default()
        )
        .is_none());
        let l = plane(40, 40, 0.0, 0.0, 1.0);
        assert!(
            refine_pair(&l, &l, [3.0, 20.0], [3.0, 20.0], &SubpixelConfig::default()).is_none()
        );
    }
}
