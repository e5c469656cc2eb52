//! Host side of stereocal: link, driver, descriptors, matching, essential matrix, Kalman.

pub mod calib;
pub mod descriptor;
pub mod driver;
pub mod essential;
pub mod estimator;
pub mod frame;
pub mod kalman;
pub mod link;
pub mod matching;
pub mod ransac;
pub mod subpixel;
pub mod synth;
