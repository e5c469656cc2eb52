//! Ground truth for the calibration library: synthetic stereo-head sequences and exact verge
//! injection into real pairs.
//!
//! The renderer ([`Sequence`]) ray-casts a deterministic (seeded ChaCha) 3D scene through two
//! pinhole cameras on a verge head (baseline 0.3 m by default, right camera at +x, each camera yawing about
//! its own vertical axis; verge = alpha_l - alpha_r, toe-in positive), optionally tilted and
//! driven along a road. Projection and occlusion are exact; only the pixel integration is
//! sampled (see `render.rs`), so the truth it reports is the truth in the pixels.
pub mod injected;
pub mod yaw_warp;

mod camera;
mod layout;
mod render;
mod rendered;
mod scene;
mod texture;
mod trajectory;

use std::path::PathBuf;

pub use camera::{CameraPose, Intrinsics, Side};
pub use render::{MotionBlur, Supersampling};
pub use rendered::{
    Frames, Sequence, SequenceConfig, StereoFrame, StereoImages, Truth, BASELINE_M,
};
pub use scene::{Material, Pattern, Scene, SceneBox, SceneKind, Sky, Surface, TextureKind};
pub use trajectory::{HeadGeometry, HeadState, Trajectory, TrajectoryKind, FIXED_VERGE_DEG};

/// Why a synthetic sequence could not be made or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SynthError {
    #[error("unknown scene `{0}` (expected road, lab or sparse)")]
    UnknownScene(String),
    #[error("unknown trajectory `{0}` (expected manual, fixed or steps)")]
    UnknownTrajectory(String),
    #[error("synth config: `{field}` {reason}")]
    InvalidConfig { field: &'static str, reason: String },
    #[error("the head would move over z = {from_m:.1}..{to_m:.1} m but the scene is furnished over {scene_from_m:.1}..{scene_to_m:.1} m (fewer frames or a lower speed)")]
    OutsideScene {
        from_m: f64,
        to_m: f64,
        scene_from_m: f64,
        scene_to_m: f64,
    },
    #[error("frame {index} does not exist (the sequence has {len})")]
    FrameOutOfRange { index: usize, len: usize },
    #[error("output directory {0} is not empty")]
    OutputNotEmpty(PathBuf),
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error(transparent)]
    Sequence(#[from] stereocal::image_sequence::SequenceError),
    #[error("{path}: {source}")]
    Image {
        path: PathBuf,
        #[source]
        source: image::ImageError,
    },
}
