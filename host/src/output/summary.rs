//! Error statistics of a run against ground truth, and the `--json` summary of the CLI contract.

use serde::Serialize;

use crate::misalignment::MisalignmentEstimate;
use crate::output::record::{FrameRecord, FrameStatus};

/// Frames the filter takes to settle after it starts from one raw measurement. Over them its
/// σ falls from the measurement's towards its steady value; their spread is the start-up, not
/// the stability the span measures. Eight: the still model's average of n frames has 1/√n of
/// one frame's σ, a third at eight. Four or sixteen moves neither the rendered road's span
/// nor the fixed KITTI drive's (README, "Sensitivity of the constants").
pub const SETTLING_FRAMES: usize = 8;

/// The first frame of a `frames`-frame run counted as settled: [`SETTLING_FRAMES`], or the
/// first eighth of a shorter run.
pub fn settled_from(frames: usize) -> usize {
    (frames / 8).min(SETTLING_FRAMES)
}

/// Whether a constant offset between estimate and truth is part of the error.
///
/// Synthetic sequences know the verge exactly, so every degree of offset is an error. A real
/// rig's truth (an injected verge on top of the pair's own, unknown residual verge) is only
/// known up to that constant, so it is estimated (median) and removed before the statistics.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Residual {
    /// The truth is exact (rendered sequences): the offset counts as error.
    Keep,
    /// The truth is known up to a constant (`run --truth`): the median offset is removed.
    Remove,
}

/// The JSON object `--json` prints: the fields the CLI contract names, then ours.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Summary {
    /// Frame pairs in the run.
    pub frames: usize,
    /// Pairs with an estimate (status `ok` or `salvaged`).
    pub estimated_frames: usize,
    /// Pairs estimated from what arrived intact of frames that lost packets (`salvaged`).
    pub salvaged_frames: usize,
    /// Link packets the delivered pairs lost, all pairs.
    pub packets_lost: u64,
    /// Keypoints the delivered pairs could not use for what the link lost, all pairs.
    pub keypoints_lost: u64,
    /// Median |raw verge − truth| in degrees, after removing `residual_removed_deg`; `None`
    /// without truth or estimates.
    pub median_abs_err_deg: Option<f64>,
    /// 95th percentile of the same error, degrees.
    pub p95_abs_err_deg: Option<f64>,
    /// Largest of the same error, degrees.
    pub max_abs_err_deg: Option<f64>,
    /// Median |filtered verge − truth| in degrees, after removing `residual_removed_deg`.
    pub filtered_median_abs_err_deg: Option<f64>,
    /// Largest of the same error, degrees.
    pub filtered_max_abs_err_deg: Option<f64>,
    /// Wall time of the whole chain per pair, milliseconds.
    pub ms_per_frame_pair: f64,
    /// Frames that never arrived intact.
    pub dropped_frames: usize,
    /// The constant offset removed before the error statistics (0 when kept).
    pub residual_removed_deg: f64,
    /// Peak-to-peak range of the filtered estimate once the filter has settled: over the
    /// frames after the first [`SETTLING_FRAMES`] (or the first eighth of a shorter run).
    /// This is the thesis' fixed-camera "span" (fig. 5.2).
    pub filtered_span_deg: Option<f64>,
    /// Median number of ratio-test matches per estimated frame.
    pub median_matches: Option<f64>,
    /// Bytes on the wire per frame pair, both cameras, as measured on the link.
    pub wire_bytes_per_pair: f64,
    /// The misalignment window's estimate after the last frame it saw, with its 1-σ;
    /// `null` without a window.
    pub misalignment: Option<MisalignmentEstimate>,
}

/// Work measured while producing the records.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunCost {
    /// Wall time of the whole chain per pair, milliseconds.
    pub ms_per_frame_pair: f64,
    /// Bytes on the link per pair, both cameras.
    pub wire_bytes_per_pair: f64,
}

impl Summary {
    /// Summarise the records of one run.
    pub fn from_records(records: &[FrameRecord], residual: Residual, cost: RunCost) -> Self {
        let estimated: Vec<&FrameRecord> =
            records.iter().filter(|r| r.status.has_estimate()).collect();
        let raw_pairs: Vec<(f64, f64)> = estimated
            .iter()
            .filter_map(|r| Some((r.raw_verge_deg?, r.truth_deg?)))
            .collect();
        let offset = match residual {
            Residual::Keep => 0.0,
            Residual::Remove => {
                median(&raw_pairs.iter().map(|(e, t)| e - t).collect::<Vec<_>>()).unwrap_or(0.0)
            }
        };
        let raw_err: Vec<f64> = raw_pairs
            .iter()
            .map(|(e, t)| (e - t - offset).abs())
            .collect();
        let filtered_err: Vec<f64> = estimated
            .iter()
            .filter_map(|r| Some((r.filtered_verge_deg? - r.truth_deg? - offset).abs()))
            .collect();
        let settled_from = settled_from(records.len());
        let filtered: Vec<f64> = estimated
            .iter()
            .filter(|r| r.frame >= settled_from)
            .filter_map(|r| r.filtered_verge_deg)
            .collect();
        let span = filtered
            .iter()
            .copied()
            .fold(None, |acc: Option<(f64, f64)>, v| match acc {
                None => Some((v, v)),
                Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
            })
            .map(|(lo, hi)| hi - lo);
        let matches: Vec<f64> = estimated.iter().map(|r| r.matches as f64).collect();
        Summary {
            frames: records.len(),
            estimated_frames: estimated.len(),
            salvaged_frames: records
                .iter()
                .filter(|r| r.status == FrameStatus::Salvaged)
                .count(),
            packets_lost: records
                .iter()
                .filter_map(|r| r.link_loss)
                .map(|l| u64::from(l.packets_lost))
                .sum(),
            keypoints_lost: records
                .iter()
                .filter_map(|r| r.link_loss)
                .map(|l| u64::from(l.keypoints_lost))
                .sum(),
            median_abs_err_deg: median(&raw_err),
            p95_abs_err_deg: percentile(&raw_err, 0.95),
            max_abs_err_deg: raw_err.iter().copied().reduce(f64::max),
            filtered_median_abs_err_deg: median(&filtered_err),
            filtered_max_abs_err_deg: filtered_err.iter().copied().reduce(f64::max),
            ms_per_frame_pair: cost.ms_per_frame_pair,
            dropped_frames: records
                .iter()
                .filter(|r| r.status == FrameStatus::Dropped)
                .count(),
            residual_removed_deg: offset,
            filtered_span_deg: span,
            median_matches: median(&matches),
            wire_bytes_per_pair: cost.wire_bytes_per_pair,
            misalignment: records.iter().rev().find_map(|r| r.misalignment),
        }
    }

    /// Fraction of frames that produced a measurement.
    pub fn estimated_fraction(&self) -> f64 {
        if self.frames == 0 {
            0.0
        } else {
            self.estimated_frames as f64 / self.frames as f64
        }
    }
}

/// Median; `None` for no values.
pub fn median(values: &[f64]) -> Option<f64> {
    percentile(values, 0.5)
}

/// Linear-interpolated percentile (`q` in 0..=1); `None` for no values.
pub fn percentile(values: &[f64], q: f64) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let pos = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let lo = pos.floor() as usize;
    let hi = pos.ceil() as usize;
    Some(sorted[lo] + (sorted[hi] - sorted[lo]) * (pos - lo as f64))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(frame: usize, raw: Option<f64>, truth: f64, status: FrameStatus) -> FrameRecord {
        FrameRecord {
            raw_verge_deg: raw,
            filtered_verge_deg: raw,
            filtered_sigma_deg: raw.map(|_| 0.01),
            matches: 100,
            inliers: 90,
            status,
            ..FrameRecord::dropped(frame, Some(truth))
        }
    }

    const COST: RunCost = RunCost {
        ms_per_frame_pair: 1.0,
        wire_bytes_per_pair: 10.0,
    };

    #[test]
    fn percentiles_interpolate() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[1.0, 2.0, 3.0, 4.0]), Some(2.5));
        assert_eq!(percentile(&[0.0, 10.0], 0.95), Some(9.5));
        assert_eq!(median(&[]), None);
    }

    #[test]
    fn residual_is_removed_only_when_asked() {
        let records = vec![
            rec(0, Some(1.5), 1.0, FrameStatus::Ok),
            rec(1, Some(2.5), 2.0, FrameStatus::Ok),
            rec(2, Some(3.6), 3.0, FrameStatus::Ok),
            rec(3, None, 4.0, FrameStatus::NoEstimate),
            rec(4, None, 5.0, FrameStatus::Dropped),
        ];
        let kept = Summary::from_records(&records, Residual::Keep, COST);
        assert_eq!(kept.frames, 5);
        assert_eq!(kept.estimated_frames, 3);
        assert_eq!(kept.dropped_frames, 1);
        assert!((kept.median_abs_err_deg.unwrap() - 0.5).abs() < 1e-12);
        assert!((kept.max_abs_err_deg.unwrap() - 0.6).abs() < 1e-12);

        let removed = Summary::from_records(&records, Residual::Remove, COST);
        assert!((removed.residual_removed_deg - 0.5).abs() < 1e-12);
        assert!(removed.median_abs_err_deg.unwrap() < 1e-12);
        assert!((removed.max_abs_err_deg.unwrap() - 0.1).abs() < 1e-12);
        assert!((removed.filtered_span_deg.unwrap() - 2.1).abs() < 1e-12);
    }

    #[test]
    fn span_leaves_out_the_filter_start_up() {
        let mut records: Vec<FrameRecord> = (0..80)
            .map(|i| rec(i, Some(1.0), 1.0, FrameStatus::Ok))
            .collect();
        records[SETTLING_FRAMES - 1].filtered_verge_deg = Some(1.5);
        records[SETTLING_FRAMES + 3].filtered_verge_deg = Some(1.02);
        let s = Summary::from_records(&records, Residual::Keep, COST);
        assert!((s.filtered_span_deg.unwrap() - 0.02).abs() < 1e-12);
    }

    #[test]
    fn no_estimates_give_no_statistics() {
        let records = vec![rec(0, None, 1.0, FrameStatus::NoEstimate)];
        let s = Summary::from_records(&records, Residual::Remove, COST);
        assert_eq!(s.estimated_frames, 0);
        assert_eq!(s.median_abs_err_deg, None);
        assert_eq!(s.estimated_fraction(), 0.0);
    }
}
