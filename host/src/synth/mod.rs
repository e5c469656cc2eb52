//! Ground truth: synthetic stereo-head sequences and exact verge injection into real pairs.
pub mod inject;
