//! The sub-pixel refinement with the right window's disparity gradient free
//! ([`SubpixelConfig::disparity_gradient`]): its fit and the sampler of the sheared windows it
//! reads.

use std::cell::Cell;

use nalgebra::{Matrix4, Vector4};

use super::{
    accepted, agreement, lane_sums, reached, residual_against, vector_block, with_buffer,
    RefinedPair, SubpixelConfig, CHANNELS,
};
use crate::features::SobelPlane;

thread_local! {
    /// [`refine_with_gradient`]'s steepest-descent images of the gradient, their products with
    /// the residual and its [`VectorCache`]'s block, kept per thread as the translation's
    /// working arrays are.
    static DESCENT: Cell<Vec<f32>> = const { Cell::new(Vec::new()) };
}

/// A refinement's template: its zero-mean windows of each channel, their gradients and its
/// norm, as [`refine_in`](super::refine_in) prepares them.
pub(super) struct Template<'a> {
    pub(super) values: &'a [f32],
    pub(super) gx: &'a [f32],
    pub(super) gy: &'a [f32],
    pub(super) norm: f32,
}

/// [`refine_in`](super::refine_in)'s iterations with the right window's disparity gradient free:
/// the window sample at offset `(u, v)` is read at `p + (u + a·u + b·v, v)`. A slanted surface's
/// disparity changes across a window (a road's by a quarter of a pixel per row on the KITTI drive),
/// so the right window is the left one sheared and scaled horizontally; a translation fitted
/// between them follows the texture's asymmetry, vertically too. Its gradient vectors turn with the
/// warp, so the right window's vectors are mapped by the warp's transpose before they are compared.
/// Inverse compositional, as the translation: the steepest-descent images `(gx·u, gx·v, gx, gy)`
/// and their Hessian are the template's, computed once. `scratch` holds three arrays of the
/// window's channels.
pub(super) fn refine_with_gradient(
    right_plane: &SobelPlane,
    [lx, ly]: [i32; 2],
    start: [f32; 2],
    template: &Template<'_>,
    scratch: [&mut [f32]; 3],
    config: &SubpixelConfig,
) -> Option<RefinedPair> {
    let half = config.half_window as i32;
    let side = config.window_side();
    let n = side * side;
    let [warped, squares, residual] = scratch;
    let len = CHANNELS * n;
    // The widest window the fit reads: the gradient keeps |a| + |b| below 1.
    let widest = [4 * side, side + 1];
    with_buffer(&DESCENT, 3 * len + VectorCache::len_for(widest), |buffer| {
        // The steepest-descent images of the gradient's two parameters, `gx·u` and `gx·v`,
        // beside the template's own `gx` and `gy` (the translation's).
        let (gxu, rest) = buffer.split_at_mut(len);
        let (gxv, rest) = rest.split_at_mut(len);
        let (products, reached) = rest.split_at_mut(len);
        let rows = gxu
            .chunks_exact_mut(side)
            .zip(gxv.chunks_exact_mut(side))
            .zip(template.gx.chunks_exact(side));
        // Rows of both channels, one channel after the other.
        for (r, ((row_u, row_v), row_gx)) in rows.enumerate() {
            let v = (r % side) as f32 - half as f32;
            for (u, ((du, dv), &x)) in row_u
                .iter_mut()
                .zip(row_v.iter_mut())
                .zip(row_gx)
                .enumerate()
            {
                *du = x * (u as f32 - half as f32);
                *dv = x * v;
            }
        }
        let images: [&[f32]; 4] = [gxu, gxv, template.gx, template.gy];
        let mut hessian = Matrix4::<f64>::zeros();
        for (r, a) in images.iter().enumerate() {
            for (c, b) in images.iter().enumerate().skip(r) {
                for (q, (&x, &y)) in products.iter_mut().zip(a.iter().zip(*b)) {
                    *q = x * y;
                }
                let [v] = lane_sums([&*products]);
                hessian[(r, c)] = f64::from(v);
                hessian[(c, r)] = f64::from(v);
            }
        }
        let inverse = hessian.try_inverse()?;
        let mut cache = VectorCache::new(right_plane, reached);
        let t = template.values;
        // The residual at translation `p` and gradient (a, b), as `refine_in`'s: the right
        // window (its vectors mapped back through the warp) zero-mean per channel, scaled to
        // the template's norm, less the template.
        let mut residual_at = |p: [f32; 2], a: f32, b: f32, e: &mut [f32]| {
            sample_sheared(&mut cache, p[0], p[1], half, [a, b], warped)?;
            let (wx, wy) = warped[..CHANNELS * n].split_at_mut(n);
            for (x, y) in wx.iter_mut().zip(wy.iter_mut()) {
                (*x, *y) = ((1.0 + a) * *x, b * *x + *y);
            }
            residual_against(&warped[..CHANNELS * n], t, template.norm, squares, e)
        };
        let (mut p, mut a, mut b) = (start, 0.0f32, 0.0f32);
        let reach = half as f32;
        let mut converged = false;
        for _ in 0..config.max_iterations {
            residual_at(p, a, b, residual)?;
            let e = &residual[..len];
            let g = Vector4::from(images.map(|image| {
                // Products first (they vectorise), then sums in interleaved lanes.
                for (q, (&x, &r)) in products.iter_mut().zip(image.iter().zip(e)) {
                    *q = x * r;
                }
                let [sum] = lane_sums([&*products]);
                f64::from(sum)
            }));
            let d = (inverse * g).map(|v| v as f32);
            let (da, db, dx, dy) = (d[0], d[1], d[2], d[3]);
            // W ← W ∘ W(Δ)⁻¹ for W(x) = A·x + p, A = [[1 + a, b], [0, 1]].
            let scale = (1.0 + a) / (1.0 + da);
            b -= scale * db;
            a = scale - 1.0;
            p[0] -= scale * dx + b * dy;
            p[1] -= dy;
            // A gradient that moves the window's edge columns by more than its half side has
            // folded the window or left the surface it sat on.
            if (p[0] - start[0]).abs() > config.max_shift_px
                || (p[1] - start[1]).abs() > config.max_shift_px
                || a.abs() + b.abs() >= 1.0
            {
                return None;
            }
            // Every sample moved by under a thousandth of a pixel, as the translation's stop.
            if dx * dx + dy * dy + (da * da + db * db) * reach * reach < 1e-6 {
                converged = true;
                break;
            }
        }
        if !converged {
            return None;
        }
        residual_at(p, a, b, residual)?;
        let (ncc, sse) = agreement(&residual[..len], t, template.norm, [squares, products]);
        // Degrees of freedom: the samples less the translation, the gradient, the gain and an
        // offset per channel.
        let noise_var = f64::from(sse) / ((CHANNELS * n) as f64 - 5.0 - CHANNELS as f64);
        let sigma_v = (noise_var * inverse[(3, 3)]).sqrt() as f32;
        accepted(ncc, sigma_v, [lx, ly], p, config)
    })
}

/// A block of a plane's Sobel vectors converted once for the many windows a refinement reads
/// around one point: each step moves its window by a fraction of a pixel and changes its
/// shape slightly, so the pixels it reaches are mostly those of the step before.
struct VectorCache<'a> {
    plane: &'a SobelPlane,
    /// The block's vectors, one channel after the other, and room for one row of them blended
    /// between two rows.
    buffer: &'a mut [f32],
    /// The top-left pixel and the size of the block held, once converted.
    held: Option<([usize; 2], [usize; 2])>,
}

impl<'a> VectorCache<'a> {
    /// Columns (each side) and rows (above and below) converted beyond what a window reaches,
    /// so that the next steps' windows, a fraction of a pixel away, stay inside the block.
    const MARGIN: [usize; 2] = [2, 1];

    /// The buffer's length for windows reaching at most `cols` x `rows` pixels.
    fn len_for([cols, rows]: [usize; 2]) -> usize {
        let [mx, my] = Self::MARGIN;
        let (bw, bh) = (cols + 2 * mx, rows + 2 * my);
        CHANNELS * (bw * bh + bw)
    }

    fn new(plane: &'a SobelPlane, buffer: &'a mut [f32]) -> Self {
        Self {
            plane,
            buffer,
            held: None,
        }
    }

    /// Holds the vectors of pixels `cols` x `rows` (inside the plane), converting a block
    /// around them when the one held does not cover them; `None` when the block would not
    /// fit the buffer.
    fn cover(&mut self, cols: [usize; 2], rows: [usize; 2]) -> Option<()> {
        let inside = |([x0, y0], [bw, bh]): ([usize; 2], [usize; 2])| {
            x0 <= cols[0] && cols[1] <= x0 + bw && y0 <= rows[0] && rows[1] <= y0 + bh
        };
        if self.held.is_some_and(inside) {
            return Some(());
        }
        let [mx, my] = Self::MARGIN;
        let (w, h) = (self.plane.width() as usize, self.plane.height() as usize);
        let origin = [cols[0].saturating_sub(mx), rows[0].saturating_sub(my)];
        let end = [(cols[1] + mx).min(w), (rows[1] + my).min(h)];
        let size = [end[0] - origin[0], end[1] - origin[1]];
        if CHANNELS * (size[0] * size[1] + size[0]) > self.buffer.len() {
            return None;
        }
        vector_block(self.plane, origin, size, self.buffer);
        self.held = Some((origin, size));
        Some(())
    }
}

/// Fraction bits of [`sample_sheared`]'s sample positions: a 65536th of a pixel, and the
/// step's rounding over a window's row is a few ten-thousandths, far below the thousandth the
/// fit stops at.
const POSITION_BITS: u32 = 16;

/// [`sample_warped`](super::sample_warped) through a warp that keeps rows, `(u, v) ↦ (u + a·u +
/// b·v, v)` for the disparity gradient `[a, b]`, reading the vectors from `cache`. Every sample of
/// the window then shares one vertical interpolation weight, so each row is blended between its two
/// source rows once, over the columns it reaches (in whole vectors), and each sample is one
/// horizontal blend of that row. `None` when the window leaves the plane or touches a lost row.
fn sample_sheared(
    cache: &mut VectorCache<'_>,
    x: f32,
    y: f32,
    half: i32,
    [a, b]: [f32; 2],
    out: &mut [f32],
) -> Option<()> {
    let p = cache.plane;
    let h = half as f32;
    // Inside the plane, so the ranges are of pixels.
    let [cols, rows] = reached(p, [x, y], [((1.0 + a).abs() + b.abs()) * h, h])?
        .map(|r| [r.start as usize, r.end as usize]);
    cache.cover(cols, rows)?;
    let ([x0, y0], [bw, bh]) = cache.held?;
    let (block, blended) = cache.buffer.split_at_mut(CHANNELS * bw * bh);
    let ty = (y - h) - (y - h).floor();
    let side = (2 * half + 1) as usize;
    let (out_x, out_y) = out[..CHANNELS * side * side].split_at_mut(side * side);
    let rows_out = out_x
        .chunks_exact_mut(side)
        .zip(out_y.chunks_exact_mut(side));
    let scale = (1u32 << POSITION_BITS) as f32;
    let step = 1.0 + a;
    let step_fixed = (step * scale).round() as i32;
    let (line_x, line_y) = blended.split_at_mut(bw);
    for (r, (row_x, row_y)) in rows_out.enumerate() {
        let dy = r as f32 - h;
        // The row's samples run from `first` by `step`; the columns between them, blended
        // between the row's two source rows.
        let first = x - step * h + b * dy;
        let last = first + 2.0 * step * h;
        let (c0, c1) = (
            (first.min(last) as usize).max(x0) - x0,
            (first.max(last) as usize + 2).min(x0 + bw) - x0,
        );
        let top = (rows[0] + r - y0) * bw;
        let (block_x, block_y) = block.split_at(bw * bh);
        for (line, src) in [(&mut *line_x, block_x), (&mut *line_y, block_y)] {
            let (upper, lower) = (&src[top + c0..top + c1], &src[top + bw + c0..top + bw + c1]);
            for (l, (&u, &d)) in line.iter_mut().zip(upper.iter().zip(lower)) {
                *l = u + ty * (d - u);
            }
        }
        let (lx, ly) = (&line_x[..c1 - c0], &line_y[..c1 - c0]);
        // Positions in fixed point, so that a sample's column is a shift (no float-to-integer
        // conversion per sample); one position serves both channels.
        let mut at = ((first - (x0 + c0) as f32) * scale).round() as i32;
        for (ox, oy) in row_x.iter_mut().zip(row_y.iter_mut()) {
            // Every sample lies within the row's columns; the bounds hold a rounding at their
            // edges.
            let i = ((at.max(0) >> POSITION_BITS) as usize).min(lx.len() - 2);
            let t = (at - ((i as i32) << POSITION_BITS)) as f32 / scale;
            *ox = lx[i] + t * (lx[i + 1] - lx[i]);
            *oy = ly[i] + t * (ly[i + 1] - ly[i]);
            at += step_fixed;
        }
    }
    Some(())
}
