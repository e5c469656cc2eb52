//! Online verge-angle calibration of an active stereo head, host side: the library a user
//! embeds.
//!
//! Camera pairs go into a device (the fabric and its soft-core, in this process, under an
//! emulator or on a board), come back over a byte link as wire packets, and leave as one
//! [`FrameRecord`](output::record::FrameRecord) per pair with the raw and filtered verge
//! angle. [`Session`](session::Session) runs that chain; `examples/embed.rs` feeds it a user's
//! own frames. The pipeline, in the order the data takes it:
//!
//! | stage | module |
//! |---|---|
//! | byte links to a device | [`link`] |
//! | the wire's packets reassembled into camera frames | [`driver`] |
//! | a camera frame's keypoints and gradients | [`features`] |
//! | descriptors, matching in the epipolar band, sub-pixel refinement | [`descriptor`], [`epipolar_band`], [`matching`], [`subpixel`] |
//! | essential matrix constrained to the head, RANSAC | [`essential`], [`ransac`] |
//! | one pair's verge | [`estimator`] |
//! | over time: the Kalman filter, the head's fixed misalignments, its encoders | [`kalman`], [`misalignment`], [`encoders`] |
//! | the chain, pair by pair | [`session`] |
//! | what a run writes | [`output`] |
//!
//! Inputs besides the link: the rig's calibration ([`calib`]) and recorded image sequences
//! ([`image_sequence`]). The data path, frames and signs and every file format are in
//! `docs/ARCHITECTURE.md`.

#![warn(missing_docs)]

pub mod calib;
pub mod descriptor;
pub mod driver;
pub mod encoders;
pub mod epipolar_band;
pub mod essential;
pub mod estimator;
pub mod features;
pub mod image_sequence;
pub mod kalman;
pub mod link;
pub mod matching;
pub mod misalignment;
pub mod output;
pub mod ransac;
pub mod session;
pub mod subpixel;
pub mod window_overlap;
