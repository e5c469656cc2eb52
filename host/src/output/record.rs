//! One row of the per-frame verge output: what the estimator said about one frame pair.
//!
//! This is the unit every output (CSV, plot, summary) is made from, so the three can never
//! disagree about a frame.

use std::fmt;

use crate::estimator::ConsistentPair;
use crate::misalignment::MisalignmentEstimate;

/// Whether a frame pair produced a measurement.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameStatus {
    /// The estimator produced a verge measurement.
    Ok,
    /// The estimator produced a verge measurement from what arrived intact of a pair that
    /// lost packets on the link (the record's [`LinkLoss`] says how much).
    Salvaged,
    /// The frame arrived intact but held too little geometry to measure the verge
    /// (texture-less scene, too few consistent matches).
    NoEstimate,
    /// The frame never arrived intact (damaged on the link, lost, or dropped at the source).
    Dropped,
}

impl FrameStatus {
    /// The spelling used in `verge.csv`.
    pub fn as_str(self) -> &'static str {
        match self {
            FrameStatus::Ok => "ok",
            FrameStatus::Salvaged => "salvaged",
            FrameStatus::NoEstimate => "no_estimate",
            FrameStatus::Dropped => "dropped",
        }
    }
}

impl FrameStatus {
    /// Whether the pair gave a verge measurement (`Ok` or `Salvaged`).
    pub fn has_estimate(self) -> bool {
        matches!(self, FrameStatus::Ok | FrameStatus::Salvaged)
    }
}

impl fmt::Display for FrameStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The estimator's output for one frame pair, plus the truth when it is known.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameRecord {
    /// Index of the frame pair in the sequence.
    pub frame: usize,
    /// The per-frame measurement, `None` unless the pair has an estimate
    /// ([`FrameStatus::has_estimate`]).
    pub raw_verge_deg: Option<f64>,
    /// The measurement's own 1-σ uncertainty (degrees), `None` unless the pair has an
    /// estimate.
    pub raw_sigma_deg: Option<f64>,
    /// The Kalman estimate after this frame, `None` unless the pair has an estimate.
    pub filtered_verge_deg: Option<f64>,
    /// One standard deviation of the Kalman estimate, `None` unless the pair has an estimate.
    pub filtered_sigma_deg: Option<f64>,
    /// Matches that passed the ratio test.
    pub matches: usize,
    /// Point pairs consistent with the estimated geometry. They include the guided matches
    /// (left keypoints without a descriptor match, found by correlation near their
    /// neighbours' disparity), so `inliers` can exceed `matches`.
    pub inliers: usize,
    /// Left keypoints by octave (index 0 = full resolution), empty unless the pair has an
    /// estimate.
    pub keypoints_per_octave: Vec<usize>,
    /// `matches` by the octave of the left keypoint, empty unless the pair has an estimate.
    pub matches_per_octave: Vec<usize>,
    /// Whether the pair gave a measurement (`status` in `verge.csv`).
    pub status: FrameStatus,
    /// Ground-truth verge, when a truth file or the renderer gives it.
    pub truth_deg: Option<f64>,
    /// Why a `Dropped` pair was dropped, as the host driver found it (the first damage of
    /// each damaged camera frame, or what never arrived); `None` otherwise.
    pub dropped_because: Option<String>,
    /// The misalignment window's estimate after this frame, when the session runs one.
    pub misalignment: Option<MisalignmentEstimate>,
    /// What the link cost the pair's two frames when they were delivered salvaged; `None`
    /// when both arrived whole (or the pair was dropped).
    pub link_loss: Option<LinkLoss>,
    /// The point pairs consistent with the estimate (`inliers` of them), kept only when the
    /// session keeps them ([`crate::session::SessionConfig::keep_pairs`]) and the pair has an
    /// estimate; empty otherwise.
    pub consistent_pairs: Vec<ConsistentPair>,
}

impl FrameRecord {
    /// The record of pair `frame` before anything about it is known: `Dropped`, with no
    /// measurement, counts or losses; the session fills in what the pair brings.
    pub fn dropped(frame: usize, truth_deg: Option<f64>) -> Self {
        Self {
            frame,
            raw_verge_deg: None,
            raw_sigma_deg: None,
            filtered_verge_deg: None,
            filtered_sigma_deg: None,
            matches: 0,
            inliers: 0,
            keypoints_per_octave: Vec::new(),
            matches_per_octave: Vec::new(),
            status: FrameStatus::Dropped,
            truth_deg,
            dropped_because: None,
            misalignment: None,
            link_loss: None,
            consistent_pairs: Vec::new(),
        }
    }
}

/// What a delivered pair lost on the link, both cameras together.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LinkLoss {
    /// Packets the sequence numbers show missing.
    pub packets_lost: u32,
    /// Keypoints the frames could not use: points and patches lost, and keypoints whose
    /// gradient window touches a lost pixel.
    pub keypoints_lost: u32,
}
