//! What can stop the driver, and how each failure is reported to the host.

use core::fmt;

use stereocal_hdl::regs;
use stereocal_wire::{ErrorCode, FrameFailure};

use crate::fabric::stream::OutOfOrder;
use crate::fabric::{ConfigError, FrameError};

/// Why the driver could not configure the fabric or process a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DriverError {
    /// The fabric's registers hold an invalid configuration.
    Registers(stereocal_hdl::Error),
    /// The fabric model refused the configuration (its memories are too small for it).
    FabricConfig(ConfigError),
    /// The fabric model refused a row.
    Frame(FrameError),
    /// The image does not have `width * height` pixels.
    ImageSize {
        /// Pixels the configured frame has.
        expected: usize,
        /// Pixels given.
        got: usize,
    },
    /// The frame is wider than the fabric's lines (`W0`: its line memories and its stream
    /// engine's row ring).
    TooWide {
        /// Configured width.
        width: u16,
        /// The fabric's line length.
        max: usize,
    },
    /// The fabric's stream engine stopped the frame at a Sobel pixel outside its octave's
    /// image or out of raster order (a datapath defect; STREAM_FAULT).
    SobelOutOfOrder(OutOfOrder),
    /// The fabric's stream engine stopped the frame at a point outside its octave's image (a
    /// datapath defect; STREAM_FAULT).
    PointOutOfFrame {
        /// The point's octave.
        octave: u8,
        /// Its column.
        x: u16,
        /// Its row.
        y: u16,
    },
    /// An answer to the host could not be encoded (a driver defect: every packet is built
    /// within the wire format's limits).
    Encode(stereocal_wire::Error),
    /// The fabric's stream engine stopped the frame at a packet its framer refused (an engine
    /// defect; STREAM_FAULT).
    StreamEncode,
    /// The fabric's stream engine fell behind the pixel rate and stopped the frame
    /// (STREAM_FAULT.OVERRUN): the camera is too fast for the engine's clock.
    StreamOverrun,
    /// The fabric did not take FRAME_ARM: STATUS.BUSY stayed 0.
    NotArmed,
}

impl DriverError {
    /// The `ErrorReport` code and detail that tell the host about this error: a
    /// configuration the fabric cannot run names its register (`InvalidConfig`), any other
    /// failure its cause (`FrameFailed`, detail [`Self::detail`]).
    pub fn report(&self) -> (ErrorCode, u32) {
        match self {
            Self::Registers(e) => (
                ErrorCode::InvalidConfig,
                register_offset(e).map_or(u32::MAX, u32::from),
            ),
            Self::TooWide { .. } | Self::FabricConfig(_) => {
                (ErrorCode::InvalidConfig, u32::from(regs::width::OFFSET))
            }
            _ => (ErrorCode::FrameFailed, self.detail()),
        }
    }

    /// The `FrameFailed` detail of this error: its cause and a value that locates it (a size,
    /// a row), as the wire spec lays them out.
    pub fn detail(&self) -> u32 {
        let (cause, value) = match *self {
            Self::Registers(_) => (FrameFailure::Registers, 0),
            Self::FabricConfig(_) => (FrameFailure::FabricConfig, 0),
            Self::Frame(_) => (FrameFailure::Frame, 0),
            // Saturated by `FrameFailure::detail` to the 24 bits the value has.
            Self::ImageSize { got, .. } => (
                FrameFailure::ImageSize,
                u32::try_from(got).unwrap_or(u32::MAX),
            ),
            Self::TooWide { width, .. } => (FrameFailure::TooWide, u32::from(width)),
            Self::SobelOutOfOrder(p) => (FrameFailure::SobelOutOfOrder, u32::from(p.y)),
            Self::PointOutOfFrame { y, .. } => (FrameFailure::PointOutOfFrame, u32::from(y)),
            Self::Encode(_) | Self::StreamEncode => (FrameFailure::Encode, 0),
            Self::NotArmed => (FrameFailure::NotArmed, 0),
            Self::StreamOverrun => (FrameFailure::StreamOverrun, 0),
        };
        cause.detail(value)
    }
}

/// The register an hdl error is about, where it names one.
fn register_offset(e: &stereocal_hdl::Error) -> Option<u16> {
    use stereocal_hdl::Error as E;
    let field = match *e {
        E::MisalignedOffset { offset } | E::UnmappedOffset { offset } => return Some(offset),
        E::FrameNotDivisible { .. } => return Some(regs::width::OFFSET),
        E::FieldOutOfRange { field, .. }
        | E::FieldReadOnly { field }
        | E::UnknownEnumValue { field, .. } => field,
        _ => return None,
    };
    let register = field.split('.').next()?;
    regs::REGISTERS
        .iter()
        .find(|r| r.name == register)
        .map(|r| r.offset)
}

impl fmt::Display for DriverError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Registers(e) => write!(f, "fabric registers: {e}"),
            Self::FabricConfig(e) => write!(f, "fabric model: {e}"),
            Self::Frame(e) => write!(f, "fabric model: {e}"),
            Self::ImageSize { expected, got } => {
                write!(f, "image of {got} pixels, the configured frame has {expected}")
            }
            Self::TooWide { width, max } => {
                write!(f, "frame width {width} exceeds the fabric's lines ({max})")
            }
            Self::SobelOutOfOrder(p) => write!(
                f,
                "the stream engine stopped at Sobel pixel ({}, {}) of octave {}: out of raster order or outside the image",
                p.x, p.y, p.octave
            ),
            Self::PointOutOfFrame { octave, x, y } => write!(
                f,
                "the stream engine stopped at point ({x}, {y}) outside octave {octave}'s image"
            ),
            Self::Encode(e) => write!(f, "packet encoding: {e}"),
            Self::StreamEncode => write!(f, "the stream engine could not encode a packet"),
            Self::NotArmed => write!(f, "the fabric did not take FRAME_ARM (STATUS.BUSY stayed 0)"),
            Self::StreamOverrun => write!(
                f,
                "the stream engine fell behind the camera (STREAM_FAULT.OVERRUN): its clock is \
                 too slow for the pixel rate"
            ),
        }
    }
}

impl core::error::Error for DriverError {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn config_errors_name_the_register() {
        let e = DriverError::Registers(stereocal_hdl::Error::FieldOutOfRange {
            field: "OCTAVES.COUNT",
            value: 7,
            min: 1,
            max: 4,
        });
        assert_eq!(
            e.report(),
            (ErrorCode::InvalidConfig, u32::from(regs::octaves::OFFSET))
        );
    }

    #[test]
    fn frame_failures_name_their_cause() {
        assert_eq!(
            DriverError::NotArmed.report(),
            (ErrorCode::FrameFailed, 0x0900_0000)
        );
        let image = DriverError::ImageSize {
            expected: 64 * 32,
            got: 100,
        };
        assert_eq!(
            FrameFailure::from_detail(image.report().1),
            (FrameFailure::ImageSize, 100)
        );
        let huge = DriverError::ImageSize {
            expected: 64 * 32,
            got: usize::MAX,
        };
        assert_eq!(
            FrameFailure::from_detail(huge.detail()),
            (FrameFailure::ImageSize, stereocal_wire::MAX_FAILURE_VALUE)
        );
    }
}
