//! What the driver's calls can fail with.

use std::fmt;
use std::time::Duration;

use stereocal_wire::{Camera, ErrorCode};

use crate::link::LinkError;

/// What the driver was waiting for when a deadline passed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Waiting {
    /// The device's `Hello`.
    Hello,
    /// The `RegisterValue` answering a read of `addr`.
    RegisterValue {
        /// Register byte offset.
        addr: u16,
    },
    /// The next camera frame; `in_progress` is the frame id, camera and packets received of
    /// a frame that had started.
    Frame {
        /// The frame that had started, if any.
        in_progress: Option<(u32, Camera, u32)>,
    },
}

impl fmt::Display for Waiting {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Hello => f.write_str("the device's Hello"),
            Self::RegisterValue { addr } => write!(f, "the value of register {addr:#06x}"),
            Self::Frame { in_progress: None } => f.write_str("a frame (no FrameStart yet)"),
            Self::Frame {
                in_progress: Some((id, camera, packets)),
            } => write!(
                f,
                "the end of frame {id} {camera:?} ({packets} packets received)"
            ),
        }
    }
}

/// A driver call failed. Damaged frames are *not* errors: they are reported as
/// [`FrameOutcome::Damaged`](super::FrameOutcome::Damaged) and counted.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DriverError {
    /// The deadline passed.
    #[error("timed out after {timeout:?} waiting for {waiting_for}")]
    Timeout {
        /// What was awaited.
        waiting_for: Waiting,
        /// The timeout the call was given.
        timeout: Duration,
    },
    /// The link failed (other than by timing out).
    #[error(transparent)]
    Link(LinkError),
    /// The configuration is invalid; nothing was sent.
    #[error("fabric configuration: {0}")]
    Config(stereocal_hdl::Error),
    /// A register did not read back what was written.
    #[error("register {addr:#06x}: wrote {written:#010x}, read back {read:#010x}")]
    ReadBack {
        /// Register byte offset.
        addr: u16,
        /// Value the register should hold.
        written: u32,
        /// Value the device reported.
        read: u32,
    },
    /// The device answered a request with an `ErrorReport`.
    #[error("device error {code:?} (detail {detail:#x}) in packet seq {seq}")]
    Device {
        /// Error code.
        code: ErrorCode,
        /// Code-specific detail.
        detail: u32,
        /// Sequence number of the `ErrorReport`.
        seq: u16,
    },
    /// The device speaks no protocol version the host does.
    #[error("device speaks protocol version {device}, the host {host}")]
    Version {
        /// The device's highest version.
        device: u8,
        /// The host's.
        host: u8,
    },
    /// A request could not be encoded (a host defect).
    #[error("encoding a request: {0}")]
    Encode(stereocal_wire::Error),
}
