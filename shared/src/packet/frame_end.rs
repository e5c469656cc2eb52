//! `FrameEnd` (`0x14`), device to host: a camera frame ends; what was sent and what was lost.
//!
//! ```text
//!  0          4        5             9             13      14            18            22
//! +----------+--------+-------------+-------------+-------+-------------+-------------+
//! | frame_id | camera | point_count | sobel_count | flags |dropped_pts  |dropped_sobel|
//! |  u32 LE  |   u8   |   u32 LE    |   u32 LE    |  u8   |   u32 LE    |   u32 LE    |
//! +----------+--------+-------------+-------------+-------+-------------+-------------+
//! ```
//! `point_count` is the number of points sent in `PointBatch` packets of this frame,
//! `sobel_count` the number of `SobelRows` / `SobelPatch` packets; the host compares them with
//! what it received to tell link loss from FIFO loss. The dropped counters count records the
//! fabric produced but the FIFOs could not hold.

use core::ops::BitOr;

use crate::le::{self, Field};
use crate::packet::camera::Camera;
use crate::packet::{check_fixed_len, check_room};
use crate::Error;

mod field {
    use super::Field;
    pub const FRAME_ID: Field = 0..4;
    pub const CAMERA: usize = 4;
    pub const POINT_COUNT: Field = 5..9;
    pub const SOBEL_COUNT: Field = 9..13;
    pub const FLAGS: usize = 13;
    pub const DROPPED_POINTS: Field = 14..18;
    pub const DROPPED_SOBEL: Field = 18..22;
}

/// Payload length of a `FrameEnd`.
pub const LEN: usize = field::DROPPED_SOBEL.end;

packet_view! {
    /// A view over a `FrameEnd` payload.
}

impl<T: AsRef<[u8]>> Packet<T> {
    /// Checks that the buffer is exactly [`LEN`] bytes.
    pub fn check_len(&self) -> Result<(), Error> {
        check_fixed_len(self.buffer.as_ref().len(), LEN)
    }

    /// Frame number.
    pub fn frame_id(&self) -> u32 {
        le::read_u32(self.buffer.as_ref(), field::FRAME_ID)
    }

    /// Camera.
    pub fn camera(&self) -> Camera {
        Camera::from(le::read_u8(self.buffer.as_ref(), field::CAMERA))
    }

    /// Points sent for this frame.
    pub fn point_count(&self) -> u32 {
        le::read_u32(self.buffer.as_ref(), field::POINT_COUNT)
    }

    /// Sobel packets sent for this frame.
    pub fn sobel_count(&self) -> u32 {
        le::read_u32(self.buffer.as_ref(), field::SOBEL_COUNT)
    }

    /// Overflow flag bits.
    pub fn flags(&self) -> u8 {
        le::read_u8(self.buffer.as_ref(), field::FLAGS)
    }

    /// Points lost to a full point FIFO.
    pub fn dropped_points(&self) -> u32 {
        le::read_u32(self.buffer.as_ref(), field::DROPPED_POINTS)
    }

    /// Sobel records lost to a full Sobel FIFO.
    pub fn dropped_sobel(&self) -> u32 {
        le::read_u32(self.buffer.as_ref(), field::DROPPED_SOBEL)
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

    /// Sets the point count.
    pub fn set_point_count(&mut self, value: u32) {
        le::write_u32(self.buffer.as_mut(), field::POINT_COUNT, value);
    }

    /// Sets the Sobel packet count.
    pub fn set_sobel_count(&mut self, value: u32) {
        le::write_u32(self.buffer.as_mut(), field::SOBEL_COUNT, value);
    }

    /// Sets the flag bits.
    pub fn set_flags(&mut self, value: u8) {
        le::write_u8(self.buffer.as_mut(), field::FLAGS, value);
    }

    /// Sets the dropped point count.
    pub fn set_dropped_points(&mut self, value: u32) {
        le::write_u32(self.buffer.as_mut(), field::DROPPED_POINTS, value);
    }

    /// Sets the dropped Sobel record count.
    pub fn set_dropped_sobel(&mut self, value: u32) {
        le::write_u32(self.buffer.as_mut(), field::DROPPED_SOBEL, value);
    }
}

/// Overflow flags of a frame; unknown bits are kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameEndFlags(pub u8);

impl FrameEndFlags {
    /// The point FIFO overflowed during the frame.
    pub const POINT_FIFO_OVERFLOW: FrameEndFlags = FrameEndFlags(1 << 0);
    /// The Sobel FIFO overflowed during the frame.
    pub const SOBEL_FIFO_OVERFLOW: FrameEndFlags = FrameEndFlags(1 << 1);

    /// `true` when every bit of `other` is set in `self`.
    pub const fn contains(self, other: FrameEndFlags) -> bool {
        self.0 & other.0 == other.0
    }
}

impl BitOr for FrameEndFlags {
    type Output = FrameEndFlags;
    fn bitor(self, rhs: FrameEndFlags) -> FrameEndFlags {
        FrameEndFlags(self.0 | rhs.0)
    }
}

/// A parsed `FrameEnd`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrameEndRepr {
    /// Frame number.
    pub frame_id: u32,
    /// Camera.
    pub camera: Camera,
    /// Points sent for this frame.
    pub point_count: u32,
    /// `SobelRows` / `SobelPatch` packets sent for this frame.
    pub sobel_count: u32,
    /// Overflow flags.
    pub flags: FrameEndFlags,
    /// Points lost to a full point FIFO.
    pub dropped_points: u32,
    /// Sobel records lost to a full Sobel FIFO.
    pub dropped_sobel: u32,
}

impl FrameEndRepr {
    /// Reads a `FrameEnd` payload.
    pub fn parse<T: AsRef<[u8]> + ?Sized>(packet: &Packet<&T>) -> Result<FrameEndRepr, Error> {
        packet.check_len()?;
        Ok(FrameEndRepr {
            frame_id: packet.frame_id(),
            camera: packet.camera(),
            point_count: packet.point_count(),
            sobel_count: packet.sobel_count(),
            flags: FrameEndFlags(packet.flags()),
            dropped_points: packet.dropped_points(),
            dropped_sobel: packet.dropped_sobel(),
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
        packet.set_point_count(self.point_count);
        packet.set_sobel_count(self.sobel_count);
        packet.set_flags(self.flags.0);
        packet.set_dropped_points(self.dropped_points);
        packet.set_dropped_sobel(self.dropped_sobel);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    static PACKET_BYTES: [u8; 22] = [
        0x2a, 0x00, 0x00, 0x00, // frame_id 42
        0x00, // camera Left
        0xf4, 0x01, 0x00, 0x00, // point_count 500
        0x20, 0x00, 0x00, 0x00, // sobel_count 32
        0x01, // flags: point FIFO overflow
        0x03, 0x00, 0x00, 0x00, // dropped_points 3
        0x00, 0x00, 0x00, 0x00, // dropped_sobel 0
    ];

    const REPR: FrameEndRepr = FrameEndRepr {
        frame_id: 42,
        camera: Camera::Left,
        point_count: 500,
        sobel_count: 32,
        flags: FrameEndFlags::POINT_FIFO_OVERFLOW,
        dropped_points: 3,
        dropped_sobel: 0,
    };

    #[test]
    fn deconstruct() {
        let packet = Packet::new_checked(&PACKET_BYTES[..]).unwrap();
        assert_eq!(packet.frame_id(), 42);
        assert_eq!(packet.camera(), Camera::Left);
        assert_eq!(packet.point_count(), 500);
        assert_eq!(packet.sobel_count(), 32);
        assert_eq!(packet.flags(), 1);
        assert_eq!(packet.dropped_points(), 3);
        assert_eq!(packet.dropped_sobel(), 0);
    }

    #[test]
    fn construct() {
        let mut bytes = [0xa5u8; LEN];
        let mut packet = Packet::new_unchecked(&mut bytes[..]);
        packet.set_frame_id(42);
        packet.set_camera(Camera::Left);
        packet.set_point_count(500);
        packet.set_sobel_count(32);
        packet.set_flags(1);
        packet.set_dropped_points(3);
        packet.set_dropped_sobel(0);
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn parse() {
        let packet = Packet::new_unchecked(&PACKET_BYTES[..]);
        let repr = FrameEndRepr::parse(&packet).unwrap();
        assert_eq!(repr, REPR);
        assert!(repr.flags.contains(FrameEndFlags::POINT_FIFO_OVERFLOW));
        assert!(!repr.flags.contains(FrameEndFlags::SOBEL_FIFO_OVERFLOW));
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
