//! A run on the emulated soft-core from start to end: QEMU started with the frames, a session
//! on it, QEMU stopped, and every failure named.

use rayon::prelude::*;

use super::device_log::{DeviceLog, LogDecoder};
use super::qemu::{QemuConfig, QemuDevice, QemuEnd};
use super::{GrabberInput, HilError, TimeoutKind};
use crate::eval::{evaluate_frames, fabric_size, sequence_calibration, EvalError};
use stereocal::driver::DriverError;
use stereocal::output::record::FrameRecord;
use stereocal::session::{Session, SessionConfig, SessionCost, SessionError};
use stereocal_synth::Sequence;

/// What a run on QEMU gave.
#[derive(Debug)]
pub struct QemuRun<T> {
    /// What the session computed.
    pub value: T,
    /// How QEMU ended (success: every frame ran) and every byte the firmware sent.
    pub end: QemuEnd,
    /// The firmware's logs, decoded with the ELF's defmt table.
    pub logs: Vec<DeviceLog>,
}

/// Starts QEMU on `config.elf` with `input` in its frame region, runs `session` on the
/// device, and ends QEMU: when `session` succeeds, by reading the UART to its end and
/// requiring the firmware's success exit; otherwise by stopping it (see
/// [`QemuDevice::abort`]) and returning the failure with QEMU's status and the firmware's
/// logs. An answer timeout inside the session is reported as [`HilError::Timeout`].
pub fn run_on_qemu<T>(
    config: &QemuConfig,
    input: &GrabberInput,
    session: impl FnOnce(&mut QemuDevice) -> Result<T, EvalError>,
) -> Result<QemuRun<T>, HilError> {
    let decoder = LogDecoder::from_elf(&config.elf)?;
    let mut device = QemuDevice::start(config, input)?;
    match session(&mut device) {
        Ok(value) => {
            let end = device.finish()?;
            let logs = decoder.logs(&end.transcript);
            if !end.exit.is_success() {
                return Err(HilError::Firmware {
                    exit: end.exit,
                    log: messages(&logs),
                });
            }
            Ok(QemuRun { value, end, logs })
        }
        Err(source) => {
            let end = device.abort();
            Err(match source {
                EvalError::Session(SessionError::Driver(DriverError::Timeout {
                    waiting_for,
                    timeout,
                })) => HilError::Timeout {
                    kind: TimeoutKind::Answer,
                    limit: timeout,
                    waiting_for: waiting_for.to_string(),
                },
                source => HilError::Device {
                    source: Box::new(source),
                    exit: end.exit,
                    log: messages(&decoder.logs(&end.transcript)),
                    stderr: end.stderr,
                },
            })
        }
    }
}

/// `stereocal hil`: every frame of `sequence` through the firmware under QEMU, then the host
/// chain exactly as `eval` runs it on the in-process device; `progress` is called after each
/// frame. Returns the records and the session's cost.
pub fn run_sequence(
    config: &QemuConfig,
    sequence: &Sequence,
    session_config: SessionConfig,
    progress: &mut dyn FnMut(&FrameRecord),
) -> Result<QemuRun<(Vec<FrameRecord>, SessionCost)>, HilError> {
    let calib = sequence_calibration(sequence).map_err(EvalError::from)?;
    let (width, height) = fabric_size(sequence)?;
    // QEMU needs every pair before it boots, so the whole sequence is rendered first.
    let frames = (0..sequence.len())
        .into_par_iter()
        .map(|index| sequence.frame(index))
        .collect::<Result<Vec<_>, _>>()
        .map_err(EvalError::from)?;
    let mut input = GrabberInput::new(width, height);
    for frame in &frames {
        if let Some(images) = &frame.images {
            input.push_pair(
                images.left.as_raw(),
                images.right.as_raw(),
                frame.timestamp_us,
            )?;
        }
    }
    run_on_qemu(config, &input, |device| {
        let mut session = Session::with_device(device, calib, width, height, session_config)?;
        let records =
            evaluate_frames(&mut session, sequence, frames.into_iter().map(Ok), progress)?;
        Ok((records, session.cost()))
    })
}

/// The logs with a level (not the instruction reports), one a line.
fn messages(logs: &[DeviceLog]) -> String {
    logs.iter()
        .filter(|log| log.level.is_some())
        .map(|log| log.to_string())
        .collect::<Vec<_>>()
        .join("\n")
}
