//! `PointBatch` (`0x11`), device to host: up to [`MAX_POINTS`] keypoints of one frame.
//!
//! ```text
//!  0          4        5          7                       7+14*count
//! +----------+--------+----------+--------- ... ---------+
//! | frame_id | camera |  count   | count point records   |
//! |  u32 LE  |   u8   |  u16 LE  | 14 bytes each         |
//! +----------+--------+----------+--------- ... ---------+
//!
//! point record:
//!  0        2        4        5        6        8        10       12       14
//! +--------+--------+--------+--------+--------+--------+--------+--------+
//! |   x    |   y    | octave | scale  |   dx   |   dy   |   ds   |  dog   |
//! | u16 LE | u16 LE |   u8   |   u8   | i16 LE | i16 LE | i16 LE | i16 LE |
//! +--------+--------+--------+--------+--------+--------+--------+--------+
//! ```
//! `x`, `y` are the extremum's pixel in its octave's image (octave `o` is subsampled by `2^o`,
//! so the octave-0 position is `(x + dx) * 2^o`). `dx`, `dy` are the sub-pixel offsets and `ds`
//! the sub-scale offset, Q2.13 signed fixed point ([`OFFSET_FRAC_BITS`] fractional bits: value
//! = raw / 8192, range [-4, 4)) of one octave-local pixel and one scale step respectively.
//! `dog` is the difference-of-Gaussians value at the extremum: positive for a maximum,
//! negative for a minimum.

use crate::le::{self, Field};
use crate::packet::camera::Camera;
use crate::packet::check_room;
use crate::records::{Record, Records};
use crate::Error;

mod field {
    use super::Field;
    pub const FRAME_ID: Field = 0..4;
    pub const CAMERA: usize = 4;
    pub const COUNT: Field = 5..7;
    pub const POINTS: usize = 7;

    pub mod point {
        use super::Field;
        pub const X: Field = 0..2;
        pub const Y: Field = 2..4;
        pub const OCTAVE: usize = 4;
        pub const SCALE: usize = 5;
        pub const DX: Field = 6..8;
        pub const DY: Field = 8..10;
        pub const DS: Field = 10..12;
        pub const DOG: Field = 12..14;
    }
}

/// Most points one batch carries.
pub const MAX_POINTS: usize = 128;
/// Bytes before the point records.
pub const HEADER_LEN: usize = field::POINTS;
/// Largest `PointBatch` payload.
pub const MAX_LEN: usize = HEADER_LEN + MAX_POINTS * Point::LEN;
/// Fractional bits of `dx`, `dy` and `ds` (Q2.13).
pub const OFFSET_FRAC_BITS: u32 = 13;

/// One keypoint: a 3x3x3 DoG extremum with its sub-pixel refinement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Point {
    /// Column in the octave's image, pixels.
    pub x: u16,
    /// Row in the octave's image, pixels.
    pub y: u16,
    /// Octave (0 = full resolution).
    pub octave: u8,
    /// DoG scale index within the octave.
    pub scale: u8,
    /// Sub-pixel column offset, Q2.13 octave-local pixels.
    pub dx: i16,
    /// Sub-pixel row offset, Q2.13 octave-local pixels.
    pub dy: i16,
    /// Sub-scale offset, Q2.13 scale steps.
    pub ds: i16,
    /// DoG value; the sign tells a maximum (positive) from a minimum (negative).
    pub dog: i16,
}

impl Record for Point {
    const LEN: usize = field::point::DOG.end;

    fn read(bytes: &[u8]) -> Self {
        use field::point;
        Point {
            x: le::read_u16(bytes, point::X),
            y: le::read_u16(bytes, point::Y),
            octave: le::read_u8(bytes, point::OCTAVE),
            scale: le::read_u8(bytes, point::SCALE),
            dx: le::read_i16(bytes, point::DX),
            dy: le::read_i16(bytes, point::DY),
            ds: le::read_i16(bytes, point::DS),
            dog: le::read_i16(bytes, point::DOG),
        }
    }

    fn write(&self, bytes: &mut [u8]) {
        use field::point;
        le::write_u16(bytes, point::X, self.x);
        le::write_u16(bytes, point::Y, self.y);
        le::write_u8(bytes, point::OCTAVE, self.octave);
        le::write_u8(bytes, point::SCALE, self.scale);
        le::write_i16(bytes, point::DX, self.dx);
        le::write_i16(bytes, point::DY, self.dy);
        le::write_i16(bytes, point::DS, self.ds);
        le::write_i16(bytes, point::DOG, self.dog);
    }
}

packet_view! {
    /// A view over a `PointBatch` payload.
}

impl<T: AsRef<[u8]>> Packet<T> {
    /// Checks that the buffer holds the fixed fields and exactly `count` records, and that
    /// `count` is at most [`MAX_POINTS`].
    pub fn check_len(&self) -> Result<(), Error> {
        let len = self.buffer.as_ref().len();
        if len < HEADER_LEN {
            return Err(Error::DecodeUnexpectedEnd);
        }
        let count = usize::from(self.count());
        if count > MAX_POINTS {
            return Err(Error::DecodeTooManyRecords);
        }
        super::check_fixed_len(len, HEADER_LEN + count * Point::LEN)
    }

    /// Frame number.
    pub fn frame_id(&self) -> u32 {
        le::read_u32(self.buffer.as_ref(), field::FRAME_ID)
    }

    /// Camera.
    pub fn camera(&self) -> Camera {
        Camera::from(le::read_u8(self.buffer.as_ref(), field::CAMERA))
    }

    /// Number of point records.
    pub fn count(&self) -> u16 {
        le::read_u16(self.buffer.as_ref(), field::COUNT)
    }

    /// The point records, as bytes.
    pub fn points(&self) -> &[u8] {
        le::sub(self.buffer.as_ref(), field::POINTS..)
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

    /// Sets the record count.
    pub fn set_count(&mut self, value: u16) {
        le::write_u16(self.buffer.as_mut(), field::COUNT, value);
    }

    /// The point records, as bytes to write.
    pub fn points_mut(&mut self) -> &mut [u8] {
        le::sub_mut(self.buffer.as_mut(), field::POINTS..)
    }
}

/// A parsed `PointBatch`, borrowing the packet bytes (or, to send, a slice of points).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PointBatchRepr<'a> {
    /// Frame number.
    pub frame_id: u32,
    /// Camera.
    pub camera: Camera,
    /// The points; iterate with `points.iter()`.
    pub points: Records<'a, Point>,
}

impl<'a> PointBatchRepr<'a> {
    /// Reads a `PointBatch` payload.
    pub fn parse<T: AsRef<[u8]> + ?Sized>(
        packet: &Packet<&'a T>,
    ) -> Result<PointBatchRepr<'a>, Error> {
        packet.check_len()?;
        let data: &'a [u8] = packet.buffer.as_ref();
        Ok(PointBatchRepr {
            frame_id: packet.frame_id(),
            camera: packet.camera(),
            points: Records::Wire(le::sub(data, field::POINTS..)),
        })
    }

    /// Payload length `emit` writes.
    pub fn buffer_len(&self) -> usize {
        HEADER_LEN + self.points.wire_len()
    }

    /// Writes the payload into `packet`.
    pub fn emit<T: AsRef<[u8]> + AsMut<[u8]>>(&self, packet: &mut Packet<T>) -> Result<(), Error> {
        let count = self.points.len();
        if count > MAX_POINTS {
            return Err(Error::EncodeTooManyRecords);
        }
        check_room(packet.buffer.as_ref().len(), self.buffer_len())?;
        packet.set_frame_id(self.frame_id);
        packet.set_camera(self.camera);
        // `count <= MAX_POINTS`, which fits a u16.
        packet.set_count(count as u16);
        self.points.write(packet.points_mut());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    static PACKET_BYTES: [u8; 35] = [
        0x07, 0x00, 0x00, 0x00, // frame_id 7
        0x00, // camera Left
        0x02, 0x00, // count 2
        // point 0
        0x40, 0x01, // x 320
        0xf0, 0x00, // y 240
        0x00, // octave 0
        0x01, // scale 1
        0x00, 0x10, // dx 0x1000 = +0.5 px
        0x00, 0xf0, // dy -0x1000 = -0.5 px
        0x00, 0x00, // ds 0
        0x2c, 0x01, // dog +300 (maximum)
        // point 1
        0x0a, 0x00, // x 10
        0x14, 0x00, // y 20
        0x03, // octave 3
        0x01, // scale 1
        0xff, 0x7f, // dx 0x7fff (just under +4 px)
        0x00, 0x80, // dy -0x8000 = -4 px
        0x00, 0x20, // ds 0x2000 = +1 scale step
        0x9c, 0xff, // dog -100 (minimum)
    ];

    const POINTS: [Point; 2] = [
        Point {
            x: 320,
            y: 240,
            octave: 0,
            scale: 1,
            dx: 0x1000,
            dy: -0x1000,
            ds: 0,
            dog: 300,
        },
        Point {
            x: 10,
            y: 20,
            octave: 3,
            scale: 1,
            dx: i16::MAX,
            dy: i16::MIN,
            ds: 0x2000,
            dog: -100,
        },
    ];

    fn repr() -> PointBatchRepr<'static> {
        PointBatchRepr {
            frame_id: 7,
            camera: Camera::Left,
            points: Records::Values(&POINTS),
        }
    }

    #[test]
    fn deconstruct() {
        let packet = Packet::new_checked(&PACKET_BYTES[..]).unwrap();
        assert_eq!(packet.frame_id(), 7);
        assert_eq!(packet.camera(), Camera::Left);
        assert_eq!(packet.count(), 2);
        assert_eq!(Point::read(&packet.points()[14..]), POINTS[1]);
    }

    #[test]
    fn construct() {
        let mut bytes = [0xa5u8; 35];
        let mut packet = Packet::new_unchecked(&mut bytes[..]);
        packet.set_frame_id(7);
        packet.set_camera(Camera::Left);
        packet.set_count(2);
        POINTS[0].write(&mut packet.points_mut()[..14]);
        POINTS[1].write(&mut packet.points_mut()[14..]);
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn parse() {
        let packet = Packet::new_unchecked(&PACKET_BYTES[..]);
        let parsed = PointBatchRepr::parse(&packet).unwrap();
        assert_eq!(parsed, repr());
        assert_eq!(parsed.points.len(), 2);
        assert_eq!(parsed.points.get(1), Some(POINTS[1]));
        assert!(parsed.points.iter().eq(POINTS.iter().copied()));
    }

    #[test]
    fn emit() {
        let mut bytes = [0u8; 35];
        assert_eq!(repr().buffer_len(), 35);
        repr()
            .emit(&mut Packet::new_unchecked(&mut bytes[..]))
            .unwrap();
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn impossible_length() {
        // Shorter than the fixed fields.
        assert_eq!(
            Packet::new_checked(&PACKET_BYTES[..6]).unwrap_err(),
            Error::DecodeUnexpectedEnd
        );
        // One byte of the last record missing, one byte too many.
        assert_eq!(
            Packet::new_checked(&PACKET_BYTES[..34]).unwrap_err(),
            Error::DecodeUnexpectedEnd
        );
        let mut long = [0u8; 36];
        long[..35].copy_from_slice(&PACKET_BYTES);
        assert_eq!(
            Packet::new_checked(&long[..]).unwrap_err(),
            Error::DecodeBadLength
        );
        // A count above the maximum.
        let mut over = [0u8; HEADER_LEN];
        over[5..7].copy_from_slice(&(MAX_POINTS as u16 + 1).to_le_bytes());
        assert_eq!(
            Packet::new_checked(&over[..]).unwrap_err(),
            Error::DecodeTooManyRecords
        );
        let too_many = [Point::default(); MAX_POINTS + 1];
        let mut out = [0u8; MAX_LEN + Point::LEN];
        let repr = PointBatchRepr {
            points: Records::Values(&too_many),
            ..repr()
        };
        assert_eq!(
            repr.emit(&mut Packet::new_unchecked(&mut out[..])),
            Err(Error::EncodeTooManyRecords)
        );
        let mut short = [0u8; 34];
        assert_eq!(
            self::repr().emit(&mut Packet::new_unchecked(&mut short[..])),
            Err(Error::EncodeBufferTooSmall)
        );
    }
}
