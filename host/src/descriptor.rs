//! SIFT-style descriptors from the fabric's Sobel gradients (thesis 4.4.2, after Lowe).
//!
//! The 16×16 window around a keypoint (at the keypoint's octave) is split into 4×4 cells of
//! 4×4 pixels; each pixel adds its magnitude, weighted by a Gaussian of σ = 8 px (half the
//! window), to an 8-bin orientation histogram, spread trilinearly over the two nearest cells
//! in x and y and the two nearest orientation bins. The 128 values are L2-normalised, clamped
//! at 0.2 (limits the weight of single strong edges, which vary with illumination) and
//! renormalised, then stored as `u8` (×512, saturating) so that distances are integer loops
//! the compiler vectorises.
//!
//! Variants: the reduced 16-element mode (2×2 cells × 4 bins, thesis 6.3) for cheaper
//! matching; and dominant-orientation rotation, off by default — on a fixed-baseline head the
//! two views are not rotated against each other, and skipping the rotation both saves work
//! and removes a source of mismatches (thesis 6.3).

use crate::features::{FeatureFrame, ORIENTATION_STEPS, PATCH_SIZE};

/// Descriptor layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DescriptorMode {
    /// 4×4 cells × 8 orientation bins = 128 elements (Lowe).
    Full128,
    /// 2×2 cells × 4 orientation bins = 16 elements.
    Reduced16,
}

impl DescriptorMode {
    /// Elements (bytes) per descriptor: 128 or 16.
    pub const fn dim(self) -> usize {
        match self {
            DescriptorMode::Full128 => 128,
            DescriptorMode::Reduced16 => 16,
        }
    }
    const fn cells(self) -> usize {
        match self {
            DescriptorMode::Full128 => 4,
            DescriptorMode::Reduced16 => 2,
        }
    }
    const fn bins(self) -> usize {
        match self {
            DescriptorMode::Full128 => 8,
            DescriptorMode::Reduced16 => 4,
        }
    }
}

/// Descriptor settings; the default is the most accurate one for a verge head.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DescriptorConfig {
    /// Layout: the full 128 elements or the reduced 16.
    pub mode: DescriptorMode,
    /// Rotate the window to the keypoint's dominant gradient orientation.
    pub rotate: bool,
}

impl Default for DescriptorConfig {
    fn default() -> Self {
        Self {
            mode: DescriptorMode::Full128,
            rotate: false,
        }
    }
}

/// The descriptors of one frame, contiguous (`dim` bytes each).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct DescriptorSet {
    dim: usize,
    data: Vec<u8>,
    keypoints: Vec<u32>,
}

impl DescriptorSet {
    /// Elements per descriptor.
    pub fn dim(&self) -> usize {
        self.dim
    }
    /// Number of descriptors: one per keypoint whose gradient window is available.
    pub fn len(&self) -> usize {
        self.keypoints.len()
    }
    /// True when the frame gave no descriptor.
    pub fn is_empty(&self) -> bool {
        self.keypoints.is_empty()
    }
    /// Descriptor `i`.
    pub fn get(&self, i: usize) -> &[u8] {
        &self.data[i * self.dim..(i + 1) * self.dim]
    }
    /// Index into `FeatureFrame::keypoints` of descriptor `i`.
    pub fn keypoint(&self, i: usize) -> usize {
        self.keypoints[i] as usize
    }
    /// All descriptors, `len() * dim()` bytes.
    pub fn data(&self) -> &[u8] {
        &self.data
    }
}

/// Gaussian weighting σ of the window (half its width), in window pixels: Lowe's (2004, 6.1),
/// so that the descriptor changes smoothly as the window shifts and the gradients far from the
/// centre, most affected by misregistration, weigh least.
const WINDOW_SIGMA: f32 = (PATCH_SIZE / 2) as f32;
/// Lowe's clamp of normalised descriptor elements.
const CLAMP: f32 = 0.2;
/// Fewer than this fraction of window samples available → no descriptor (image border).
/// Three quarters: the window less one row or column of its 4x4 cells, so at most a quarter
/// of the descriptor's cells are empty. Any coverage from 3/8 to the whole window moves the
/// rendered road's raw median error by < 0.0003° and the KITTI drive's by < 0.005°
/// (README, "Sensitivity of the constants").
const MIN_COVERAGE: usize = PATCH_SIZE * PATCH_SIZE * 3 / 4;

/// Computes the descriptor of every keypoint whose gradient window is available (keypoints
/// whose window leaves the image are skipped; their indices are absent from the set).
pub fn describe(frame: &FeatureFrame, config: &DescriptorConfig) -> DescriptorSet {
    let dim = config.mode.dim();
    let n = frame.keypoints().len();
    let mut set = DescriptorSet {
        dim,
        data: Vec::with_capacity(n * dim),
        keypoints: Vec::with_capacity(n),
    };
    let mut window = [(0u8, 0u8); PATCH_SIZE * PATCH_SIZE];
    let mut hist = [0f32; 128];
    for k in 0..n {
        if frame.window(k, &mut window) < MIN_COVERAGE {
            continue;
        }
        if config.rotate {
            accumulate(
                &window,
                config.mode,
                dominant_orientation(&window),
                &mut hist[..dim],
            );
        } else {
            accumulate_fixed_mode(&window, config.mode, &mut hist[..dim]);
        }
        let start = set.data.len();
        set.data.resize(start + dim, 0);
        quantize(&mut hist[..dim], &mut set.data[start..]);
        set.keypoints.push(k as u32);
    }
    set
}

/// Offset of window sample `i` from the window centre, in pixels (the centre lies between
/// the middle four samples).
fn offset(i: usize) -> (f32, f32) {
    let half = (PATCH_SIZE / 2) as f32;
    (
        (i % PATCH_SIZE) as f32 - half + 0.5,
        (i / PATCH_SIZE) as f32 - half + 0.5,
    )
}

/// Dominant gradient orientation (radians) from a Gaussian-weighted 64-bin histogram,
/// smoothed and peak-interpolated.
fn dominant_orientation(window: &[(u8, u8)]) -> f32 {
    // One bin per orientation code of the fabric: its whole angular resolution.
    const STEPS: usize = ORIENTATION_STEPS as usize;
    let mut h = [0f32; STEPS];
    for (i, &(m, o)) in window.iter().enumerate() {
        let (x, y) = offset(i);
        // 0.75 of the descriptor's σ: the orientation comes from nearer the keypoint than
        // the descriptor does. Half or twice that (with `--rotate`) moves the rendered road's
        // raw median error by < 0.0001° and the KITTI drive's by < 0.006° (README,
        // "Sensitivity of the constants").
        let g = (-(x * x + y * y) / (2.0 * (0.75 * WINDOW_SIGMA).powi(2))).exp();
        h[o as usize % STEPS] += m as f32 * g;
    }
    // The binomial [¼ ½ ¼]: it sums to one, leaves a symmetric peak where it is, and cancels
    // the alternation between neighbouring codes that the angles' quantisation leaves (its
    // response at the bins' Nyquist frequency is zero). It is the pass Hess's SIFT repeats on
    // its orientation histogram (`smooth_ori_hist`), and OpenCV's [1 4 6 4 1]/16 is two of it.
    let smooth: [f32; STEPS] = std::array::from_fn(|i| {
        0.25 * h[(i + STEPS - 1) % STEPS] + 0.5 * h[i] + 0.25 * h[(i + 1) % STEPS]
    });
    let (best, _) =
        smooth.iter().enumerate().fold(
            (0, f32::MIN),
            |acc, (i, &v)| if v > acc.1 { (i, v) } else { acc },
        );
    let (l, c, r) = (
        smooth[(best + STEPS - 1) % STEPS],
        smooth[best],
        smooth[(best + 1) % STEPS],
    );
    let den = l - 2.0 * c + r;
    let frac = if den < 0.0 { 0.5 * (l - r) / den } else { 0.0 };
    (best as f32 + frac) * std::f32::consts::TAU / STEPS as f32
}

/// Trilinear accumulation of the window into `hist` (cells × cells × bins), in a frame rotated
/// by `angle`.
fn accumulate(window: &[(u8, u8)], mode: DescriptorMode, angle: f32, hist: &mut [f32]) {
    hist.fill(0.0);
    let cells = mode.cells();
    let bins = mode.bins();
    let cell_px = (PATCH_SIZE / cells) as f32;
    let half = (PATCH_SIZE / 2) as f32;
    let (sin, cos) = angle.sin_cos();
    let bins_per_step = bins as f32 / ORIENTATION_STEPS as f32;
    let angle_bins = angle / std::f32::consts::TAU * bins as f32;
    for (i, &(m, o)) in window.iter().enumerate() {
        if m == 0 {
            continue;
        }
        let (x0, y0) = offset(i);
        let (x, y) = (cos * x0 + sin * y0, -sin * x0 + cos * y0);
        // Continuous cell coordinates: cell centres at 0, 1, ..., cells-1.
        let cx = (x + half) / cell_px - 0.5;
        let cy = (y + half) / cell_px - 0.5;
        if cx <= -1.0 || cy <= -1.0 || cx >= cells as f32 || cy >= cells as f32 {
            continue;
        }
        let g = (-(x0 * x0 + y0 * y0) / (2.0 * WINDOW_SIGMA * WINDOW_SIGMA)).exp();
        let w = m as f32 * g;
        let mut ob = o as f32 * bins_per_step - angle_bins;
        ob = ob.rem_euclid(bins as f32);
        let (ix, iy, io) = (cx.floor(), cy.floor(), ob.floor());
        let (fx, fy, fo) = (cx - ix, cy - iy, ob - io);
        for (dy, wy) in [(0, 1.0 - fy), (1, fy)] {
            let yy = iy as i32 + dy;
            if yy < 0 || yy >= cells as i32 {
                continue;
            }
            for (dx, wx) in [(0, 1.0 - fx), (1, fx)] {
                let xx = ix as i32 + dx;
                if xx < 0 || xx >= cells as i32 {
                    continue;
                }
                let base = (yy as usize * cells + xx as usize) * bins;
                for (d_o, wo) in [(0, 1.0 - fo), (1, fo)] {
                    let bin = (io as usize + d_o) % bins;
                    hist[base + bin] += w * wy * wx * wo;
                }
            }
        }
    }
}

/// Orientation weights of one 6-bit code as a dense bin vector: `1 − fo` at the lower bin, `fo`
/// at the upper one, `0` elsewhere. Aligned so a vector load of it never splits a cache line.
#[derive(Clone, Copy)]
#[repr(align(32))]
struct BinWeights<const B: usize>([f32; B]);

/// The per-mode tables of the unrotated window (the same for every keypoint, built once).
struct FixedTables<const B: usize> {
    /// Indexed by orientation code (all 64 codes).
    bins: [BinWeights<B>; ORIENTATION_STEPS as usize],
    /// Every (window sample, spatial weight incl. Gaussian) contributing to a cell, grouped by
    /// cell (`taps[starts[c]..starts[c + 1]]`) and in window order within a cell.
    taps: Vec<(u8, f32)>,
    starts: Vec<usize>,
}

impl<const B: usize> FixedTables<B> {
    fn new(mode: DescriptorMode) -> Self {
        assert_eq!(mode.bins(), B);
        let steps_per_bin = ORIENTATION_STEPS as usize / B;
        let frac_scale = 1.0 / steps_per_bin as f32;
        let bins = std::array::from_fn(|o| {
            let b0 = (o / steps_per_bin) % B;
            let fo = (o % steps_per_bin) as f32 * frac_scale;
            let mut v = [0.0; B];
            v[b0] = 1.0 - fo;
            v[(b0 + 1) % B] = fo;
            BinWeights(v)
        });
        let cells = mode.cells();
        let cell_px = (PATCH_SIZE / cells) as f32;
        let half = (PATCH_SIZE / 2) as f32;
        let mut per_cell = vec![Vec::new(); cells * cells];
        for i in 0..PATCH_SIZE * PATCH_SIZE {
            let (x, y) = offset(i);
            let g = (-(x * x + y * y) / (2.0 * WINDOW_SIGMA * WINDOW_SIGMA)).exp();
            let cx = (x + half) / cell_px - 0.5;
            let cy = (y + half) / cell_px - 0.5;
            let (ix, iy) = (cx.floor(), cy.floor());
            let (fx, fy) = (cx - ix, cy - iy);
            for (dy, wy) in [(0, 1.0 - fy), (1, fy)] {
                for (dx, wx) in [(0, 1.0 - fx), (1, fx)] {
                    let (xx, yy) = (ix as i32 + dx, iy as i32 + dy);
                    if (0..cells as i32).contains(&xx) && (0..cells as i32).contains(&yy) {
                        per_cell[yy as usize * cells + xx as usize].push((i as u8, g * wx * wy));
                    }
                }
            }
        }
        let mut starts = vec![0];
        let mut taps = Vec::new();
        for cell in per_cell {
            taps.extend(cell);
            starts.push(taps.len());
        }
        Self { bins, taps, starts }
    }
}

/// [`accumulate`] for the unrotated window, with the spatial and orientation weights from
/// tables: `hist` is cells × `B` bins.
///
/// Cell by cell, each cell's `B` sums live in registers: every sample near the cell adds
/// `(m · w) · bins[o]`, one `B`-wide multiply-add of the dense orientation vector. A scatter
/// of `hist[cell][b0] += …; hist[cell][b1] += …` per sample would instead read back, through
/// memory, values stored a few instructions earlier at data-dependent addresses: each sum would
/// wait on store-to-load forwarding (or on a memory-ordering flush when a load was hoisted over
/// an aliasing store), and samples outside the border cells would still cost a (zero) update.
///
/// The result is bit-identical to that scatter (kept as the reference in the tests): each
/// product is the same `(m · w) · (1 − fo)` or `(m · w) · fo`, each element receives its nonzero
/// terms in the same (window) order starting from `+0`, and the extra terms are `x · 0 = +0`
/// (all weights are finite and ≥ 0), which leave a sum unchanged. Rust does not contract
/// `a · b + c` into a fused multiply-add, so every product is rounded as before.
fn accumulate_fixed<const B: usize>(
    window: &[(u8, u8); PATCH_SIZE * PATCH_SIZE],
    tables: &FixedTables<B>,
    hist: &mut [f32],
) {
    for (c, out) in hist.chunks_exact_mut(B).enumerate() {
        let mut acc = [0f32; B];
        for &(i, sw) in &tables.taps[tables.starts[c]..tables.starts[c + 1]] {
            let (m, o) = window[i as usize];
            let w = m as f32 * sw;
            // `% 64` keeps codes ≥ 64 (unchecked patches) in the bins the shift/mask would give.
            let bins = &tables.bins[o as usize % ORIENTATION_STEPS as usize].0;
            for (a, &t) in acc.iter_mut().zip(bins) {
                *a += w * t;
            }
        }
        out.copy_from_slice(&acc);
    }
}

/// [`accumulate_fixed`] in the layout of `mode`, with that mode's tables.
fn accumulate_fixed_mode(
    window: &[(u8, u8); PATCH_SIZE * PATCH_SIZE],
    mode: DescriptorMode,
    hist: &mut [f32],
) {
    use std::sync::OnceLock;
    static FULL: OnceLock<FixedTables<8>> = OnceLock::new();
    static REDUCED: OnceLock<FixedTables<4>> = OnceLock::new();
    match mode {
        DescriptorMode::Full128 => {
            accumulate_fixed(window, FULL.get_or_init(|| FixedTables::new(mode)), hist)
        }
        DescriptorMode::Reduced16 => {
            accumulate_fixed(window, REDUCED.get_or_init(|| FixedTables::new(mode)), hist)
        }
    }
}

/// Normalise, clamp at 0.2, renormalise, scale by 512 into u8.
fn quantize(hist: &mut [f32], out: &mut [u8]) {
    let norm = hist.iter().map(|v| v * v).sum::<f32>().sqrt();
    if norm <= 0.0 {
        out.fill(0);
        return;
    }
    hist.iter_mut().for_each(|v| *v = (*v / norm).min(CLAMP));
    let norm = hist.iter().map(|v| v * v).sum::<f32>().sqrt();
    for (o, v) in out.iter_mut().zip(hist.iter()) {
        // The u8 scale of OpenCV's and Hess's SIFT (`SIFT_INT_DESCR_FCTR`), which clamp at the
        // same 0.2.
        *o = round_to_u8(v / norm * 512.0);
    }
}

/// `x.round().clamp(0.0, 255.0) as u8`, without the `roundf` call that the baseline x86-64
/// target (no SSE4.1 `roundss`) makes per element — a quarter of the descriptor's cost.
///
/// Clamping first changes nothing (rounding is monotonic and 0 and 255 are integers; NaN stays
/// NaN and ends as 0 either way). On [0, 255] the truncation `t` is exact and so is `x − t`
/// (both below 2^23), and rounding half away from zero adds one exactly when `x − t ≥ 0.5`.
/// The loop over elements then vectorises.
fn round_to_u8(x: f32) -> u8 {
    let x = x.clamp(0.0, 255.0);
    let t = x as i32;
    (t + i32::from(x - t as f32 >= 0.5)) as u8
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::features::{Gradients, Keypoint, SobelPlane};

    /// A synthetic gradient plane: orientation and magnitude from a smooth pseudo-random field.
    fn plane(width: u32, height: u32, shift_x: i32, rotate_quarter: bool) -> SobelPlane {
        let mut mag = Vec::new();
        let mut ori = Vec::new();
        for y in 0..height as i32 {
            for x in 0..width as i32 {
                let (sx, sy) = if rotate_quarter {
                    // Rotate the field by 90° about (32, 32): (x, y) -> (y, 64 - x).
                    (y, 64 - x)
                } else {
                    (x - shift_x, y)
                };
                let h = (sx.wrapping_mul(73856093) ^ sy.wrapping_mul(19349663)) as u32;
                mag.push((h % 200) as u8 + 20);
                let code = ((h >> 8) % 64) as u8;
                // Rotating the image by +90° adds 16 codes to every gradient angle.
                ori.push(if rotate_quarter {
                    (code + 16) % 64
                } else {
                    code
                });
            }
        }
        SobelPlane::new(0, width, height, mag, ori).unwrap()
    }

    fn frame(p: SobelPlane, pts: &[(f32, f32)]) -> FeatureFrame {
        let (w, h) = (p.width(), p.height());
        let kps = pts
            .iter()
            .map(|&(x, y)| Keypoint {
                x,
                y,
                octave: 0,
                scale: 1.0,
                dog: 1.0,
            })
            .collect();
        FeatureFrame::new(0, 0, w, h, kps, Gradients::Planes(vec![p])).unwrap()
    }

    fn dist(a: &[u8], b: &[u8]) -> u32 {
        a.iter()
            .zip(b)
            .map(|(&x, &y)| (x as i32 - y as i32).pow(2) as u32)
            .sum()
    }

    #[test]
    fn descriptors_are_normalised_and_translation_invariant() {
        let a = frame(plane(64, 64, 0, false), &[(30.0, 30.0), (2.0, 2.0)]);
        let b = frame(plane(64, 64, 5, false), &[(35.0, 30.0), (20.0, 40.0)]);
        let cfg = DescriptorConfig::default();
        let da = describe(&a, &cfg);
        let db = describe(&b, &cfg);
        // The corner keypoint has less than 3/4 of its window: skipped.
        assert_eq!(da.len(), 1);
        assert_eq!(da.keypoint(0), 0);
        assert_eq!(db.len(), 2);
        assert_eq!(da.get(0), db.get(0));
        assert!(dist(da.get(0), db.get(1)) > 10_000);
        let energy: f32 = da.get(0).iter().map(|&v| (v as f32 / 512.0).powi(2)).sum();
        assert!((energy - 1.0).abs() < 0.05, "{energy}");
        assert!(da.get(0).iter().all(|&v| v as f32 <= 0.2 * 512.0 * 1.3));
    }

    #[test]
    fn rotation_mode_makes_descriptors_rotation_invariant() {
        let a = frame(plane(65, 65, 0, false), &[(32.0, 32.0)]);
        let b = frame(plane(65, 65, 0, true), &[(32.0, 32.0)]);
        let fixed = DescriptorConfig::default();
        let rot = DescriptorConfig {
            rotate: true,
            ..fixed
        };
        let d_fixed = dist(describe(&a, &fixed).get(0), describe(&b, &fixed).get(0));
        let d_rot = dist(describe(&a, &rot).get(0), describe(&b, &rot).get(0));
        assert!(d_rot * 4 < d_fixed, "rotated {d_rot} vs fixed {d_fixed}");
    }

    #[test]
    fn table_path_equals_the_general_path_at_zero_rotation() {
        let a = frame(plane(64, 64, 0, false), &[(30.0, 30.0)]);
        let mut window = [(0u8, 0u8); 256];
        a.window(0, &mut window);
        for mode in [DescriptorMode::Full128, DescriptorMode::Reduced16] {
            let mut h1 = [0f32; 128];
            let mut h2 = [0f32; 128];
            accumulate(&window, mode, 0.0, &mut h1[..mode.dim()]);
            accumulate_fixed_mode(&window, mode, &mut h2[..mode.dim()]);
            for (x, y) in h1.iter().zip(&h2) {
                assert!((x - y).abs() <= 1e-3 * x.abs().max(1.0), "{x} vs {y}");
            }
        }
    }

    /// The per-sample scatter that [`accumulate_fixed`] must equal: for each sample, its up to
    /// four cells (weights `g · wx · wy`, in (dy, dx) order) each get `m · w · (1 − fo)` at
    /// bin `b0` and `m · w · fo` at `b1`.
    fn scatter_reference(window: &[(u8, u8)], mode: DescriptorMode, hist: &mut [f32]) {
        hist.fill(0.0);
        let (cells, bins) = (mode.cells(), mode.bins());
        let cell_px = (PATCH_SIZE / cells) as f32;
        let half = (PATCH_SIZE / 2) as f32;
        let shift = (ORIENTATION_STEPS as usize / bins).trailing_zeros();
        let frac_scale = 1.0 / (ORIENTATION_STEPS as usize / bins) as f32;
        for (i, &(m, o)) in window.iter().enumerate() {
            if m == 0 {
                continue;
            }
            let b0 = (o as usize >> shift) % bins;
            let b1 = (b0 + 1) % bins;
            let fo = (o as usize & ((1 << shift) - 1)) as f32 * frac_scale;
            let (x, y) = offset(i);
            let g = (-(x * x + y * y) / (2.0 * WINDOW_SIGMA * WINDOW_SIGMA)).exp();
            let cx = (x + half) / cell_px - 0.5;
            let cy = (y + half) / cell_px - 0.5;
            let (ix, iy) = (cx.floor(), cy.floor());
            let (fx, fy) = (cx - ix, cy - iy);
            for (dy, wy) in [(0, 1.0 - fy), (1, fy)] {
                for (dx, wx) in [(0, 1.0 - fx), (1, fx)] {
                    let (xx, yy) = (ix as i32 + dx, iy as i32 + dy);
                    if (0..cells as i32).contains(&xx) && (0..cells as i32).contains(&yy) {
                        let base = (yy as usize * cells + xx as usize) * bins;
                        let w = m as f32 * (g * wx * wy);
                        hist[base + b0] += w * (1.0 - fo);
                        hist[base + b1] += w * fo;
                    }
                }
            }
        }
    }

    #[test]
    fn dense_bin_vectors_equal_the_scatter_bitwise() {
        let mut rng = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            rng
        };
        for round in 0..200 {
            let window: [(u8, u8); 256] = std::array::from_fn(|_| {
                let r = next();
                // Some zero magnitudes (skipped by the scatter); codes ≥ 64 in a few rounds.
                let m = if r % 7 == 0 { 0 } else { (r >> 8) as u8 };
                let o = if round % 4 == 0 {
                    (r >> 16) as u8
                } else {
                    (r >> 16) as u8 % 64
                };
                (m, o)
            });
            for mode in [DescriptorMode::Full128, DescriptorMode::Reduced16] {
                let mut fast = [0f32; 128];
                let mut reference = [0f32; 128];
                accumulate_fixed_mode(&window, mode, &mut fast[..mode.dim()]);
                scatter_reference(&window, mode, &mut reference[..mode.dim()]);
                let bits = |h: &[f32]| h.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&fast), bits(&reference), "round {round}, {mode:?}");
            }
        }
    }

    #[test]
    fn rounding_to_u8_equals_round_then_clamp() {
        let reference = |x: f32| x.round().clamp(0.0, 255.0) as u8;
        let mut xs = vec![
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            -0.0,
            0.0,
            -0.5,
            -1.5,
        ];
        for k in 0..=600 {
            // Every half-integer and its float neighbours (the rounding ties), and integers.
            for base in [k as f32, k as f32 + 0.5] {
                let b = base.to_bits();
                xs.extend((b.saturating_sub(3)..=b + 3).map(f32::from_bits));
            }
        }
        let mut rng = 0x9e37_79b9_u32;
        for _ in 0..100_000 {
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            xs.push((rng >> 8) as f32 / (1 << 24) as f32 * 600.0 - 20.0);
        }
        for x in xs {
            assert_eq!(round_to_u8(x), reference(x), "{x:e}");
        }
    }

    #[test]
    fn reduced_mode_has_16_elements() {
        let a = frame(plane(64, 64, 0, false), &[(30.0, 30.0)]);
        let cfg = DescriptorConfig {
            mode: DescriptorMode::Reduced16,
            rotate: false,
        };
        let d = describe(&a, &cfg);
        assert_eq!(d.dim(), 16);
        assert_eq!(d.data().len(), 16);
        assert!(d.get(0).iter().any(|&v| v > 0));
    }
}
