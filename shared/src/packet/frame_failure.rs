//! The `detail` of an `ErrorReport` with code `FrameFailed`: why a camera frame failed.
//!
//! ```text
//!  31      24 23                     0
//! +----------+-----------------------+
//! |  cause   |        value          |
//! +----------+-----------------------+
//! ```
//! The cause says what failed, the value (24 bits) a number that locates it: a size, a row,
//! a width. A report must tell the causes apart without a log, and a 32-bit detail has room
//! for both.

/// Bits of the value below the cause byte.
const VALUE_BITS: u32 = 24;
/// The largest value; larger ones are sent as this.
pub const MAX_FAILURE_VALUE: u32 = (1 << VALUE_BITS) - 1;

/// Why a camera frame failed. Unknown causes are kept so they round-trip.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FrameFailure {
    /// `1`: the fabric's registers hold an invalid configuration; value 0.
    Registers,
    /// `2`: the fabric refused the configuration (its memories are too small); value 0.
    FabricConfig,
    /// `3`: the fabric refused a row or did not finish the frame; value 0.
    Frame,
    /// `4`: the image does not have width × height pixels; value: the pixels given.
    ImageSize,
    /// `5`: the frame is wider than the channel's line memory; value: the width.
    TooWide,
    /// `6`: the fabric emitted a Sobel pixel out of raster order or outside its octave's
    /// image; value: its row.
    SobelOutOfOrder,
    /// `7`: the fabric emitted a point outside its octave's image; value: its row.
    PointOutOfFrame,
    /// `8`: a packet could not be encoded; value 0.
    Encode,
    /// `9`: the fabric did not take FRAME_ARM (STATUS.BUSY stayed 0); value 0.
    NotArmed,
    /// `10`: the fabric's stream engine fell behind the pixel rate (STREAM_FAULT.OVERRUN) and
    /// stopped the frame; value 0.
    StreamOverrun,
    /// Any other cause byte.
    Unknown(u8),
}

impl FrameFailure {
    /// The detail word for this cause and `value` (saturated to [`MAX_FAILURE_VALUE`]).
    pub fn detail(self, value: u32) -> u32 {
        (u32::from(u8::from(self)) << VALUE_BITS) | value.min(MAX_FAILURE_VALUE)
    }

    /// The cause and value a detail word holds.
    pub fn from_detail(detail: u32) -> (FrameFailure, u32) {
        // The shift leaves the top 8 bits only.
        let cause = (detail >> VALUE_BITS) as u8;
        (FrameFailure::from(cause), detail & MAX_FAILURE_VALUE)
    }
}

impl From<u8> for FrameFailure {
    fn from(value: u8) -> Self {
        match value {
            1 => FrameFailure::Registers,
            2 => FrameFailure::FabricConfig,
            3 => FrameFailure::Frame,
            4 => FrameFailure::ImageSize,
            5 => FrameFailure::TooWide,
            6 => FrameFailure::SobelOutOfOrder,
            7 => FrameFailure::PointOutOfFrame,
            8 => FrameFailure::Encode,
            9 => FrameFailure::NotArmed,
            10 => FrameFailure::StreamOverrun,
            other => FrameFailure::Unknown(other),
        }
    }
}

impl From<FrameFailure> for u8 {
    fn from(cause: FrameFailure) -> u8 {
        match cause {
            FrameFailure::Registers => 1,
            FrameFailure::FabricConfig => 2,
            FrameFailure::Frame => 3,
            FrameFailure::ImageSize => 4,
            FrameFailure::TooWide => 5,
            FrameFailure::SobelOutOfOrder => 6,
            FrameFailure::PointOutOfFrame => 7,
            FrameFailure::Encode => 8,
            FrameFailure::NotArmed => 9,
            FrameFailure::StreamOverrun => 10,
            FrameFailure::Unknown(other) => other,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_cause_round_trips() {
        for byte in 0..=u8::MAX {
            assert_eq!(u8::from(FrameFailure::from(byte)), byte);
        }
    }

    #[test]
    fn detail_holds_cause_and_value() {
        let detail = FrameFailure::NotArmed.detail(0);
        assert_eq!(detail, 0x0900_0000);
        assert_eq!(
            FrameFailure::from_detail(detail),
            (FrameFailure::NotArmed, 0)
        );
        let detail = FrameFailure::ImageSize.detail(0x0123_4567);
        assert_eq!(detail, 0x04ff_ffff);
        assert_eq!(
            FrameFailure::from_detail(0x0400_1000),
            (FrameFailure::ImageSize, 0x1000)
        );
    }
}
