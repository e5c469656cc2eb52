//! The tools around the calibration library, kept out of what a user links: the generators
//! of `docs/` (the thesis' experiments, the link-fault sweep, the soak), ground-truth runs of
//! rendered sequences, and the runners of the firmware under an emulator.

pub mod eval;
pub mod experiments;
pub mod hil;
pub mod reliability;
pub mod soak;
pub mod workload;
