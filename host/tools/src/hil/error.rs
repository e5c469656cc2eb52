//! What can go wrong in a hardware-in-the-loop run, and how the emulator ended.

use std::fmt;
use std::io;
use std::path::PathBuf;
use std::process::ExitStatus;
use std::time::Duration;

use stereocal_firmware::softcore::finisher::ExitCode;

use crate::eval::EvalError;
use stereocal::link::LinkError;

/// The timeouts of a run, by name: an error says which one fired.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeoutKind {
    /// The machine to open its UART socket after it was started.
    Startup,
    /// The device to answer one request (Hello, a register read) or deliver one frame pair.
    Answer,
    /// The firmware to end the simulation after the last frame.
    Exit,
    /// The device to send anything at all.
    Silence,
}

impl fmt::Display for TimeoutKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Startup => "startup",
            Self::Answer => "answer",
            Self::Exit => "exit",
            Self::Silence => "silence",
        })
    }
}

/// How the emulator ended: the firmware's exit code through the `sifive_test` finisher.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FirmwareExit {
    /// One of the firmware's own codes.
    Code(ExitCode),
    /// Another status: the machine itself stopped the run (QEMU's bad arguments or missing
    /// files; the SoC's board: 64 it cannot run, 124 its watchdog or cycle limit, 125 a
    /// camera's pixel not taken).
    Other(i32),
    /// The machine was killed by a signal (by this runner after an error, or from outside).
    Signal,
}

impl FirmwareExit {
    /// Reads the machine's exit status.
    pub fn from_status(status: ExitStatus) -> Self {
        const CODES: [ExitCode; 5] = [
            ExitCode::Success,
            ExitCode::Panic,
            ExitCode::BadInput,
            ExitCode::FrameFailed,
            ExitCode::Trap,
        ];
        match status.code() {
            None => Self::Signal,
            Some(code) => CODES
                .into_iter()
                .find(|c| *c as i32 == code)
                .map_or(Self::Other(code), Self::Code),
        }
    }

    /// Whether every frame ran.
    pub fn is_success(&self) -> bool {
        *self == Self::Code(ExitCode::Success)
    }
}

impl fmt::Display for FirmwareExit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Code(code) => {
                let meaning = match code {
                    ExitCode::Success => "every frame ran",
                    ExitCode::Panic => "the firmware panicked",
                    ExitCode::BadInput => "the frame input region is invalid",
                    ExitCode::FrameFailed => "a frame failed; an ErrorReport said why",
                    ExitCode::Trap => "the core trapped; its log says where",
                };
                write!(f, "status {} ({meaning})", *code as u16)
            }
            Self::Other(code) => write!(
                f,
                "status {code} (not a firmware exit code: the machine itself stopped the run)"
            ),
            Self::Signal => f.write_str("killed by a signal"),
        }
    }
}

/// A hardware-in-the-loop run failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum HilError {
    /// The machine could not be started.
    #[error(
        "cannot start {program} (QEMU: is qemu-system-misc installed? the SoC: `cargo build \
         --release -p stereocal-hil --bin sc-soc-sim`): {source}"
    )]
    Spawn {
        /// The QEMU binary or the SoC simulator.
        program: PathBuf,
        /// The operating system's reason.
        #[source]
        source: io::Error,
    },
    /// A file of the run could not be read or written.
    #[error("{path}: {source}")]
    File {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        #[source]
        source: io::Error,
    },
    /// The firmware ELF has no defmt table (or one this host cannot read).
    #[error("{path}: defmt table: {reason}")]
    DefmtTable {
        /// The ELF.
        path: PathBuf,
        /// What the decoder said.
        reason: String,
    },
    /// An image does not have the size of the run.
    #[error("frame pair {pair}: image has {got} pixels, the run is {width}x{height}")]
    ImageSize {
        /// Index of the pair among the loaded ones.
        pair: usize,
        /// Pixels of the image.
        got: usize,
        /// Width of the run.
        width: u16,
        /// Height of the run.
        height: u16,
    },
    /// The frames do not fit the soft-core's frame-grabber region.
    #[error(
        "{pairs} frame pairs of {width}x{height} need {needed} bytes; the soft-core's frame \
         region holds {available}: use fewer or smaller frames"
    )]
    InputTooLarge {
        /// Pairs asked for.
        pairs: usize,
        /// Width of the run.
        width: u16,
        /// Height of the run.
        height: u16,
        /// Bytes the input needs.
        needed: u64,
        /// Bytes of the region.
        available: usize,
    },
    /// A timeout fired; the machine was killed.
    #[error(
        "the {kind} timeout ({limit:?}) fired waiting for {waiting_for}; the machine was \
         killed{}",
        log_suffix(log)
    )]
    Timeout {
        /// Which timeout.
        kind: TimeoutKind,
        /// Its length.
        limit: Duration,
        /// What the host was waiting for.
        waiting_for: String,
        /// What the firmware had logged (decoded), one message a line.
        log: String,
    },
    /// The machine ended before the run did.
    #[error("the machine ended early, {exit}{}", stderr_suffix(stderr))]
    EndedEarly {
        /// How it ended.
        exit: FirmwareExit,
        /// What the machine printed on stderr.
        stderr: String,
    },
    /// The firmware ran to its end but did not report success.
    #[error("the firmware exited with {exit}{}", log_suffix(log))]
    Firmware {
        /// How it ended.
        exit: FirmwareExit,
        /// What the firmware logged (decoded), one message a line.
        log: String,
    },
    /// The run could not be prepared (rendering, calibration, image size).
    #[error(transparent)]
    Eval(Box<EvalError>),
    /// The link to the machine failed while the run was ending.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// The session on the device failed; the machine was stopped.
    #[error(
        "{source}; the machine: {exit}{}{}",
        stderr_suffix(stderr),
        log_suffix(log)
    )]
    Device {
        /// What failed (boxed: the session's errors are large and this one is rare).
        #[source]
        source: Box<EvalError>,
        /// How the machine ended (`killed by a signal` when the runner had to kill it).
        exit: FirmwareExit,
        /// What the machine printed on stderr.
        stderr: String,
        /// What the firmware logged (decoded), one message a line.
        log: String,
    },
}

impl From<EvalError> for HilError {
    fn from(e: EvalError) -> Self {
        Self::Eval(Box::new(e))
    }
}

/// What the machine said, less the SoC board's measurement lines (`SocReport`).
fn stderr_suffix(stderr: &str) -> String {
    let said: Vec<&str> = stderr
        .lines()
        .filter(|line| {
            !line.starts_with("sc_soc_sim: image ") && !line.starts_with("sc_soc_sim: timing ")
        })
        .filter(|line| !line.trim().is_empty())
        .collect();
    if said.is_empty() {
        String::new()
    } else {
        format!("; the machine said: {}", said.join("\n"))
    }
}

fn log_suffix(log: &str) -> String {
    if log.is_empty() {
        String::new()
    } else {
        format!("; the firmware logged:\n{log}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::process::ExitStatusExt;

    #[test]
    fn exit_statuses_are_named() {
        let exit = |code: i32| FirmwareExit::from_status(ExitStatus::from_raw(code << 8));
        assert!(exit(0).is_success());
        assert_eq!(exit(3), FirmwareExit::Code(ExitCode::FrameFailed));
        assert_eq!(exit(101), FirmwareExit::Code(ExitCode::Panic));
        assert_eq!(exit(1), FirmwareExit::Other(1));
        assert_eq!(
            FirmwareExit::from_status(ExitStatus::from_raw(9)),
            FirmwareExit::Signal
        );
        assert_eq!(
            exit(2).to_string(),
            "status 2 (the frame input region is invalid)"
        );
    }
}
