//! `FrameStart` (`0x10`), device to host: a camera frame begins.
//!
//! ```text
//!  0          4        5          7          9        10                 18
//! +----------+--------+----------+----------+--------+------------------+
//! | frame_id | camera |  width   |  height  |octaves |   timestamp_us   |
//! |  u32 LE  |   u8   |  u16 LE  |  u16 LE  |   u8   |      u64 LE      |
//! +----------+--------+----------+----------+--------+------------------+
//! ```
//! `width` x `height` is the octave-0 image size in pixels; `timestamp_us` is the capture
//! time of the first pixel on the device clock, in microseconds.

use crate::le::{self, Field};
use crate::packet::camera::Camera;
use crate::packet::{check_fixed_len, check_room};
use crate::Error;

mod field {
    use super::Field;
    pub const FRAME_ID: Field = 0..4;
    pub const CAMERA: usize = 4;
    pub const WIDTH: Field = 5..7;
    pub const HEIGHT: Field = 7..9;
    pub const OCTAVES: usize = 9;
    pub const TIMESTAMP_US: Field = 10..18;
}

/// Payload length of a `FrameStart`.
pub const LEN: usize = field::TIMESTAMP_US.end;

packet_view! {
    /// A view over a `FrameStart` payload.
}

impl<T: AsRef<[u8]>> Packet<T> {
    /// Checks that the buffer is exactly [`LEN`] bytes.
    pub fn check_len(&self) -> Result<(), Error> {
        check_fixed_len(self.buffer.as_ref().len(), LEN)
    }

    /// Frame number, shared by both cameras of one stereo capture.
    pub fn frame_id(&self) -> u32 {
        le::read_u32(self.buffer.as_ref(), field::FRAME_ID)
    }

    /// Camera.
    pub fn camera(&self) -> Camera {
        Camera::from(le::read_u8(self.buffer.as_ref(), field::CAMERA))
    }

    /// Octave-0 width in pixels.
    pub fn width(&self) -> u16 {
        le::read_u16(self.buffer.as_ref(), field::WIDTH)
    }

    /// Octave-0 height in pixels.
    pub fn height(&self) -> u16 {
        le::read_u16(self.buffer.as_ref(), field::HEIGHT)
    }

    /// Number of octaves the fabric computes for this frame.
    pub fn octaves(&self) -> u8 {
        le::read_u8(self.buffer.as_ref(), field::OCTAVES)
    }

    /// Capture time of the first pixel, device clock, microseconds.
    pub fn timestamp_us(&self) -> u64 {
        le::read_u64(self.buffer.as_ref(), field::TIMESTAMP_US)
    }
}

impl<T: AsRef<[u8]> + AsMut<[u8]>> Packet<T> {
    /// Sets the frame number.
    pub fn set_frame_id(&mut self, value: u32) {
        le::write_u32(self.buffer.as_mut(), field::FRAME_ID, value);
    }

    /// Sets the camera.
    pub fn set_camera(&mut self, value: Camera) {
        le::write_u8(self.buffer.as_mut(), field::CAMERA, u8::from(value));
    }

    /// Sets the width.
    pub fn set_width(&mut self, value: u16) {
        le::write_u16(self.buffer.as_mut(), field::WIDTH, value);
    }

    /// Sets the height.
    pub fn set_height(&mut self, value: u16) {
        le::write_u16(self.buffer.as_mut(), field::HEIGHT, value);
    }

    /// Sets the octave count.
    pub fn set_octaves(&mut self, value: u8) {
        le::write_u8(self.buffer.as_mut(), field::OCTAVES, value);
    }

    /// Sets the timestamp.
    pub fn set_timestamp_us(&mut self, value: u64) {
        le::write_u64(self.buffer.as_mut(), field::TIMESTAMP_US, value);
    }
}

/// A parsed `FrameStart`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameStartRepr {
    /// Frame number.
    pub frame_id: u32,
    /// Camera.
    pub camera: Camera,
    /// Octave-0 width in pixels.
    pub width: u16,
    /// Octave-0 height in pixels.
    pub height: u16,
    /// Number of octaves.
    pub octaves: u8,
    /// Capture time of the first pixel, device clock, microseconds.
    pub timestamp_us: u64,
}

impl FrameStartRepr {
    /// Reads a `FrameStart` payload.
    pub fn parse<T: AsRef<[u8]> + ?Sized>(packet: &Packet<&T>) -> Result<FrameStartRepr, Error> {
        packet.check_len()?;
        Ok(FrameStartRepr {
            frame_id: packet.frame_id(),
            camera: packet.camera(),
            width: packet.width(),
            height: packet.height(),
            octaves: packet.octaves(),
            timestamp_us: packet.timestamp_us(),
        })
    }

    /// Payload length `emit` writes.
    pub const fn buffer_len(&self) -> usize {
        LEN
    }

    /// Writes the payload into `packet`.
    pub fn emit<T: AsRef<[u8]> + AsMut<[u8]>>(&self, packet: &mut Packet<T>) -> Result<(), Error> {
        check_room(packet.buffer.as_ref().len(), self.buffer_len())?;
        packet.set_frame_id(self.frame_id);
        packet.set_camera(self.camera);
        packet.set_width(self.width);
        packet.set_height(self.height);
        packet.set_octaves(self.octaves);
        packet.set_timestamp_us(self.timestamp_us);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    static PACKET_BYTES: [u8; 18] = [
        0x2a, 0x00, 0x00, 0x00, // frame_id 42
        0x01, // camera Right
        0x80, 0x02, // width 640
        0xe0, 0x01, // height 480
        0x04, // octaves 4
        0x88, 0x77, 0x66, 0x55, 0x44, 0x33, 0x22, 0x11, // timestamp_us 0x1122334455667788
    ];

    const REPR: FrameStartRepr = FrameStartRepr {
        frame_id: 42,
        camera: Camera::Right,
        width: 640,
        height: 480,
        octaves: 4,
        timestamp_us: 0x1122_3344_5566_7788,
    };

    #[test]
    fn deconstruct() {
        let packet = Packet::new_checked(&PACKET_BYTES[..]).unwrap();
        assert_eq!(packet.frame_id(), 42);
        assert_eq!(packet.camera(), Camera::Right);
        assert_eq!(packet.width(), 640);
        assert_eq!(packet.height(), 480);
        assert_eq!(packet.octaves(), 4);
        assert_eq!(packet.timestamp_us(), 0x1122_3344_5566_7788);
    }

    #[test]
    fn construct() {
        let mut bytes = [0xa5u8; LEN];
        let mut packet = Packet::new_unchecked(&mut bytes[..]);
        packet.set_frame_id(42);
        packet.set_camera(Camera::Right);
        packet.set_width(640);
        packet.set_height(480);
        packet.set_octaves(4);
        packet.set_timestamp_us(0x1122_3344_5566_7788);
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn parse() {
        let packet = Packet::new_unchecked(&PACKET_BYTES[..]);
        assert_eq!(FrameStartRepr::parse(&packet), Ok(REPR));
    }

    #[test]
    fn emit() {
        let mut bytes = [0u8; LEN];
        REPR.emit(&mut Packet::new_unchecked(&mut bytes[..]))
            .unwrap();
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn unknown_camera_round_trips() {
        let mut bytes = PACKET_BYTES;
        bytes[4] = 7;
        let repr = FrameStartRepr::parse(&Packet::new_unchecked(&bytes[..])).unwrap();
        assert_eq!(repr.camera, Camera::Unknown(7));
        let mut out = [0u8; LEN];
        repr.emit(&mut Packet::new_unchecked(&mut out[..])).unwrap();
        assert_eq!(out, bytes);
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
