//! Rendered frame pairs held in memory, with their exact truth: what the reliability sweep and
//! the soak submit to a device over and over, so every run sees the same bytes.

use rayon::prelude::*;

use crate::eval::{fabric_size, sequence_calibration, EvalError};
use stereocal::calib::{CalibError, Calibration};
use stereocal_synth::{SceneKind, Sequence, SequenceConfig, SynthError};

/// Why a workload could not be rendered.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WorkloadError {
    #[error(transparent)]
    Synth(#[from] SynthError),
    #[error("synthetic calibration: {0}")]
    Calib(#[from] CalibError),
    #[error(transparent)]
    Size(#[from] EvalError),
    #[error("frame {frame} was dropped by the renderer; the workload needs every frame")]
    DroppedFrame { frame: usize },
}

/// One rendered pair.
#[derive(Debug, Clone)]
pub struct Pair {
    /// Left image, raster order, `width * height` grey pixels.
    pub left: Vec<u8>,
    /// Right image, likewise.
    pub right: Vec<u8>,
    /// The verge the renderer used (degrees).
    pub truth_deg: f64,
}

/// Rendered pairs, their calibration and the fabric frame size.
#[derive(Debug, Clone)]
pub struct Workload {
    pub calib: Calibration,
    pub width: u16,
    pub height: u16,
    pub pairs: Vec<Pair>,
    fps: f64,
}

impl Workload {
    /// Renders the road scene at `width` x `height` for `frames` frames from `seed`
    /// (frames in parallel).
    pub fn road(frames: usize, seed: u64, width: u32, height: u32) -> Result<Self, WorkloadError> {
        let config = SequenceConfig {
            width,
            height,
            frames,
            seed,
            ..SequenceConfig::for_scene(SceneKind::Road)
        };
        let fps = config.fps;
        let sequence = Sequence::builtin(SceneKind::Road, config)?;
        let (w, h) = fabric_size(&sequence)?;
        let calib = sequence_calibration(&sequence)?;
        let pairs = (0..sequence.len())
            .into_par_iter()
            .map(|index| {
                let frame = sequence.frame(index)?;
                let images = frame
                    .images
                    .ok_or(WorkloadError::DroppedFrame { frame: index })?;
                Ok(Pair {
                    left: images.left.into_raw(),
                    right: images.right.into_raw(),
                    truth_deg: frame.truth.verge_deg,
                })
            })
            .collect::<Result<Vec<_>, WorkloadError>>()?;
        Ok(Self {
            calib,
            width: w,
            height: h,
            pairs,
            fps,
        })
    }

    /// Frame pairs.
    pub fn len(&self) -> usize {
        self.pairs.len()
    }

    /// Whether there are no frames.
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }

    /// `(width, height)` as the session takes it.
    pub fn size(&self) -> (usize, usize) {
        (usize::from(self.width), usize::from(self.height))
    }

    /// Capture time of frame `index` at the scene's frame rate; indices past the rendered
    /// pairs continue the clock (a cycled workload keeps advancing time).
    pub fn timestamp_us(&self, index: usize) -> u64 {
        (index as f64 / self.fps * 1e6).round() as u64
    }
}
