//! Nearest-neighbour matching of left and right descriptors (thesis 4.4.3).
//!
//! Candidates are the right keypoints within the band of rows where the left keypoint's match
//! can lie (the caller's [`RowBand`]: on a verge head the epipolar geometry keeps a match within
//! a few pixels of rows near the image centre and within tens at the corners, so the band
//! removes most false candidates and most of the work); the best candidate must beat the second best by the
//! ratio test; optionally the match must also be the left keypoint's best from the right
//! side (left-right consistency); optionally only the N best are kept.
//!
//! Distances are squared Euclidean over the descriptors' `u8` elements, computed by `simsimd`
//! (the widest integer SIMD the CPU has, picked at run time) on offset-binary copies: `v ^ 0x80`
//! maps `u8` to `i8` as `v - 128`, which leaves every difference, so every distance, unchanged.
//! `cargo bench -p stereocal --bench estimate` (`match only`) times the matching.

use rayon::prelude::*;

use crate::descriptor::DescriptorSet;
use crate::features::Keypoint;

/// Matching settings; the default is the most accurate for a verge head.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MatchConfig {
    /// Lowe's ratio: best distance < ratio · second-best distance (thesis 4.4.3: 0.6, stricter
    /// than Lowe's 0.8 because the calibration must see as few false matches as possible).
    pub ratio: f32,
    /// Require the match to be mutual (left's best is right's best).
    pub cross_check: bool,
    /// Keep only the N matches with the smallest descriptor distance (thesis: 20). `None`
    /// keeps every match that passes: the refinement needs many matches for sub-0.05°
    /// accuracy, and it is robust to the few extra outliers.
    pub best_n: Option<usize>,
    /// Which right keypoints are candidates for a left one, by row.
    pub gate: Gate,
}

/// The rows of the right image a left keypoint's candidates come from.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Gate {
    /// The epipolar band the calibration, the image size and the head's range of poses allow
    /// (`crate::epipolar_band`).
    #[default]
    Epipolar,
    /// |y_r - y_l| ≤ this many full-resolution pixels, whatever the geometry.
    Rows(f32),
    /// Every right keypoint.
    Off,
}

/// The right rows `[lowest, highest]` a left keypoint's candidates may have.
pub type RowBand<'a> = &'a (dyn Fn(&Keypoint) -> [f32; 2] + Sync);

impl Default for MatchConfig {
    fn default() -> Self {
        Self {
            ratio: 0.6,
            cross_check: true,
            best_n: None,
            gate: Gate::Epipolar,
        }
    }
}

/// One accepted match.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Match {
    /// Index into the left frame's keypoints.
    pub left: u32,
    /// Index into the right frame's keypoints.
    pub right: u32,
    /// Euclidean descriptor distance (in the u8 descriptor scale).
    pub distance: f32,
    /// best / second-best distance (≤ ratio).
    pub ratio: f32,
}

/// A descriptor element in offset binary: `v - 128` as `i8`.
#[inline]
fn offset(v: &u8) -> i8 {
    (v ^ 0x80) as i8
}

/// Squared Euclidean distance of two offset-binary descriptors of equal length.
#[inline]
fn distance_sq(a: &[i8], b: &[i8]) -> u32 {
    use simsimd::SpatialSimilarity;
    // Integer sums (at most 128 · 255² < 2^24 for our descriptors) are exact in `f64`;
    // `None` only for unequal lengths, which the callers never pass.
    i8::l2sq(a, b).map_or(u32::MAX, |d| d as u32)
}

/// Left descriptors one core scans at least, so that a chunk outweighs its bookkeeping (a
/// `right_best` array of its own).
const MIN_SCAN_CHUNK: usize = 64;

/// What scanning some left descriptors found, in left index order.
struct Scan {
    /// `(left, best right, best distance, second-best distance)`.
    candidates: Vec<(u32, u32, u32, u32)>,
    /// Per right descriptor, the best `(distance, left)` seen.
    right_best: Vec<(u32, u32)>,
}

impl Scan {
    fn new(rights: usize) -> Self {
        Self {
            candidates: Vec::new(),
            right_best: vec![(u32::MAX, u32::MAX); rights],
        }
    }

    /// `self` followed by `later` (higher left indices): a right descriptor keeps the earlier
    /// left one unless the later one is strictly nearer.
    fn then(mut self, mut later: Self) -> Self {
        self.candidates.append(&mut later.candidates);
        for (best, later) in self.right_best.iter_mut().zip(later.right_best) {
            if later.0 < best.0 {
                *best = later;
            }
        }
        self
    }
}

/// Matches the left descriptors against the right ones. Keypoint slices are the frames'
/// keypoints (the sets index into them); `band` gives each left keypoint's candidate rows
/// (`config.gate` is the caller's to turn into it). Output sorted by increasing distance.
pub fn match_descriptors(
    left: &DescriptorSet,
    left_kp: &[Keypoint],
    right: &DescriptorSet,
    right_kp: &[Keypoint],
    config: &MatchConfig,
    band: RowBand<'_>,
) -> Vec<Match> {
    if left.is_empty() || right.is_empty() || left.dim() != right.dim() {
        return Vec::new();
    }
    // Right descriptors sorted by y for the vertical band lookup.
    let mut order: Vec<u32> = (0..right.len() as u32).collect();
    let ry = |j: u32| right_kp[right.keypoint(j as usize)].y;
    order.sort_by(|&a, &b| ry(a).total_cmp(&ry(b)));
    let ys: Vec<f32> = order.iter().map(|&j| ry(j)).collect();
    // The right descriptors copied in y order, so that each band is one contiguous run.
    let dim = right.dim();
    let sorted: Vec<i8> = order
        .iter()
        .flat_map(|&j| right.get(j as usize).iter().map(offset))
        .collect();
    let left_all: Vec<i8> = (0..left.len())
        .flat_map(|i| left.get(i).iter().map(offset))
        .collect();

    // Each left descriptor's best and second-best candidate, and the best left (distance,
    // index) per right descriptor for the cross check. The left descriptors are independent,
    // so both cores scan them; per right descriptor the nearer left one wins, the lower index
    // on a tie, as in one pass in index order.
    let scan = |mut acc: Scan, i: usize| {
        let [top, bottom] = band(&left_kp[left.keypoint(i)]);
        let lo = ys.partition_point(|&y| y < top);
        let hi = ys.partition_point(|&y| y <= bottom).max(lo);
        let d = &left_all[i * dim..(i + 1) * dim];
        let (mut b1, mut b2, mut j1) = (u32::MAX, u32::MAX, u32::MAX);
        for (s, &j) in order[lo..hi].iter().enumerate() {
            let at = (lo + s) * dim;
            let dist = distance_sq(d, &sorted[at..at + dim]);
            if dist < b1 {
                b2 = b1;
                b1 = dist;
                j1 = j;
            } else if dist < b2 {
                b2 = dist;
            }
            let rb = &mut acc.right_best[j as usize];
            if dist < rb.0 {
                *rb = (dist, i as u32);
            }
        }
        if j1 != u32::MAX {
            acc.candidates.push((i as u32, j1, b1, b2));
        }
        acc
    };
    let Scan {
        candidates,
        right_best,
    } = (0..left.len())
        .into_par_iter()
        .with_min_len(MIN_SCAN_CHUNK)
        .fold(|| Scan::new(right.len()), scan)
        .reduce(|| Scan::new(right.len()), Scan::then);
    let r2 = config.ratio * config.ratio;
    let mut out: Vec<Match> = candidates
        .into_iter()
        .filter(|&(i, j, b1, b2)| {
            let ratio_ok = b2 == u32::MAX || (b1 as f32) < r2 * b2 as f32;
            ratio_ok && (!config.cross_check || right_best[j as usize].1 == i)
        })
        .map(|(i, j, b1, b2)| Match {
            left: left.keypoint(i as usize) as u32,
            right: right.keypoint(j as usize) as u32,
            distance: (b1 as f32).sqrt(),
            ratio: if b2 == u32::MAX {
                0.0
            } else {
                (b1 as f32 / b2 as f32).sqrt()
            },
        })
        .collect();
    out.sort_by(|a, b| a.distance.total_cmp(&b.distance));
    if let Some(n) = config.best_n {
        out.truncate(n);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::descriptor::{describe, DescriptorConfig};
    use crate::features::{FeatureFrame, Gradients, SobelPlane};
    use proptest::prelude::*;

    /// A plane whose gradient at `(x, y)` is drawn from `hash(x, y)`.
    fn hashed(width: u32, height: u32, hash: impl Fn(i32, i32) -> u32) -> SobelPlane {
        let mut mag = Vec::new();
        let mut ori = Vec::new();
        for y in 0..height as i32 {
            for x in 0..width as i32 {
                let h = hash(x, y);
                mag.push((h % 200) as u8 + 20);
                ori.push(((h >> 8) % 64) as u8);
            }
        }
        SobelPlane::new(0, width, height, mag, ori).unwrap()
    }

    /// A pseudo-random texture of pixel `(x, y)`.
    fn texture_hash(x: i32, y: i32) -> u32 {
        (x.wrapping_mul(73856093) ^ y.wrapping_mul(19349663)) as u32
    }

    /// The band of rows within `px` of the left keypoint's.
    fn rows(px: f32) -> impl Fn(&Keypoint) -> [f32; 2] + Sync {
        move |k: &Keypoint| [k.y - px, k.y + px]
    }

    fn textured(width: u32, height: u32, dx: i32, dy: i32) -> SobelPlane {
        hashed(width, height, |x, y| texture_hash(x - dx, y - dy))
    }

    fn frame(plane: SobelPlane, pts: &[(f32, f32)]) -> FeatureFrame {
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
        let (w, h) = (plane.width(), plane.height());
        FeatureFrame::new(0, 0, w, h, kps, Gradients::Planes(vec![plane])).unwrap()
    }

    #[test]
    fn shifted_texture_matches_its_own_points() {
        let pts: Vec<(f32, f32)> = (0..40)
            .map(|i| (20.0 + (i % 8) as f32 * 25.0, 20.0 + (i / 8) as f32 * 25.0))
            .collect();
        let right_pts: Vec<(f32, f32)> =
            pts.iter().rev().map(|&(x, y)| (x - 7.0, y + 1.0)).collect();
        let l = frame(textured(240, 160, 0, 0), &pts);
        let r = frame(textured(240, 160, -7, 1), &right_pts);
        let cfg = DescriptorConfig::default();
        let (dl, dr) = (describe(&l, &cfg), describe(&r, &cfg));
        let m = match_descriptors(
            &dl,
            l.keypoints(),
            &dr,
            r.keypoints(),
            &MatchConfig::default(),
            &rows(24.0),
        );
        assert_eq!(m.len(), 40);
        assert!(m
            .iter()
            .all(|m| m.left + m.right == 39 && m.distance == 0.0));
        let few = MatchConfig {
            best_n: Some(20),
            ..MatchConfig::default()
        };
        assert_eq!(
            match_descriptors(&dl, l.keypoints(), &dr, r.keypoints(), &few, &rows(24.0)).len(),
            20
        );
        // A half-pixel band excludes the right points (they are 1 px lower), and so does a band
        // a pixel off in the other direction.
        let cfg = MatchConfig::default();
        assert!(
            match_descriptors(&dl, l.keypoints(), &dr, r.keypoints(), &cfg, &rows(0.5)).is_empty()
        );
        let above = |k: &Keypoint| [k.y - 1.5, k.y - 0.5];
        assert!(match_descriptors(&dl, l.keypoints(), &dr, r.keypoints(), &cfg, &above).is_empty());
        let below = |k: &Keypoint| [k.y + 0.5, k.y + 1.5];
        assert_eq!(
            match_descriptors(&dl, l.keypoints(), &dr, r.keypoints(), &cfg, &below).len(),
            40
        );
    }

    /// A texture that repeats every 8 pixels: keypoints 8 pixels apart get equal descriptors,
    /// so equal distances, the ties the scan must break as one pass in index order would.
    fn periodic(width: u32, height: u32) -> SobelPlane {
        hashed(width, height, |x, y| texture_hash(x % 8, y % 8))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(16))]
        /// The left descriptors are scanned in chunks on several threads; however rayon splits
        /// them, the matches are those of one thread scanning them in order.
        #[test]
        fn chunked_scan_equals_one_pass(
            left in proptest::collection::vec((16u32..224, 16u32..144), 1..300),
            right in proptest::collection::vec((16u32..224, 16u32..144), 1..300),
        ) {
            let points = |p: &[(u32, u32)]| -> Vec<(f32, f32)> {
                p.iter().map(|&(x, y)| (x as f32, y as f32)).collect()
            };
            let (l, r) = (frame(periodic(240, 160), &points(&left)), frame(periodic(240, 160), &points(&right)));
            let cfg = DescriptorConfig::default();
            let (dl, dr) = (describe(&l, &cfg), describe(&r, &cfg));
            let on = |threads: usize| {
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap()
                    .install(|| {
                        match_descriptors(&dl, l.keypoints(), &dr, r.keypoints(), &MatchConfig::default(), &rows(24.0))
                    })
            };
            let one = on(1);
            prop_assert_eq!(&one, &on(8));
            prop_assert_eq!(one, on(3));
        }
    }

    proptest! {
        #[test]
        /// Exercises the simsimd kernel this machine's CPU dispatches to.
        fn distance_matches_the_plain_formula(a in proptest::collection::vec(any::<u8>(), 0..140), seed in any::<u8>()) {
            let b: Vec<u8> = a.iter().map(|v| v.wrapping_mul(seed).wrapping_add(3)).collect();
            let plain: u64 = a.iter().zip(&b).map(|(&x, &y)| ((x as i64 - y as i64).pow(2)) as u64).sum();
            let (ai, bi): (Vec<i8>, Vec<i8>) = (a.iter().map(offset).collect(), b.iter().map(offset).collect());
            prop_assert_eq!(distance_sq(&ai, &bi) as u64, plain);
        }
    }
}
