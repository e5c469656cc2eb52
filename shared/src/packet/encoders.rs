//! `Encoders` (`0x15`), device to host: the head's two camera yaws at one stereo capture, read
//! from its joint encoders (or the angles it was commanded to).
//!
//! ```text
//!  0          4              8              12
//! +----------+--------------+--------------+
//! | frame_id |   left_yaw   |  right_yaw   |
//! |  u32 LE  | i32 LE, µdeg | i32 LE, µdeg |
//! +----------+--------------+--------------+
//! ```
//! `frame_id` is the capture's, as in its cameras' `FrameStart`. Yaws are in microdegrees,
//! positive toward +x (verge = left − right, toe-in positive): finer than any joint encoder,
//! and ±2147° covers any joint. The host takes the verge's change between captures as its
//! filter's control input, so only changes matter and the encoders' zero need not be the
//! optical one.

use crate::le::{self, Field};
use crate::packet::{check_fixed_len, check_room};
use crate::Error;

mod field {
    use super::Field;
    pub const FRAME_ID: Field = 0..4;
    pub const LEFT_YAW: Field = 4..8;
    pub const RIGHT_YAW: Field = 8..12;
}

/// Payload length of an `Encoders`.
pub const LEN: usize = field::RIGHT_YAW.end;

packet_view! {
    /// A view over an `Encoders` payload.
}

impl<T: AsRef<[u8]>> Packet<T> {
    /// Checks that the buffer is exactly [`LEN`] bytes.
    pub fn check_len(&self) -> Result<(), Error> {
        check_fixed_len(self.buffer.as_ref().len(), LEN)
    }

    /// The capture's frame id.
    pub fn frame_id(&self) -> u32 {
        le::read_u32(self.buffer.as_ref(), field::FRAME_ID)
    }

    /// Left camera yaw, microdegrees.
    pub fn left_yaw_udeg(&self) -> i32 {
        le::read_i32(self.buffer.as_ref(), field::LEFT_YAW)
    }

    /// Right camera yaw, microdegrees.
    pub fn right_yaw_udeg(&self) -> i32 {
        le::read_i32(self.buffer.as_ref(), field::RIGHT_YAW)
    }
}

impl<T: AsRef<[u8]> + AsMut<[u8]>> Packet<T> {
    /// Sets the capture's frame id.
    pub fn set_frame_id(&mut self, value: u32) {
        le::write_u32(self.buffer.as_mut(), field::FRAME_ID, value);
    }

    /// Sets the left camera yaw, microdegrees.
    pub fn set_left_yaw_udeg(&mut self, value: i32) {
        le::write_i32(self.buffer.as_mut(), field::LEFT_YAW, value);
    }

    /// Sets the right camera yaw, microdegrees.
    pub fn set_right_yaw_udeg(&mut self, value: i32) {
        le::write_i32(self.buffer.as_mut(), field::RIGHT_YAW, value);
    }
}

/// A parsed `Encoders`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EncodersRepr {
    /// The capture's frame id.
    pub frame_id: u32,
    /// Left camera yaw, microdegrees.
    pub left_yaw_udeg: i32,
    /// Right camera yaw, microdegrees.
    pub right_yaw_udeg: i32,
}

impl EncodersRepr {
    /// Reads an `Encoders` payload.
    pub fn parse<T: AsRef<[u8]> + ?Sized>(packet: &Packet<&T>) -> Result<EncodersRepr, Error> {
        packet.check_len()?;
        Ok(EncodersRepr {
            frame_id: packet.frame_id(),
            left_yaw_udeg: packet.left_yaw_udeg(),
            right_yaw_udeg: packet.right_yaw_udeg(),
        })
    }

    /// The head's verge at the capture, microdegrees (left yaw minus right yaw, toe-in
    /// positive), without overflow: each yaw spans the whole `i32`.
    pub const fn verge_udeg(&self) -> i64 {
        self.left_yaw_udeg as i64 - self.right_yaw_udeg as i64
    }

    /// Payload length `emit` writes.
    pub const fn buffer_len(&self) -> usize {
        LEN
    }

    /// Writes the payload into `packet`.
    pub fn emit<T: AsRef<[u8]> + AsMut<[u8]>>(&self, packet: &mut Packet<T>) -> Result<(), Error> {
        check_room(packet.buffer.as_ref().len(), self.buffer_len())?;
        packet.set_frame_id(self.frame_id);
        packet.set_left_yaw_udeg(self.left_yaw_udeg);
        packet.set_right_yaw_udeg(self.right_yaw_udeg);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verge_is_left_minus_right_over_the_whole_range() {
        let reading = |l, r| EncodersRepr {
            frame_id: 0,
            left_yaw_udeg: l,
            right_yaw_udeg: r,
        };
        assert_eq!(reading(7_500_000, -1_250_000).verge_udeg(), 8_750_000);
        assert_eq!(
            reading(i32::MAX, i32::MIN).verge_udeg(),
            i64::from(i32::MAX) - i64::from(i32::MIN)
        );
    }

    static PACKET_BYTES: [u8; 12] = [
        0x2a, 0x00, 0x00, 0x00, // frame 42
        0x20, 0xa1, 0x07, 0x00, // left yaw 500000 µdeg (0.5°)
        0xe0, 0x5e, 0xf8, 0xff, // right yaw -500000 µdeg
    ];

    const REPR: EncodersRepr = EncodersRepr {
        frame_id: 42,
        left_yaw_udeg: 500_000,
        right_yaw_udeg: -500_000,
    };

    #[test]
    fn deconstruct() {
        let packet = Packet::new_checked(&PACKET_BYTES[..]).unwrap();
        assert_eq!(packet.frame_id(), 42);
        assert_eq!(packet.left_yaw_udeg(), 500_000);
        assert_eq!(packet.right_yaw_udeg(), -500_000);
    }

    #[test]
    fn construct() {
        let mut bytes = [0xa5u8; LEN];
        let mut packet = Packet::new_unchecked(&mut bytes[..]);
        packet.set_frame_id(42);
        packet.set_left_yaw_udeg(500_000);
        packet.set_right_yaw_udeg(-500_000);
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn parse() {
        let packet = Packet::new_unchecked(&PACKET_BYTES[..]);
        assert_eq!(EncodersRepr::parse(&packet), Ok(REPR));
    }

    #[test]
    fn emit() {
        let mut bytes = [0u8; LEN];
        REPR.emit(&mut Packet::new_unchecked(&mut bytes[..]))
            .unwrap();
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn impossible_length() {
        assert_eq!(
            Packet::new_checked(&PACKET_BYTES[..LEN - 1]).unwrap_err(),
            Error::DecodeUnexpectedEnd
        );
        assert_eq!(
            Packet::new_checked(&[0u8; LEN + 1][..]).unwrap_err(),
            Error::DecodeBadLength
        );
        let mut short = [0u8; LEN - 1];
        assert_eq!(
            REPR.emit(&mut Packet::new_unchecked(&mut short[..])),
            Err(Error::EncodeBufferTooSmall)
        );
    }
}
