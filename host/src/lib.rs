//! Host side of stereocal: link, driver, descriptors, matching, essential matrix, Kalman.

pub mod calib;
pub mod descriptor;
pub mod driver;
pub mod essential;
pub mod estimator;
pub mod eval;
pub mod experiments;
pub mod frame;
pub mod hil;
pub mod kalman;
pub mod link;
pub mod matching;
pub mod output_dir;
pub mod plot;
pub mod ransac;
pub mod record;
pub mod reliability;
pub mod report;
pub mod sequence;
pub mod session;
pub mod soak;
pub mod subpixel;
pub mod summary;
pub mod synth;
pub mod verge_csv;
pub mod workload;
