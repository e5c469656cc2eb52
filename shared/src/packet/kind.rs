//! The packet kind byte of the header.

/// What a packet's payload is. Unknown values are kept so they can be logged and re-emitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PacketKind {
    /// `0x01`, both ways: protocol version and capabilities.
    Hello,
    /// `0x02`, host to device: write a fabric register.
    RegisterWrite,
    /// `0x03`, host to device: read a fabric register.
    RegisterRead,
    /// `0x04`, device to host: a register's value (answer to a read).
    RegisterValue,
    /// `0x10`, device to host: a camera frame begins.
    FrameStart,
    /// `0x11`, device to host: keypoints of a frame.
    PointBatch,
    /// `0x12`, device to host: one row of Sobel magnitude and orientation.
    SobelRows,
    /// `0x13`, device to host: a 16x16 Sobel patch around one keypoint.
    SobelPatch,
    /// `0x14`, device to host: a camera frame ends, with counters.
    FrameEnd,
    /// `0x15`, device to host: the head's camera yaws at a stereo capture.
    Encoders,
    /// `0x20`, device to host: one defmt log frame.
    Log,
    /// `0x21`, both ways: an error report.
    ErrorReport,
    /// Any other value.
    Unknown(u8),
}

impl From<u8> for PacketKind {
    fn from(value: u8) -> Self {
        match value {
            0x01 => PacketKind::Hello,
            0x02 => PacketKind::RegisterWrite,
            0x03 => PacketKind::RegisterRead,
            0x04 => PacketKind::RegisterValue,
            0x10 => PacketKind::FrameStart,
            0x11 => PacketKind::PointBatch,
            0x12 => PacketKind::SobelRows,
            0x13 => PacketKind::SobelPatch,
            0x14 => PacketKind::FrameEnd,
            0x15 => PacketKind::Encoders,
            0x20 => PacketKind::Log,
            0x21 => PacketKind::ErrorReport,
            other => PacketKind::Unknown(other),
        }
    }
}

impl From<PacketKind> for u8 {
    fn from(kind: PacketKind) -> u8 {
        match kind {
            PacketKind::Hello => 0x01,
            PacketKind::RegisterWrite => 0x02,
            PacketKind::RegisterRead => 0x03,
            PacketKind::RegisterValue => 0x04,
            PacketKind::FrameStart => 0x10,
            PacketKind::PointBatch => 0x11,
            PacketKind::SobelRows => 0x12,
            PacketKind::SobelPatch => 0x13,
            PacketKind::FrameEnd => 0x14,
            PacketKind::Encoders => 0x15,
            PacketKind::Log => 0x20,
            PacketKind::ErrorReport => 0x21,
            PacketKind::Unknown(other) => other,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_byte_round_trips() {
        for byte in 0..=u8::MAX {
            assert_eq!(u8::from(PacketKind::from(byte)), byte);
        }
    }
}
