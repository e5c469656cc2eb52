//! What a camera frame delivered with known losses lost, and how much loss a frame may have
//! and still be delivered.
//!
//! Every packet that passed its CRC is genuine device data that names its own place (a point
//! its octave and pixel, a Sobel row its octave and row, a patch its point's octave and
//! pixel), so a frame missing some packets is still right in what it holds: the driver
//! delivers it with the rows it lacks marked invalid in their planes, and the descriptor and
//! the sub-pixel refinement skip every window touching such a row.
//!
//! The loss limit keeps a salvaged pair's estimate within its own sigma of the intact pair's.
//! An estimate from a fraction `1 - f` of the keypoints is the whole's plus an independent
//! part whose variance is the fraction `f` of its own: the two differ by more than the
//! subset's sigma with the probability of a normal deviate beyond `1 / sqrt(f)`. A pair's two
//! frames lose their keypoints independently, so at most `2 f` of its matches go; at the limit
//! `f = 0.05` that is beyond 3.2 sigma, 0.16 % of such pairs, and most salvaged pairs lose far
//! less. A lost row costs every keypoint whose window touches it (16 rows of its octave), and
//! a lost full-resolution row also every keypoint, of any octave, within the sub-pixel
//! refinement's reach of it (`SubpixelConfig::reach_px`: the match's refinement reads those
//! rows, and the argument counts the matches the estimate loses); so the limit counts
//! keypoints, not rows. `stereocal reliability` measures the moves against the argument
//! (docs/RELIABILITY.md, "How far salvage moves an estimate").

/// The largest fraction of a frame's keypoints a salvaged frame may have lost (points or
/// patches that did not arrive, and keypoints whose window touches a lost row or whose
/// refinement reach holds a lost full-resolution pixel).
pub const MAX_LOST_FRACTION: f64 = 0.05;

/// What a salvaged camera frame lost on the link.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Salvage {
    /// Packets of the frame's channel that the sequence numbers show missing while the frame
    /// was open.
    pub packets_lost: u32,
    /// Sobel rows missing, per octave (index 0 = full resolution); empty in patches mode.
    pub rows_lost: Vec<u32>,
    /// Points the `FrameEnd` announced that did not arrive; `None` when the `FrameEnd` was
    /// lost, so the total is unknown.
    pub points_lost: Option<u32>,
    /// `SobelPatch` packets the `FrameEnd` announced that did not arrive (0 in rows mode);
    /// `None` when the `FrameEnd` was lost.
    pub patches_lost: Option<u32>,
    /// Keypoints the frame cannot use: points and patches lost, and keypoints whose window
    /// touches a lost row.
    pub keypoints_lost: u32,
}

impl Salvage {
    /// Sobel rows missing, all octaves.
    pub fn rows_lost_total(&self) -> u32 {
        self.rows_lost.iter().sum()
    }

    /// Whether the frame's `FrameEnd` (and so its totals) was lost.
    pub fn end_lost(&self) -> bool {
        self.points_lost.is_none()
    }
}

/// Whether `lost` of `total` is within the fraction `limit`.
pub(crate) fn within_limit(lost: u32, total: u32, limit: f64) -> bool {
    f64::from(lost) <= limit * f64::from(total)
}
