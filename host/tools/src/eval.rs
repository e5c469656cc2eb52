//! Ground-truth runs: a rendered sequence through the whole chain (fabric model → wire →
//! host), each record carrying the renderer's exact verge.
//!
//! Rendering runs on its own thread a few frames ahead of the chain, so the two overlap on a
//! multi-core machine; the session's cost counts only the chain.

use std::sync::mpsc;

use stereocal::calib::{CalibError, Calibration};
use stereocal::link::{FrameInput, Link};
use stereocal::output::record::FrameRecord;
use stereocal::session::{Session, SessionConfig, SessionCost, SessionError};
use stereocal_synth::{Sequence, StereoFrame, SynthError};

/// Frames rendered ahead of the chain.
const LOOKAHEAD: usize = 3;

/// Why a ground-truth run failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EvalError {
    #[error(transparent)]
    Synth(#[from] SynthError),
    #[error("synthetic calibration: {0}")]
    Calib(#[from] CalibError),
    #[error(transparent)]
    Session(#[from] SessionError),
    #[error("frame {frame}: image size {width}x{height} does not fit the fabric's registers")]
    Size {
        frame: usize,
        width: u32,
        height: u32,
    },
}

/// The calibration the renderer's cameras have.
pub fn sequence_calibration(sequence: &Sequence) -> Result<Calibration, CalibError> {
    Calibration::from_toml_str(&sequence.calib_toml(), "<synthetic head>")
}

/// Runs every frame of `sequence`; `progress` is called after each frame.
pub fn evaluate(
    sequence: &Sequence,
    config: SessionConfig,
    progress: &mut dyn FnMut(&FrameRecord),
) -> Result<(Vec<FrameRecord>, SessionCost), EvalError> {
    let calib = sequence_calibration(sequence)?;
    let (w, h) = fabric_size(sequence)?;
    let mut session = Session::new(calib, w, h, config)?;
    std::thread::scope(|scope| {
        let (tx, rx) = mpsc::sync_channel::<Result<StereoFrame, SynthError>>(LOOKAHEAD);
        scope.spawn(move || {
            for index in 0..sequence.len() {
                let frame = sequence.frame(index);
                let stop = frame.is_err();
                if tx.send(frame).is_err() || stop {
                    break;
                }
            }
        });
        let records = evaluate_frames(&mut session, sequence, rx, progress)?;
        Ok((records, session.cost()))
    })
}

/// The sequence's image size as the fabric's WIDTH and HEIGHT registers hold it.
pub fn fabric_size(sequence: &Sequence) -> Result<(u16, u16), EvalError> {
    let (width, height) = sequence.image_size();
    let size = || EvalError::Size {
        frame: 0,
        width,
        height,
    };
    Ok((
        u16::try_from(width).map_err(|_| size())?,
        u16::try_from(height).map_err(|_| size())?,
    ))
}

/// Runs `frames` of `sequence` (rendered by the caller, in order) through `session`, on
/// whatever device it has; `progress` is called after each frame. The session keeps its
/// cost and its device, so the caller can stop the device and tell why a run failed.
pub fn evaluate_frames<D: Link + FrameInput>(
    session: &mut Session<D>,
    sequence: &Sequence,
    frames: impl IntoIterator<Item = Result<StereoFrame, SynthError>>,
    progress: &mut dyn FnMut(&FrameRecord),
) -> Result<Vec<FrameRecord>, EvalError> {
    let (width, height) = sequence.image_size();
    let mut records = Vec::with_capacity(sequence.len());
    for frame in frames {
        let frame = frame?;
        let images = frame
            .images
            .as_ref()
            .map(|i| (i.left.as_raw().as_slice(), i.right.as_raw().as_slice()));
        let record = session.submit(
            frame.index,
            images,
            (width as usize, height as usize),
            frame.timestamp_us,
            Some(frame.truth.verge_deg),
        )?;
        if let Some(record) = record {
            progress(&record);
            records.push(record);
        }
    }
    while let Some(record) = session.flush()? {
        progress(&record);
        records.push(record);
    }
    Ok(records)
}
