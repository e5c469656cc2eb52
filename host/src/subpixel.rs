//! Sub-pixel refinement of matches on the octave-0 Sobel planes.
//!
//! A verge change of 0.01° moves points vertically by only `u·v·Δα/f`, a few hundredths of a
//! pixel at the image corners, while DoG extrema are localised to a few tenths of a pixel
//! (and at 2ᵒ-pixel steps in octave `o`). So each match is re-localised: the left point is
//! snapped to its nearest octave-0 pixel, and the right point is moved to where a window of
//! the right plane's Sobel vectors (each pixel's magnitude along its orientation code) best
//! matches the left window (Lucas-Kanade, inverse-compositional, with gain and offset
//! compensation, since the two cameras' exposures differ; `refine_in` says why vectors). The
//! right window is not a translated copy of the left one on a verged head: turning a camera by
//! the verge maps its image by a homography, which stretches and shears a window by several per
//! cent at 10-20° (the horizontal scale is 1/cos² of the angle off the axis), and a
//! translation fitted across such a window moves with the texture's asymmetry. So the left
//! window (the template) is sampled through the inverse of the homography's local linear map
//! (the caller's [`Warp`]), which makes it the right window's shape, and only the translation
//! of the right window is estimated; the template is sampled once per match, so the
//! iterations keep the translated window's fast sampling. Only the geometry of the point pair
//! matters to the estimator, so fixing the left point at an integer pixel loses nothing and
//! keeps the interpolation on one side.
//!
//! Matches whose window has too little vertical structure (the vertical position would be
//! uncertain), that do not converge, that move too far or whose windows do not agree after
//! alignment are rejected.

use std::cell::Cell;
use std::ops::Range;
use std::sync::LazyLock;
use std::thread::LocalKey;

use crate::features::{SobelPlane, ORIENTATION_STEPS};

mod gradient;

use gradient::{refine_with_gradient, Template};

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
    /// Also fit the right window's horizontal scale and shear, the local gradient of the
    /// disparity (README, "Disparity gradient"), beside its translation.
    pub disparity_gradient: bool,
}

impl Default for SubpixelConfig {
    fn default() -> Self {
        Self {
            // A 15x15 window, the largest whose sums in `SearchLine::magnitudes` stay exact in
            // `f32` (225 · 255² < 2^24 < 289 · 255²).
            half_window: 7,
            // The inverse-compositional steps converge within a few iterations from a start
            // inside the window; halving or doubling the bound moves the rendered road's raw
            // median error by < 0.0002° and the KITTI drive's by < 0.008°
            // (README, "Sensitivity of the constants").
            max_iterations: 12,
            // Two pixels: the most a match between octave-1 keypoints starts from its true
            // place (each lies within a pixel of its blob on that octave's 2 px grid). Halving
            // or doubling it moves the rendered road's raw median error by < 0.0002° and the
            // KITTI drive's by < 0.007°.
            max_shift_px: 2.0,
            // Halving or doubling it moves the rendered road's raw median error by < 0.0001°
            // and the KITTI drive's by < 0.002°.
            max_sigma_v_px: 0.15,
            // 0.7 or 0.9 moves the rendered road's raw median error by < 0.0005° and the
            // KITTI drive's by < 0.007°.
            min_correlation: 0.8,
            // Translation only: on the KITTI drive the free gradient raises the injected
            // trajectories' errors (README, "Disparity gradient").
            disparity_gradient: false,
        }
    }
}

impl SubpixelConfig {
    /// The window's side in pixels, `2·half_window + 1`.
    pub fn window_side(&self) -> usize {
        self.half_window.saturating_mul(2).saturating_add(1)
    }

    /// How far from a keypoint's nearest full-resolution pixel, in rows and in columns, the
    /// refinement of a match there may read: half the window, the largest shift, a pixel for
    /// the template's border (its central differences) or the right window's bilinear
    /// neighbours, and one for the start's rounding to that pixel. A pixel the link lost
    /// within it costs the match.
    pub fn reach_px(&self) -> usize {
        let shift = self.max_shift_px.max(0.0).ceil() as usize;
        self.half_window.saturating_add(shift).saturating_add(2)
    }
}

/// The local linear map from the left window's offsets to the right window's, row-major:
/// `[dx_r, dy_r] = [[a, b], [c, d]] · [dx_l, dy_l]`. The identity on a parallel head.
pub type Warp = [f32; 4];

/// The identity [`Warp`]: the right window a translated copy of the left one.
pub const IDENTITY: Warp = [1.0, 0.0, 0.0, 1.0];

/// A warp whose largest displacement of a window sample, against the identity's, stays below
/// this (pixels) is taken as the identity: the template is then read from whole pixels, with
/// no interpolation, and a hundredth of a pixel at the window's edge is below what the
/// refinement resolves (the u8 magnitudes limit it to a few hundredths).
const WARP_NEGLIGIBLE_PX: f32 = 0.01;

/// A bound on how far `warp` moves a sample of a window of half side `half` from where the
/// identity puts it (pixels): the map's deviation from the identity, summed, times `half`.
fn deformation_px(warp: &Warp, half: i32) -> f32 {
    let [a, b, c, d] = *warp;
    ((a - 1.0).abs() + b.abs() + c.abs() + (d - 1.0).abs()) * half as f32
}

/// The inverse of `warp`; `None` when it is singular (or not finite).
fn inverse(warp: &Warp) -> Option<Warp> {
    let [a, b, c, d] = *warp;
    let det = a * d - b * c;
    (det.is_finite() && det.abs() > f32::EPSILON).then(|| [d / det, -b / det, -c / det, a / det])
}

/// The shifts `dx` within `±search` for which the window of half side `half` centred on
/// column `bx + dx` lies inside `plane`'s columns: one contiguous range, `None` when empty.
fn shifts_inside(plane: &SobelPlane, bx: i64, search: i64, half: i64) -> Option<(i64, i64)> {
    let lo = (-search).max(half - bx);
    let hi = search.min(i64::from(plane.width()) - 1 - half - bx);
    (lo <= hi).then_some((lo, hi))
}

/// A warp that moves the window's edge by this much or more (pixels) is searched through:
/// a whole-pixel scan of the unwarped window aligns its centre, but not its edges to within
/// the half pixel of its own step. At a large verge the edges of the image stretch by tens
/// of per cent between the views, well beyond it; the KITTI drive's 0.6° moves them by at most
/// about 0.2 px, within it.
const SCAN_WARP_PX: f32 = 0.5;

/// A refined point pair in octave-0 (full-resolution) pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RefinedPair {
    /// The left point `(x, y)`, snapped to its nearest octave-0 pixel.
    pub left: [f32; 2],
    /// The right point `(x, y)` where its window best matches the left one.
    pub right: [f32; 2],
    /// Estimated 1-σ vertical position error of `right` (pixels).
    pub sigma_v: f32,
}

/// Channels of a refinement window: the two components of the Sobel vector.
const CHANNELS: usize = 2;

/// The unit vector of each orientation code, `(cos, sin)` of `code · 5.625°` measured from +x
/// toward +y (the fabric's CORDIC bins).
fn directions() -> &'static [[f32; 2]; ORIENTATION_STEPS as usize] {
    static TABLE: LazyLock<[[f32; 2]; ORIENTATION_STEPS as usize]> = LazyLock::new(|| {
        std::array::from_fn(|code| {
            let angle = code as f32 * std::f32::consts::TAU / f32::from(ORIENTATION_STEPS);
            [angle.cos(), angle.sin()]
        })
    });
    &TABLE
}

/// The Sobel vector `magnitude · (cos, sin)` of pixel `i` of a plane's magnitudes and
/// orientation codes, `dirs` being [`directions`].
#[inline]
fn vector_at(
    magnitude: &[u8],
    orientation: &[u8],
    dirs: &[[f32; 2]; ORIENTATION_STEPS as usize],
    i: usize,
) -> [f32; 2] {
    let [c, s] = dirs[usize::from(orientation[i] & (ORIENTATION_STEPS - 1))];
    let m = f32::from(magnitude[i]);
    [m * c, m * s]
}

/// The `width` x `height` block of `p`'s Sobel vectors whose top-left pixel is (`x0`, `y0`)
/// into `out`, one channel after the other; the block lies inside the plane.
fn vector_block(
    p: &SobelPlane,
    [x0, y0]: [usize; 2],
    [width, height]: [usize; 2],
    out: &mut [f32],
) {
    let (m, o, stride) = (p.magnitude(), p.orientation(), p.width() as usize);
    let dirs = directions();
    let (cx, cy) = out[..CHANNELS * width * height].split_at_mut(width * height);
    let rows = cx.chunks_exact_mut(width).zip(cy.chunks_exact_mut(width));
    for (r, (row_x, row_y)) in rows.enumerate() {
        let at = (y0 + r) * stride + x0;
        for (k, (vx, vy)) in row_x.iter_mut().zip(row_y.iter_mut()).enumerate() {
            [*vx, *vy] = vector_at(m, o, dirs, at + k);
        }
    }
}

/// Samples the `side` x `side` window of `p`'s Sobel vectors centred on (`x`, `y`) into `out`
/// (one channel after the other), bilinearly, with `block` for the vectors of the whole pixels
/// it reads. The window is a pure translation, so every sample shares one pair of fractional
/// weights: the bounds are checked once and the loop is four loads and a blend, over four
/// equal-length row slices so that it compiles to vector code without bounds checks. `None`
/// when the window (plus its interpolation neighbours) leaves the plane or touches a lost row.
///
/// `block_origin` is the top-left pixel whose block `block` holds, if any: the refinement's
/// later steps move the window by fractions of a pixel, mostly within the same whole pixels,
/// whose vectors are then not converted again.
fn sample_translated(
    p: &SobelPlane,
    x: f32,
    y: f32,
    half: i32,
    (block, block_origin): (&mut [f32], &mut Option<(i32, i32)>),
    out: &mut [f32],
) -> Option<()> {
    let (w, h) = (p.width() as i32, p.height() as i32);
    let (x0, y0) = ((x - half as f32).floor(), (y - half as f32).floor());
    let (ix, iy) = (x0 as i32, y0 as i32);
    let side = 2 * half + 1;
    if !(x0.is_finite() && y0.is_finite()) || ix < 0 || iy < 0 || ix + side >= w || iy + side >= h {
        return None;
    }
    if !p.window_valid(
        i64::from(ix)..i64::from(ix + side + 1),
        i64::from(iy)..i64::from(iy + side + 1),
    ) {
        return None;
    }
    let (fx, fy) = (x - half as f32 - x0, y - half as f32 - y0);
    let (w00, w01) = ((1.0 - fx) * (1.0 - fy), fx * (1.0 - fy));
    let (w10, w11) = ((1.0 - fx) * fy, fx * fy);
    let (side, span) = (side as usize, side as usize + 1);
    if *block_origin != Some((ix, iy)) {
        vector_block(p, [ix as usize, iy as usize], [span, span], block);
        *block_origin = Some((ix, iy));
    }
    let channels = block
        .chunks_exact(span * span)
        .zip(out.chunks_exact_mut(side * side));
    for (src, dst) in channels {
        for (r, row_out) in dst.chunks_exact_mut(side).enumerate() {
            let top = &src[r * span..][..span];
            let bottom = &src[(r + 1) * span..][..span];
            let corners = top[..side]
                .iter()
                .zip(&top[1..])
                .zip(&bottom[..side])
                .zip(&bottom[1..]);
            for (o, (((&a, &b), &c), &d)) in row_out.iter_mut().zip(corners) {
                *o = w00 * a + w01 * b + w10 * c + w11 * d;
            }
        }
    }
    Some(())
}

/// The columns and rows of the pixels a window centred on `(x, y)` reads when its samples
/// reach `reach` pixels either way (horizontally, vertically), with the next pixel that their
/// interpolation reads; `None` when they leave `p` or touch a lost row.
fn reached(p: &SobelPlane, [x, y]: [f32; 2], reach: [f32; 2]) -> Option<[Range<i64>; 2]> {
    let [reach_x, reach_y] = reach;
    let (w, h) = (p.width() as f32, p.height() as f32);
    if !(x.is_finite() && y.is_finite())
        || x - reach_x < 0.0
        || y - reach_y < 0.0
        || x + reach_x + 1.0 >= w
        || y + reach_y + 1.0 >= h
    {
        return None;
    }
    let cols = (x - reach_x).floor() as i64..(x + reach_x).floor() as i64 + 2;
    let rows = (y - reach_y).floor() as i64..(y + reach_y).floor() as i64 + 2;
    p.window_valid(cols.clone(), rows.clone())
        .then_some([cols, rows])
}

/// [`sample_translated`] through `warp`: sample `(c, r)` of the window (offsets from its centre)
/// is taken at `(x, y) + warp · (c, r)`, each sample with its own interpolation weights.
/// `None` when the window leaves the plane or touches a lost row.
fn sample_warped(
    p: &SobelPlane,
    x: f32,
    y: f32,
    half: i32,
    warp: &Warp,
    out: &mut [f32],
) -> Option<()> {
    let [a, b, c, d] = *warp;
    let h = half as f32;
    // The window's extreme sample positions are at its corners (the map is linear).
    let [cols, rows] = reached(
        p,
        [x, y],
        [(a.abs() + b.abs()) * h, (c.abs() + d.abs()) * h],
    )?;
    // The vectors of every pixel the window reaches, converted once: each is a corner of up to
    // four samples. The checks above keep the block inside the plane.
    let origin = [cols.start as usize, rows.start as usize];
    let [bw, bh] = [cols.end - cols.start, rows.end - rows.start].map(|n| n as usize);
    with_buffer(&REACHED, CHANNELS * bw * bh, |reached| {
        vector_block(p, origin, [bw, bh], reached);
        let (rx, ry) = reached.split_at(bw * bh);
        let side = (2 * half + 1) as usize;
        let (out_x, out_y) = out[..CHANNELS * side * side].split_at_mut(side * side);
        let rows = out_x
            .chunks_exact_mut(side)
            .zip(out_y.chunks_exact_mut(side));
        for (r, (row_x, row_y)) in rows.enumerate() {
            let dy = r as f32 - h;
            let (mut sx, mut sy) = (x - a * h + b * dy, y - c * h + d * dy);
            for (ox, oy) in row_x.iter_mut().zip(row_y.iter_mut()) {
                // Every sample lies within the window's reach (truncation is the floor there,
                // without a call to `floorf`); the bounds hold a rounding at its edges in the
                // block.
                let bx = (sx as usize).saturating_sub(origin[0]).min(bw - 2);
                let by = (sy as usize).saturating_sub(origin[1]).min(bh - 2);
                let (tx, ty) = (sx - (origin[0] + bx) as f32, sy - (origin[1] + by) as f32);
                let at = by * bw + bx;
                let blend = |c: &[f32]| {
                    let top = c[at] + tx * (c[at + 1] - c[at]);
                    let bottom = c[at + bw] + tx * (c[at + bw + 1] - c[at + bw]);
                    top + ty * (bottom - top)
                };
                (*ox, *oy) = (blend(rx), blend(ry));
                sx += a;
                sy += c;
            }
        }
    });
    Some(())
}

/// One row of the template and its central-difference gradients: `row` is the template row
/// with one sample of border each side, `above` and `below` the rows around it.
fn template_row(
    row: &[f32],
    above: &[f32],
    below: &[f32],
    t_row: &mut [f32],
    gx_row: &mut [f32],
    gy_row: &mut [f32],
) {
    let horizontal = row.iter().zip(&row[1..]).zip(&row[2..]);
    let cells = t_row
        .iter_mut()
        .zip(gx_row.iter_mut())
        .zip(gy_row.iter_mut());
    for ((((tv, gxv), gyv), ((&l, &c), &r)), (&a, &b)) in
        cells.zip(horizontal).zip(above.iter().zip(below))
    {
        *tv = c;
        *gxv = 0.5 * (r - l);
        *gyv = 0.5 * (b - a);
    }
}

thread_local! {
    /// [`sample_warped`]'s block of the vectors its window reaches, kept per thread as
    /// [`SCRATCH`] is.
    static REACHED: Cell<Vec<f32>> = const { Cell::new(Vec::new()) };
    /// [`refine_pair`]'s working arrays, kept per thread between calls: a match needs seven
    /// arrays of a window's channels and a block of pixels, and taking them from here spares
    /// their allocation (or the zeroing of stack arrays) per match. Every array is written
    /// before it is read, so what a previous match left in them never matters, and any
    /// configured window size gets the same path.
    static SCRATCH: Cell<Vec<f32>> = const { Cell::new(Vec::new()) };
}

/// Refines one match: `left` / `right` in full-resolution pixels, `warp` the local map from the
/// left window to the right one ([`IDENTITY`] on a parallel head). `None` when rejected.
pub fn refine_pair(
    left_plane: &SobelPlane,
    right_plane: &SobelPlane,
    left: [f32; 2],
    right: [f32; 2],
    warp: &Warp,
    config: &SubpixelConfig,
) -> Option<RefinedPair> {
    let half = i32::try_from(config.half_window).ok()?;
    let (lx, ly) = (left[0].round() as i32, left[1].round() as i32);
    let (w, h) = (left_plane.width() as i32, left_plane.height() as i32);
    if lx - half - 1 < 0 || ly - half - 1 < 0 || lx + half + 1 >= w || ly + half + 1 >= h {
        return None;
    }
    // The template and its central differences read one row beyond the window each side.
    if !left_plane.window_valid(
        i64::from(lx - half - 1)..i64::from(lx + half + 2),
        i64::from(ly - half - 1)..i64::from(ly + half + 2),
    ) {
        return None;
    }
    // Inside the plane, so the window side is small enough for any arithmetic below.
    let side = config.window_side();
    let len = CHANNELS * (SCRATCH_ARRAYS * side * side + (side + 2) * (side + 2));
    let warp = (deformation_px(warp, half) >= WARP_NEGLIGIBLE_PX).then_some(warp);
    with_buffer(&SCRATCH, len, |scratch| {
        refine_in(
            left_plane,
            right_plane,
            left,
            [lx, ly],
            right,
            warp,
            config,
            scratch,
        )
    })
}

/// `f` on the first `len` elements of the thread's buffer `cell`, grown to `len` first when
/// shorter; the buffer stays with the thread for the next call.
fn with_buffer<R>(
    cell: &'static LocalKey<Cell<Vec<f32>>>,
    len: usize,
    f: impl FnOnce(&mut [f32]) -> R,
) -> R {
    let mut buffer = cell.take();
    if buffer.len() < len {
        buffer.resize(len, 0.0);
    }
    let out = f(&mut buffer[..len]);
    cell.set(buffer);
    out
}

/// Window-sized arrays [`refine_in`] works in, each [`CHANNELS`] windows long (besides the
/// bordered block of whole pixels).
const SCRATCH_ARRAYS: usize = 7;

/// The sum of each of `arrays`, taken in eight interleaved partial sums that are added
/// pairwise at the end. A sum taken element by element waits on its previous add at every
/// step, and the refinement's few window sums per iteration were most of its time that way;
/// partial sums in whole vectors take a fraction of it. The result is the same sum rounded
/// differently (a different order of float adds, `f32` as before), which moves a refined point
/// by far less than its own uncertainty. The element-wise terms are computed beforehand in
/// passes over whole arrays, which vectorise.
fn lane_sums<const K: usize>(arrays: [&[f32]; K]) -> [f32; K] {
    const LANES: usize = 8;
    let n = arrays.iter().map(|a| a.len()).min().unwrap_or(0);
    let mut acc = [[0.0f32; LANES]; K];
    let whole = n / LANES * LANES;
    for i in (0..whole).step_by(LANES) {
        for (lanes, array) in acc.iter_mut().zip(&arrays) {
            for (l, v) in lanes.iter_mut().zip(&array[i..i + LANES]) {
                *l += v;
            }
        }
    }
    for (lanes, array) in acc.iter_mut().zip(&arrays) {
        for (l, v) in lanes.iter_mut().zip(&array[whole..n]) {
            *l += v;
        }
    }
    acc.map(|l| ((l[0] + l[4]) + (l[1] + l[5])) + ((l[2] + l[6]) + (l[3] + l[7])))
}

/// The mean of each channel of `window` (channels of equal length, one after the other) and
/// the norm of the deviations from them, with `squares` (as long as `window`) for the squared
/// deviations.
fn means_and_norm(window: &[f32], squares: &mut [f32]) -> ([f32; CHANNELS], f32) {
    let n = window.len() / CHANNELS;
    let mut means = [0.0; CHANNELS];
    for ((mean, channel), sq) in means
        .iter_mut()
        .zip(window.chunks_exact(n))
        .zip(squares.chunks_exact_mut(n))
    {
        let [sum] = lane_sums([channel]);
        *mean = sum / n as f32;
        for (o, &v) in sq.iter_mut().zip(channel) {
            *o = (v - *mean).powi(2);
        }
    }
    let [sq] = lane_sums([&squares[..window.len()]]);
    (means, sq.sqrt())
}

/// [`refine_pair`] with the left point snapped to `[lx, ly]`, whose window plus a one-pixel
/// border lies inside the plane, `warp` `None` for the identity, and `buffer` [`CHANNELS`]
/// times [`SCRATCH_ARRAYS`] window sizes and one bordered window long.
///
/// The windows are of Sobel vectors, both components of each pixel's gradient, not of its
/// magnitude alone. The magnitude is a non-linear function of the image, which folds a
/// scene's fine structure into frequencies the pixel grid aliases, and the aliasing of a
/// window shifted by a fraction of a pixel is an error of that shift; the components are linear
/// in the image, and their orientation codes carry where an edge runs, which a magnitude
/// window does not. On real images shifted exactly by a fraction of a pixel, the rms error of a
/// refined vertical position is 0.035-0.043 px on vectors against 0.05-0.07 px on magnitudes
/// (README, "How much of a match's vertical position is the pixels' own bias"). One gain (an
/// exposure scales both components alike) and an offset per component relate the windows.
#[allow(clippy::too_many_arguments)]
fn refine_in(
    left_plane: &SobelPlane,
    right_plane: &SobelPlane,
    left: [f32; 2],
    [lx, ly]: [i32; 2],
    right: [f32; 2],
    warp: Option<&Warp>,
    config: &SubpixelConfig,
    buffer: &mut [f32],
) -> Option<RefinedPair> {
    let half = config.half_window as i32;
    let side = config.window_side();
    let n = side * side;
    let (windows, block) = buffer.split_at_mut(SCRATCH_ARRAYS * CHANNELS * n);
    // Template, its two gradients, the warped right window and three arrays of terms.
    let mut arrays = windows.chunks_exact_mut(CHANNELS * n);
    let [t, gx, gy, warped, p0, p1, p2] =
        std::array::from_fn(|_| arrays.next().unwrap_or_default());
    // The template with a one-pixel border: the left plane's pixels or, through a warp, its
    // window sampled through the warp's inverse (in the right image's frame).
    match warp {
        None => vector_block(
            left_plane,
            [(lx - half - 1) as usize, (ly - half - 1) as usize],
            [side + 2, side + 2],
            block,
        ),
        Some(warp) => {
            let inverse = inverse(warp)?;
            sample_warped(left_plane, lx as f32, ly as f32, half + 1, &inverse, block)?;
        }
    }
    // Template, its gradient (central differences) and zero-mean form per channel. Row slices
    // (the row with its left and right neighbours, the rows above and below) let the loop run
    // without bounds checks.
    let stride = side + 2;
    let channels = block
        .chunks_exact(stride * stride)
        .zip(t.chunks_exact_mut(n))
        .zip(gx.chunks_exact_mut(n).zip(gy.chunks_exact_mut(n)));
    for ((src, t), (gx, gy)) in channels {
        let cells = t
            .chunks_exact_mut(side)
            .zip(gx.chunks_exact_mut(side))
            .zip(gy.chunks_exact_mut(side));
        for (r, ((t_row, gx_row), gy_row)) in cells.enumerate() {
            let row = &src[(r + 1) * stride..][..stride];
            let above = &src[r * stride + 1..][..side];
            let below = &src[(r + 2) * stride + 1..][..side];
            template_row(row, above, below, t_row, gx_row, gy_row);
        }
    }
    let (t_means, t_norm) = means_and_norm(t, p0);
    for (channel, mean) in t.chunks_exact_mut(n).zip(t_means) {
        channel.iter_mut().for_each(|v| *v -= mean);
    }
    for ((xx, xy), (yy, (&x, &y))) in p0
        .iter_mut()
        .zip(p1.iter_mut())
        .zip(p2.iter_mut().zip(gx.iter().zip(gy.iter())))
    {
        *xx = x * x;
        *xy = x * y;
        *yy = y * y;
    }
    let [hxx, hxy, hyy] = lane_sums([&*p0, &*p1, &*p2]);
    let det = hxx * hyy - hxy * hxy;
    // Only a guard of the solve against a singular structure tensor (a flat window, or one of
    // a single edge direction): det / trace² is about its small eigenvalue over its large one,
    // and 1e-6 of trace² is at least thirty times f32's rounding of det (ε · hxx · hyy, at most
    // ε · trace² / 4). Whether the vertical structure suffices is `max_sigma_v_px`'s to judge,
    // at the solution.
    if det.is_nan() || det <= 1e-6 * (hxx + hyy).powi(2) || t_norm <= 0.0 {
        return None;
    }
    // The right plane's block of vectors: none converted yet (the block held the template's).
    let mut block_origin = None;
    // The right window, zero-mean per channel and scaled to the template's norm, less the
    // template: the residual at `p`, into `residual`. `None` when the window leaves the plane
    // or is flat.
    let mut residual_at = |p: [f32; 2], residual: &mut [f32], scratch: &mut [f32]| {
        sample_translated(
            right_plane,
            p[0],
            p[1],
            half,
            (&mut *block, &mut block_origin),
            warped,
        )?;
        residual_against(warped, t, t_norm, scratch, residual)
    };
    // Start: the right point shifted by what the left one was snapped, mapped by the warp.
    let [a, b, c, d] = *warp.unwrap_or(&IDENTITY);
    let (sx, sy) = (lx as f32 - left[0], ly as f32 - left[1]);
    let start = [right[0] + a * sx + b * sy, right[1] + c * sx + d * sy];
    if config.disparity_gradient {
        let template = Template {
            values: t,
            gx,
            gy,
            norm: t_norm,
        };
        return refine_with_gradient(
            right_plane,
            [lx, ly],
            start,
            &template,
            [warped, p0, p1],
            config,
        );
    }
    let mut p = start;
    let mut converged = false;
    for _ in 0..config.max_iterations {
        residual_at(p, p2, p0)?;
        for ((ox, oy), (&e, (&x, &y))) in p0
            .iter_mut()
            .zip(p1.iter_mut())
            .zip(p2.iter().zip(gx.iter().zip(gy.iter())))
        {
            *ox = x * e;
            *oy = y * e;
        }
        let [bx, by] = lane_sums([&*p0, &*p1]);
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
        // A step under a thousandth of a pixel: well below the few hundredths the u8
        // magnitudes resolve.
        if dx * dx + dy * dy < 1e-6 {
            converged = true;
            break;
        }
    }
    if !converged {
        return None;
    }
    // Quality at the solution: correlation and the vertical position uncertainty.
    residual_at(p, p2, p0)?;
    let (ncc, sse) = agreement(p2, t, t_norm, [p0, p1]);
    // The residual's degrees of freedom: the samples of every channel less the parameters
    // fitted (the two of the translation, the gain and an offset per channel).
    let noise_var = sse / ((CHANNELS * n) as f32 - 3.0 - CHANNELS as f32);
    let sigma_v = (noise_var * hxx / det).sqrt();
    accepted(ncc, sigma_v, [lx, ly], p, config)
}

/// How well an aligned right window agrees with the template `t` (zero-mean, of norm `norm`),
/// from `residual`, the right window scaled to the template's norm less the template: their
/// normalised cross-correlation and the residual's sum of squares. `scratch` holds two arrays
/// as long as the residual.
fn agreement(residual: &[f32], t: &[f32], norm: f32, scratch: [&mut [f32]; 2]) -> (f32, f32) {
    let [dots, squares] = scratch;
    for ((od, os), (&e, &tv)) in dots
        .iter_mut()
        .zip(squares.iter_mut())
        .zip(residual.iter().zip(t))
    {
        *od = (e + tv) * tv;
        *os = e * e;
    }
    let [dot, sse] = lane_sums([&*dots, &*squares]);
    (dot / (norm * norm), sse)
}

/// The right window `window` (channels of equal length, one after the other) zero-mean per
/// channel and scaled to the norm `t_norm` of the zero-mean template `t`, less the template,
/// into `residual`, with `squares` (as long as the window) for its squared deviations. `None`
/// when the window is flat.
fn residual_against(
    window: &[f32],
    t: &[f32],
    t_norm: f32,
    squares: &mut [f32],
    residual: &mut [f32],
) -> Option<()> {
    let n = window.len() / CHANNELS;
    let (means, norm) = means_and_norm(window, squares);
    if norm <= 0.0 {
        return None;
    }
    let rows = residual
        .chunks_exact_mut(n)
        .zip(window.chunks_exact(n).zip(t.chunks_exact(n)));
    let gain = t_norm / norm;
    for ((res, (w, t)), mean) in rows.zip(means) {
        for (e, (&wv, &tv)) in res.iter_mut().zip(w.iter().zip(t)) {
            *e = (wv - mean) * gain - tv;
        }
    }
    Some(())
}

/// The refined match of the left pixel `[lx, ly]` and the right point `right` when it passes
/// the quality gates: its windows correlate at least `min_correlation` once aligned, and its
/// vertical position's 1-σ is known and at most `max_sigma_v_px`.
fn accepted(
    ncc: f32,
    sigma_v: f32,
    [lx, ly]: [i32; 2],
    right: [f32; 2],
    config: &SubpixelConfig,
) -> Option<RefinedPair> {
    (ncc >= config.min_correlation && sigma_v <= config.max_sigma_v_px).then_some(RefinedPair {
        left: [lx as f32, ly as f32],
        right,
        sigma_v,
    })
}

/// A guided search: the window of half side `half` of the left plane centred on `left`
/// against the right plane's windows centred on (`guess[0] + dx`, `guess[1]`) for `dx` in
/// `-search..=search`, as [`SearchLine::magnitudes`] or [`SearchLine::through`] a warp
/// correlates them.
struct SearchLine<'a> {
    left_plane: &'a SobelPlane,
    left: [i32; 2],
    right_plane: &'a SobelPlane,
    guess: [i32; 2],
    search: i32,
    half: i32,
}

impl SearchLine<'_> {
    /// The windows' side in pixels.
    fn side(&self) -> usize {
        (2 * self.half + 1) as usize
    }

    /// Whether the right window centred on column `x` of the guess's row touches no pixel the
    /// link lost.
    fn right_valid(&self, x: i64) -> bool {
        let [y, half] = [self.guess[1], self.half].map(i64::from);
        self.right_plane
            .window_valid(x - half..x + half + 1, y - half..y + half + 1)
    }

    /// Normalised cross-correlations of the left window's magnitudes with each right window's,
    /// in `dx` order; positions whose window leaves its plane or touches a pixel the link lost,
    /// or where either window is flat, are left out.
    ///
    /// Every sum is an integer sum, exact in any order, so each value equals a direct
    /// per-position computation bit for bit (see the tests); what differs is that the left
    /// window's sums are taken once, and the right windows' sums come from per-column sums of
    /// the search strip instead of each position's full window, leaving only the cross products
    /// per position, taken over zero-padded copies of the rows in whole vectors. Up to the
    /// default 15x15 window every sum stays below 2^24 (225 products of at most 255²), so they
    /// convert to `f32` exactly; u32 holds them up to windows of 257x257. Products are taken in
    /// `u16` (255² fits), which the compiler vectorises with plain SSE2.
    fn magnitudes(&self) -> Vec<(i32, f32)> {
        let (a, b) = (self.left_plane, self.right_plane);
        let mut scores = Vec::new();
        let [[ax, ay], [bx, by]] = [self.left, self.guess].map(|p| p.map(i64::from));
        let [search, half] = [self.search, self.half].map(i64::from);
        let inside = |p: &SobelPlane, x: i64, y: i64| {
            x - half >= 0
                && y - half >= 0
                && x + half < i64::from(p.width())
                && y + half < i64::from(p.height())
        };
        // The right window lies inside its plane for one contiguous range of shifts; whether it
        // touches a pixel the link lost is each shift's own question.
        let Some((lo, hi)) = shifts_inside(b, bx, search, half) else {
            return scores;
        };
        if !inside(a, ax, ay)
            || !a.window_valid(ax - half..ax + half + 1, ay - half..ay + half + 1)
            || !inside(b, bx + lo, by)
        {
            return scores;
        }
        let len = self.side();
        let row_a = |r: usize| {
            let start = (ay - half) as usize + r;
            &a.magnitude()[start * a.width() as usize + (ax - half) as usize..][..len]
        };
        let strip_len = (hi - lo) as usize + len;
        let row_b = |r: usize| {
            let start = (by - half) as usize + r;
            &b.magnitude()[start * b.width() as usize + (bx + lo - half) as usize..][..strip_len]
        };
        let (mut sa, mut saa) = (0u32, 0u32);
        for r in 0..len {
            for &x in row_a(r) {
                sa += u32::from(x);
                saa += u32::from(u16::from(x) * u16::from(x));
            }
        }
        let (mut col_b, mut col_bb) = (vec![0u32; strip_len], vec![0u32; strip_len]);
        for r in 0..len {
            for ((s, ss), &y) in col_b.iter_mut().zip(col_bb.iter_mut()).zip(row_b(r)) {
                *s += u32::from(y);
                *ss += u32::from(u16::from(y) * u16::from(y));
            }
        }
        let n = (len * len) as f32;
        let (sa, saa) = (sa as f32, saa as f32);
        let va = saa - sa * sa / n;
        if va <= 0.0 {
            return scores;
        }
        // Copies of the left window's rows and the strip's rows, zero-padded to whole multiples of
        // `LANES` (the zeros add nothing), so that each row's cross products are whole vectors.
        let padded = len.div_ceil(LANES) * LANES;
        let strip_padded = strip_len + padded - len;
        let mut window_a = vec![0u8; len * padded];
        let mut strip_b = vec![0u8; len * strip_padded];
        for (r, (wa, sb)) in window_a
            .chunks_exact_mut(padded)
            .zip(strip_b.chunks_exact_mut(strip_padded))
            .enumerate()
        {
            wa[..len].copy_from_slice(row_a(r));
            sb[..strip_len].copy_from_slice(row_b(r));
        }
        for (k, dx) in (lo..=hi).enumerate() {
            if !self.right_valid(bx + dx) {
                continue;
            }
            let sb = col_b[k..k + len].iter().sum::<u32>() as f32;
            let sbb = col_bb[k..k + len].iter().sum::<u32>() as f32;
            let sab: u32 = window_a
                .chunks_exact(padded)
                .zip(strip_b.chunks_exact(strip_padded))
                .map(|(wa, sb)| dot_u8(wa, &sb[k..k + padded]))
                .sum();
            let vb = sbb - sb * sb / n;
            if vb > 0.0 {
                scores.push((dx as i32, (sab as f32 - sa * sb / n) / (va * vb).sqrt()));
            }
        }
        scores
    }

    /// [`SearchLine::magnitudes`] through `warp`: the correlations of the template the
    /// refinement starts from (the left window's Sobel vectors sampled through the inverse of
    /// `warp`, as the right camera sees them) with each right window of vectors, in `dx` order;
    /// a correlation sums over both channels, each about its own mean. Positions whose window
    /// leaves the plane or touches a lost row, or where either window is flat, are left out. At
    /// a large verge a window near the image's edge is stretched by tens of per cent between
    /// the views, which no whole-pixel shift of the unwarped window aligns.
    fn through(&self, warp: &Warp) -> Vec<(i32, f32)> {
        let (a, [ax, ay], b, half) = (self.left_plane, self.left, self.right_plane, self.half);
        let mut scores = Vec::new();
        let Some(inverse) = inverse(warp) else {
            return scores;
        };
        let side = self.side();
        let n = side * side;
        let mut template = vec![0.0; CHANNELS * n];
        if sample_warped(a, ax as f32, ay as f32, half, &inverse, &mut template).is_none() {
            return scores;
        }
        let mut squares = vec![0.0; CHANNELS * n];
        let (t_means, t_norm) = means_and_norm(&template, &mut squares);
        if t_norm <= 0.0 {
            return scores;
        }
        for (channel, mean) in template.chunks_exact_mut(n).zip(t_means) {
            channel.iter_mut().for_each(|v| *v -= mean);
        }
        // The right windows lie inside the plane for one contiguous range of shifts; their strip
        // of vectors is converted once.
        let [bx, by, search, half] =
            [self.guess[0], self.guess[1], self.search, half].map(i64::from);
        let Some((lo, hi)) = shifts_inside(b, bx, search, half) else {
            return scores;
        };
        if by - half < 0 || by + half >= i64::from(b.height()) {
            return scores;
        }
        let strip_width = (hi - lo) as usize + side;
        let mut strip = vec![0.0; CHANNELS * strip_width * side];
        let origin = [(bx + lo - half) as usize, (by - half) as usize];
        vector_block(b, origin, [strip_width, side], &mut strip);
        let mut window = vec![0.0; CHANNELS * n];
        for (k, dx) in (lo..=hi).enumerate() {
            if !self.right_valid(bx + dx) {
                continue;
            }
            for (channel, src) in window
                .chunks_exact_mut(n)
                .zip(strip.chunks_exact(strip_width * side))
            {
                for (row, src_row) in channel
                    .chunks_exact_mut(side)
                    .zip(src.chunks_exact(strip_width))
                {
                    row.copy_from_slice(&src_row[k..k + side]);
                }
            }
            let (means, norm) = means_and_norm(&window, &mut squares);
            if norm <= 0.0 {
                continue;
            }
            let dot: f32 = window
                .chunks_exact(n)
                .zip(template.chunks_exact(n))
                .zip(means)
                .map(|((w, t), mean)| w.iter().zip(t).map(|(&w, &t)| (w - mean) * t).sum::<f32>())
                .sum();
            scores.push((dx as i32, dot / (t_norm * norm)));
        }
        scores
    }
}

/// Vector width (in `u8` pixels) of [`SearchLine::magnitudes`]' cross products.
const LANES: usize = 8;

/// Σ a·b over two equally long rows whose length is a multiple of [`LANES`]: whole chunks of
/// fixed width, which compile to vector multiplies without a scalar tail. The products are
/// taken in `u16`, where 255² fits.
fn dot_u8(a: &[u8], b: &[u8]) -> u32 {
    a.chunks_exact(LANES)
        .zip(b.chunks_exact(LANES))
        .map(|(a, b)| {
            a.iter()
                .zip(b)
                .map(|(&x, &y)| u32::from(u16::from(x) * u16::from(y)))
                .sum::<u32>()
        })
        .sum()
}

/// Guided matching for a left point without a descriptor match: searches `±search_px`
/// horizontally around the predicted right position `guess` (from neighbouring matches) for
/// the best correlation of the windows (of magnitudes, or through `warp` of vectors when the
/// warp moves the window's edge by `SCAN_WARP_PX` or more), requires it to beat every other
/// local maximum clearly, then refines it with [`refine_pair`].
pub fn guided_pair(
    left_plane: &SobelPlane,
    right_plane: &SobelPlane,
    left: [f32; 2],
    guess: [f32; 2],
    search_px: i32,
    warp: &Warp,
    config: &SubpixelConfig,
) -> Option<RefinedPair> {
    let half = i32::try_from(config.half_window).ok()?;
    let (lx, ly) = (left[0].round() as i32, left[1].round() as i32);
    let gy = (guess[1] + (ly as f32 - left[1])).round() as i32;
    let gx = (guess[0] + (lx as f32 - left[0])).round() as i32;
    let line = SearchLine {
        left_plane,
        left: [lx, ly],
        right_plane,
        guess: [gx, gy],
        search: search_px,
        half,
    };
    let scores = if deformation_px(warp, half) >= SCAN_WARP_PX {
        line.through(warp)
    } else {
        line.magnitudes()
    };
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
        // The lowest correlation there is: no other peak.
        .fold(-1.0f32, f32::max);
    if best < config.min_correlation || runner_up > best - GUIDED_PEAK_MARGIN {
        return None;
    }
    refine_pair(
        left_plane,
        right_plane,
        [lx as f32, ly as f32],
        [(gx + best_dx) as f32, gy as f32],
        warp,
        config,
    )
}

/// A guided match's correlation peak must beat any other peak by this much (ambiguity test,
/// the analogue of the descriptor ratio test). Halving or doubling it moves the rendered
/// road's raw median error by < 0.0001° and the KITTI drive's by < 0.002°
/// (README, "Sensitivity of the constants").
const GUIDED_PEAK_MARGIN: f32 = 0.1;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lane_sums_are_the_sums_of_every_element() {
        for n in [0usize, 1, 7, 8, 9, 225, 226] {
            let a: Vec<f32> = (0..n).map(|i| (i as f32 * 0.37).sin() * 100.0).collect();
            let b: Vec<f32> = (0..n).map(|i| i as f32 + 0.5).collect();
            let [sa, sb] = lane_sums([&a, &b]);
            let exact = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>();
            assert!((f64::from(sa) - exact(&a)).abs() <= 1e-3, "{n}: {sa}");
            assert!(
                (f64::from(sb) - exact(&b)).abs() <= 1e-3 * exact(&b).max(1.0),
                "{n}: {sb}"
            );
        }
    }

    /// A smooth blob field sampled at a sub-pixel shift.
    fn plane(w: u32, h: u32, sx: f32, sy: f32, gain: f32) -> SobelPlane {
        mapped(w, h, gain, |x, y| (x - sx, y - sy))
    }

    /// A `w` x `h` plane of a smooth texture seen at `source(x, y)` from pixel (x, y), scaled
    /// by `gain`.
    fn mapped(w: u32, h: u32, gain: f32, source: impl Fn(f32, f32) -> (f32, f32)) -> SobelPlane {
        let mut mag = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let (xf, yf) = source(x as f32, y as f32);
                let v = 100.0
                    + 60.0 * (xf * 0.31).sin() * (yf * 0.23).cos()
                    + 40.0 * ((xf + 2.0 * yf) * 0.17).sin();
                mag.push((v * gain).round().clamp(0.0, 255.0) as u8);
            }
        }
        SobelPlane::new(0, w, h, mag, vec![0; (w * h) as usize]).unwrap()
    }

    /// A `w` x `h` plane of the Sobel vectors of [`mapped`]'s texture seen at `source(x, y)`
    /// from pixel (x, y): each pixel's gradient (central differences of the texture at the
    /// source point's neighbours, so that a warp turns the vectors as it turns an image's) as
    /// magnitude and orientation code, both channels busy.
    fn gradients(w: u32, h: u32, source: impl Fn(f32, f32) -> (f32, f32)) -> SobelPlane {
        let texture = |x: f32, y: f32| {
            let (xf, yf) = source(x, y);
            60.0 * (xf * 0.31).sin() * (yf * 0.23).cos() + 40.0 * ((xf + 2.0 * yf) * 0.17).sin()
        };
        let steps = f32::from(ORIENTATION_STEPS);
        let (mut magnitude, mut orientation) = (Vec::new(), Vec::new());
        for y in 0..h {
            for x in 0..w {
                let (xf, yf) = (x as f32, y as f32);
                let gx = texture(xf + 1.0, yf) - texture(xf - 1.0, yf);
                let gy = texture(xf, yf + 1.0) - texture(xf, yf - 1.0);
                magnitude.push(gx.hypot(gy).round().min(255.0) as u8);
                let code = (gy.atan2(gx) / std::f32::consts::TAU * steps).round();
                orientation.push(code.rem_euclid(steps) as u8);
            }
        }
        SobelPlane::new(0, w, h, magnitude, orientation).unwrap()
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
                &IDENTITY,
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
    fn the_disparity_gradient_unbiases_a_sheared_window() {
        // A slanted surface: the right view's columns move by 0.25 px a row about row 30 (a
        // road's disparity gradient on the KITTI drive), and the view is shifted by
        // (-3.2, 0.2).
        let (shear, shift) = (0.25f32, [-3.2f32, 0.2]);
        let l = gradients(80, 60, |x, y| (x, y));
        let r = gradients(80, 60, |x, y| {
            (x - shift[0] - shear * (y - 30.0), y - shift[1])
        });
        // The largest error of the refined right point, horizontal and vertical (pixels).
        let worst = |config: &SubpixelConfig| {
            let mut worst = [0f32; 2];
            for x in [30.0f32, 40.0, 50.0] {
                let got = refine_pair(&l, &r, [x, 30.0], [x - 3.0, 30.0], &IDENTITY, config)
                    .expect("refined");
                let want = [x + shift[0], 30.0 + shift[1]];
                for (w, (g, t)) in worst.iter_mut().zip(got.right.iter().zip(want)) {
                    *w = w.max((g - t).abs());
                }
            }
            worst
        };
        let [_, translation] = worst(&SubpixelConfig::default());
        let gradient = worst(&SubpixelConfig {
            disparity_gradient: true,
            ..SubpixelConfig::default()
        });
        // The translation alone follows the texture's oblique stripes, vertically too; the
        // gradient leaves the quantisation's few hundredths (u8 magnitudes, 64 orientation
        // codes).
        assert!(
            gradient[0] < 0.08 && gradient[1] < 0.03,
            "with the gradient {gradient:?} px"
        );
        assert!(translation > 0.2, "translation alone {translation} px");
    }

    /// Every pixel of an 80x60 plane valid except columns `cols` of row `row`.
    fn losing(row: u32, cols: std::ops::Range<u32>) -> Vec<bool> {
        (0..60u32)
            .flat_map(|y| (0..80u32).map(move |x| (x, y)))
            .map(|(x, y)| y != row || !cols.contains(&x))
            .collect()
    }

    /// Every pixel of an 80x60 plane valid except row `row`.
    fn rows_without(row: u32) -> Vec<bool> {
        losing(row, 0..80)
    }

    #[test]
    fn windows_touching_a_lost_row_are_rejected_on_either_side() {
        let cfg = SubpixelConfig::default();
        let (x, y) = (40.0f32, 30.0f32);
        let l = plane(80, 60, 0.0, 0.0, 1.0);
        let r = plane(80, 60, -3.37, 0.21, 0.9);
        // The identity, and a verged head's stretch and shear (the warped template path).
        for warp in [IDENTITY, [1.06, 0.0, 0.03, 1.02]] {
            let refine = |l: &SobelPlane, r: &SobelPlane| {
                refine_pair(l, r, [x, y], [x - 3.0, y], &warp, &cfg)
            };
            assert!(refine(&l, &r).is_some());
            // The left template reads rows 22..=38 (window and central differences).
            for lost in [22, 38] {
                let damaged = l.clone().with_valid(rows_without(lost));
                assert!(
                    refine(&damaged, &r).is_none(),
                    "left row {lost}, warp {warp:?}"
                );
            }
            let far = l.clone().with_valid(rows_without(45));
            assert_eq!(refine(&far, &r), refine(&l, &r));
            let damaged = r.clone().with_valid(rows_without(30));
            assert!(refine(&l, &damaged).is_none());
            let guided = |r: &SobelPlane| guided_pair(&l, r, [x, y], [x - 3.0, y], 8, &warp, &cfg);
            assert!(guided(&r).is_some());
            assert!(guided(&r.clone().with_valid(rows_without(24))).is_none());
            // A lost segment of a row costs only the windows that reach its columns: the
            // left template spans columns 31..=49.
            let beside = l.clone().with_valid(losing(30, 55..80));
            assert_eq!(refine(&beside, &r), refine(&l, &r));
            let inside = l.clone().with_valid(losing(30, 45..80));
            assert!(refine(&inside, &r).is_none());
        }
    }

    #[test]
    fn a_lost_segment_costs_the_guided_scan_only_the_shifts_that_reach_it() {
        let l = plane(100, 60, 0.0, 0.0, 1.0);
        let r = plane(100, 60, -6.4, 0.3, 1.0);
        // Columns 28..34 of row 30 lost: the right windows of shifts -8..=-7 from column 47
        // (centres 39 and 40, 15 wide) reach them, those of -6..=8 do not.
        let valid: Vec<bool> = (0..60u32)
            .flat_map(|y| (0..100u32).map(move |x| y != 30 || !(28..34).contains(&x)))
            .collect();
        let damaged = r.clone().with_valid(valid);
        let line = |right_plane| SearchLine {
            left_plane: &l,
            left: [50, 30],
            right_plane,
            guess: [47, 30],
            search: 8,
            half: 7,
        };
        let intact = line(&r).magnitudes();
        let kept: Vec<(i32, f32)> = intact.iter().copied().filter(|&(dx, _)| dx >= -6).collect();
        assert_eq!(intact.len(), 17);
        assert_eq!(line(&damaged).magnitudes(), kept);
        // The match, 3.4 px left of the guess, is found beside the lost segment.
        let got = guided_pair(
            &l,
            &damaged,
            [50.0, 30.0],
            [47.0, 30.0],
            8,
            &IDENTITY,
            &SubpixelConfig::default(),
        )
        .expect("the match beside the lost segment");
        assert!((got.right[0] - (got.left[0] - 6.4)).abs() < 0.05, "{got:?}");
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
            &IDENTITY,
            &SubpixelConfig::default(),
        )
        .unwrap();
        assert!((got.right[0] - (got.left[0] - 6.4)).abs() < 0.05, "{got:?}");
        assert!((got.right[1] - (got.left[1] + 0.3)).abs() < 0.05, "{got:?}");
    }

    #[test]
    fn guided_search_through_a_stretch() {
        // The right view stretched by 1.3 about column 50 and shifted by -6.4 px, as a large
        // verge stretches an image's edge: the left point (50, 30) lies at (43.6, 30.3).
        let (stretch, shift) = (1.3, -6.4);
        let l = plane(100, 60, 0.0, 0.0, 1.0);
        let r = mapped(100, 60, 1.0, |x, y| {
            (50.0 + (x - 50.0 - shift) / stretch, y - 0.3)
        });
        let search = |warp: &Warp| {
            guided_pair(
                &l,
                &r,
                [50.0, 30.0],
                [47.0, 30.0],
                8,
                warp,
                &SubpixelConfig::default(),
            )
        };
        let got = search(&[stretch, 0.0, 0.0, 1.0]).expect("the warped search matches");
        assert!((got.right[0] - (50.0 + shift)).abs() < 0.05, "{got:?}");
        assert!((got.right[1] - 30.3).abs() < 0.05, "{got:?}");
        // The warped scan peaks at the whole pixel nearest the true shift (-3.4 from the
        // guess), and higher than the unwarped scan's own peak, which the stretch moves.
        let peak = |scores: Vec<(i32, f32)>| {
            scores
                .into_iter()
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap()
        };
        let warp = [stretch, 0.0, 0.0, 1.0];
        let line = SearchLine {
            left_plane: &l,
            left: [50, 30],
            right_plane: &r,
            guess: [47, 30],
            search: 8,
            half: 7,
        };
        let warped = peak(line.through(&warp));
        let plain = peak(line.magnitudes());
        assert_eq!(warped.0, -3, "{warped:?}");
        assert!(
            warped.1 > 0.99 && warped.1 > plain.1,
            "{warped:?} {plain:?}"
        );
    }

    /// The direct per-position correlation [`SearchLine::magnitudes`] must reproduce bit for bit.
    fn ncc_at(
        a: &SobelPlane,
        [ax, ay]: [i32; 2],
        b: &SobelPlane,
        [bx, by]: [i32; 2],
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
        let (mut sa, mut sb, mut saa, mut sbb, mut sab) = (0u32, 0u32, 0u32, 0u32, 0u32);
        for dy in -half..=half {
            for dx in -half..=half {
                let x = u32::from(a.get(ax + dx, ay + dy)?.0);
                let y = u32::from(b.get(bx + dx, by + dy)?.0);
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

    #[test]
    fn scan_equals_the_direct_correlation_at_every_shift() {
        let l = plane(60, 40, 0.0, 0.0, 1.0);
        let r = plane(60, 40, -4.6, 0.4, 0.8);
        // A right plane with a flat band, so some windows are flat and left out.
        let mut mag = r.magnitude().to_vec();
        mag.iter_mut()
            .enumerate()
            .filter(|(i, _)| (20..34).contains(&(i % 60)))
            .for_each(|(_, v)| *v = 77);
        let banded = SobelPlane::new(0, 60, 40, mag, vec![0; 2400]).unwrap();
        let mut compared = 0;
        for right in [&r, &banded] {
            for half in [1, 3, 7] {
                // Centres near and beyond every border, so windows leave the planes.
                for &(lx, ly, gx, gy) in &[
                    (30, 20, 26, 20),
                    (5, 7, 2, 8),
                    (55, 33, 58, 32),
                    (30, 2, 30, 20),
                    (30, 20, 30, 38),
                    (30, 20, -9, 20),
                    (30, 20, 70, 20),
                    (40, 20, 27, 21),
                ] {
                    for search in [-1, 0, 4, 9] {
                        let got = SearchLine {
                            left_plane: &l,
                            left: [lx, ly],
                            right_plane: right,
                            guess: [gx, gy],
                            search,
                            half,
                        }
                        .magnitudes();
                        let want: Vec<(i32, f32)> = (-search..=search)
                            .filter_map(|dx| {
                                Some((dx, ncc_at(&l, [lx, ly], right, [gx + dx, gy], half)?))
                            })
                            .collect();
                        let bits = |v: &[(i32, f32)]| {
                            v.iter().map(|&(d, c)| (d, c.to_bits())).collect::<Vec<_>>()
                        };
                        assert_eq!(
                            bits(&got),
                            bits(&want),
                            "{lx} {ly} {gx} {gy} {search} {half}"
                        );
                        compared += want.len();
                    }
                }
            }
        }
        assert!(compared > 300, "only {compared} correlations compared");
    }

    #[test]
    fn stale_scratch_and_large_or_impossible_windows() {
        let l = plane(120, 90, 0.0, 0.0, 1.0);
        let r = plane(120, 90, -3.37, 0.21, 0.9);
        let default = SubpixelConfig::default();
        let first = refine_pair(&l, &r, [60.3, 45.6], [57.0, 46.0], &IDENTITY, &default).unwrap();
        // A larger window grows this thread's scratch arrays and leaves its values in them.
        let config = SubpixelConfig {
            half_window: 12,
            ..default
        };
        let got = refine_pair(&l, &r, [60.3, 45.6], [57.0, 46.0], &IDENTITY, &config).unwrap();
        assert!(
            (got.right[0] - (got.left[0] - 3.37)).abs() < 0.05,
            "{got:?}"
        );
        assert!(
            (got.right[1] - (got.left[1] + 0.21)).abs() < 0.05,
            "{got:?}"
        );
        let again = refine_pair(&l, &r, [60.3, 45.6], [57.0, 46.0], &IDENTITY, &default).unwrap();
        assert_eq!(format!("{first:?}"), format!("{again:?}"));
        // Windows that cannot fit the plane, however large the configured value, are rejected.
        for half_window in [60, usize::MAX] {
            let config = SubpixelConfig {
                half_window,
                ..default
            };
            assert!(refine_pair(&l, &r, [60.0, 45.0], [57.0, 45.0], &IDENTITY, &config).is_none());
            assert!(
                guided_pair(&l, &r, [60.0, 45.0], [57.0, 45.0], 4, &IDENTITY, &config).is_none()
            );
        }
    }

    #[test]
    fn rejects_featureless_and_border_windows() {
        let flat = SobelPlane::new(0, 40, 40, vec![50; 1600], vec![0; 1600]).unwrap();
        assert!(refine_pair(
            &flat,
            &flat,
            [20.0, 20.0],
            [20.0, 20.0],
            &IDENTITY,
            &SubpixelConfig::default()
        )
        .is_none());
        let l = plane(40, 40, 0.0, 0.0, 1.0);
        assert!(refine_pair(
            &l,
            &l,
            [3.0, 20.0],
            [3.0, 20.0],
            &IDENTITY,
            &SubpixelConfig::default()
        )
        .is_none());
    }
}
