//! A run on the soft-core from start to end: the machine (QEMU or the SoC's board) started
//! with the frames, a session on it, the machine stopped, and every failure named.

use rayon::prelude::*;

use super::device_log::{DeviceLog, LogDecoder};
use super::machine::{MachineConfig, MachineDevice, MachineEnd};
use super::soc_report::SocReport;
use super::stream_compare::{compare_streams, StreamMismatch};
use super::{GrabberInput, HilError, TimeoutKind};
use crate::eval::{evaluate_frames, fabric_size, sequence_calibration, EvalError};
use stereocal::driver::DriverError;
use stereocal::link::{InProcessLink, Recording};
use stereocal::output::record::FrameRecord;
use stereocal::session::{Session, SessionConfig, SessionCost, SessionError};
use stereocal_synth::Sequence;

/// What a run on the machine gave.
#[derive(Debug)]
pub struct MachineRun<T> {
    /// What the session computed.
    pub value: T,
    /// How the machine ended (success: every frame ran) and every byte the firmware sent.
    pub end: MachineEnd,
    /// The firmware's logs, decoded with the ELF's defmt table.
    pub logs: Vec<DeviceLog>,
    /// What the SoC in the loop's board measured ([`MachineConfig::soc`]); `None` under QEMU.
    pub board: Option<SocReport>,
}

/// What `stereocal hil` gave: the run on the device, and the same frames on the in-process
/// device beside it.
#[derive(Debug)]
pub struct SequenceRun {
    /// The run on the device: records and the session's cost.
    pub device: MachineRun<(Vec<FrameRecord>, SessionCost)>,
    /// Whether the device's bytes after its `Hello` were the in-process device's; `None` when
    /// the firmware counted instructions (its reports are extra `Log` packets on the link).
    pub wire: Option<Result<(), StreamMismatch>>,
    /// Whether the host's records of both runs are equal, field by field (floats by `==`).
    pub records_identical: bool,
}

/// Starts the machine on `config.elf` with `input` in its frame region, runs `session` on the
/// device, and ends the machine: when `session` succeeds, by reading the UART to its end and
/// requiring the firmware's success exit; otherwise by stopping it (see
/// [`MachineDevice::abort`]) and returning the failure with the machine's status and the firmware's
/// logs. An answer timeout inside the session is reported as [`HilError::Timeout`].
pub fn run_on_machine<T>(
    config: &MachineConfig,
    input: &GrabberInput,
    session: impl FnOnce(&mut MachineDevice) -> Result<T, EvalError>,
) -> Result<MachineRun<T>, HilError> {
    let decoder = LogDecoder::from_elf(&config.elf)?;
    let mut device = MachineDevice::start(config, input)?;
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
            let board = config.soc.is_some().then(|| SocReport::parse(&end.stderr));
            Ok(MachineRun {
                value,
                end,
                logs,
                board,
            })
        }
        Err(source) => {
            let silent = device.silent_for();
            let end = device.abort();
            let log = messages(&decoder.logs(&end.transcript));
            Err(match source {
                EvalError::Session(SessionError::Driver(DriverError::Timeout {
                    waiting_for,
                    timeout,
                })) => HilError::Timeout {
                    kind: TimeoutKind::Answer,
                    limit: timeout,
                    waiting_for: waiting_for.to_string(),
                    log,
                },
                _ if silent.is_some() => HilError::Timeout {
                    kind: TimeoutKind::Silence,
                    limit: config.timeouts.silence,
                    waiting_for: "any byte from the device (the firmware hangs, or the machine \
                                  stopped)"
                        .into(),
                    log,
                },
                source => HilError::Device {
                    source: Box::new(source),
                    exit: end.exit,
                    log,
                    stderr: end.stderr,
                },
            })
        }
    }
}

/// `stereocal hil`: every frame of `sequence` through the firmware on the machine, then the host
/// chain exactly as `eval` runs it on the in-process device; `progress` is called after each
/// frame. Then the same frames on the in-process device, whose bytes and records the device's
/// are compared with.
pub fn run_sequence(
    config: &MachineConfig,
    sequence: &Sequence,
    session_config: SessionConfig,
    progress: &mut dyn FnMut(&FrameRecord),
) -> Result<SequenceRun, HilError> {
    let calib = sequence_calibration(sequence).map_err(EvalError::from)?;
    let (width, height) = fabric_size(sequence)?;
    // The machine needs every pair before it boots, so the whole sequence is rendered first.
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
    let device = run_on_machine(config, &input, |device| {
        let mut session = Session::with_device(device, calib, width, height, session_config)?;
        let records = evaluate_frames(
            &mut session,
            sequence,
            frames.iter().cloned().map(Ok),
            progress,
        )?;
        Ok((records, session.cost()))
    })?;

    let mut in_process = Recording::new(InProcessLink::new()?);
    let mut session = Session::with_device(&mut in_process, calib, width, height, session_config)
        .map_err(EvalError::from)?;
    let records = evaluate_frames(
        &mut session,
        sequence,
        frames.into_iter().map(Ok),
        &mut |_| {},
    )?;
    drop(session);
    let wire = (!config.count_instructions)
        .then(|| compare_streams(&device.end.transcript, &in_process.take_received()));
    let records_identical = records == device.value.0;
    Ok(SequenceRun {
        device,
        wire,
        records_identical,
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
