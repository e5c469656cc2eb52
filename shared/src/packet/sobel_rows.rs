//! `SobelRows` (`0x12`), device to host: one row of one scale's Sobel output, or a segment of
//! one.
//!
//! ```text
//!  0          4        5        6        7          9          11         13                 13+2*width
//! +----------+--------+--------+--------+----------+----------+----------+------- ... -------+
//! | frame_id | camera | octave | scale  |   row    |    x     |  width   | width Sobel pixels|
//! |  u32 LE  |   u8   |   u8   |   u8   |  u16 LE  |  u16 LE  |  u16 LE  | 2 bytes each      |
//! +----------+--------+--------+--------+----------+----------+----------+------- ... -------+
//! ```
//! `row`, `x` and `width` are in the octave's own pixels: the packet carries pixels
//! `x .. x + width` of the row, left to right, each a [`SobelPixel`] (magnitude, then 6-bit
//! orientation). A row goes out whole (`x` = 0) or cut into segments of the width
//! OUTPUT_MODE.ROW_SEGMENT sets, so that a damaged packet costs only the part of the row it
//! carried. `x + width` is at most [`MAX_WIDTH`], so a full 1280-pixel octave-0 row fits one
//! packet.

use crate::le::{self, Field};
use crate::packet::camera::Camera;
use crate::packet::check_room;
use crate::packet::sobel_pixel::{all_records_valid, all_valid, SobelPixel};
use crate::records::{Record, Records};
use crate::Error;

mod field {
    use super::Field;
    pub const FRAME_ID: Field = 0..4;
    pub const CAMERA: usize = 4;
    pub const OCTAVE: usize = 5;
    pub const SCALE: usize = 6;
    pub const ROW: Field = 7..9;
    pub const X: Field = 9..11;
    pub const WIDTH: Field = 11..13;
    pub const PIXELS: usize = 13;
}

/// Widest row one packet carries, in pixels, and the end of the widest row.
pub const MAX_WIDTH: usize = 1280;
/// Bytes before the pixels.
pub const HEADER_LEN: usize = field::PIXELS;
/// Largest `SobelRows` payload.
pub const MAX_LEN: usize = HEADER_LEN + MAX_WIDTH * SobelPixel::LEN;

packet_view! {
    /// A view over a `SobelRows` payload.
}

impl<T: AsRef<[u8]>> Packet<T> {
    /// Checks that the buffer holds the fixed fields and exactly `width` pixels, and that
    /// `x + width` is at most [`MAX_WIDTH`].
    pub fn check_len(&self) -> Result<(), Error> {
        let len = self.buffer.as_ref().len();
        if len < HEADER_LEN {
            return Err(Error::DecodeUnexpectedEnd);
        }
        let width = usize::from(self.width());
        if usize::from(self.x()) + width > MAX_WIDTH {
            return Err(Error::DecodeTooManyRecords);
        }
        super::check_fixed_len(len, HEADER_LEN + width * SobelPixel::LEN)
    }

    /// Frame number.
    pub fn frame_id(&self) -> u32 {
        le::read_u32(self.buffer.as_ref(), field::FRAME_ID)
    }

    /// Camera.
    pub fn camera(&self) -> Camera {
        Camera::from(le::read_u8(self.buffer.as_ref(), field::CAMERA))
    }

    /// Octave.
    pub fn octave(&self) -> u8 {
        le::read_u8(self.buffer.as_ref(), field::OCTAVE)
    }

    /// Scale index within the octave.
    pub fn scale(&self) -> u8 {
        le::read_u8(self.buffer.as_ref(), field::SCALE)
    }

    /// Row number in the octave's image.
    pub fn row(&self) -> u16 {
        le::read_u16(self.buffer.as_ref(), field::ROW)
    }

    /// Column of the first pixel.
    pub fn x(&self) -> u16 {
        le::read_u16(self.buffer.as_ref(), field::X)
    }

    /// Pixels in the packet.
    pub fn width(&self) -> u16 {
        le::read_u16(self.buffer.as_ref(), field::WIDTH)
    }

    /// The pixels, as bytes.
    pub fn pixels(&self) -> &[u8] {
        le::sub(self.buffer.as_ref(), field::PIXELS..)
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

    /// Sets the octave.
    pub fn set_octave(&mut self, value: u8) {
        le::write_u8(self.buffer.as_mut(), field::OCTAVE, value);
    }

    /// Sets the scale.
    pub fn set_scale(&mut self, value: u8) {
        le::write_u8(self.buffer.as_mut(), field::SCALE, value);
    }

    /// Sets the row number.
    pub fn set_row(&mut self, value: u16) {
        le::write_u16(self.buffer.as_mut(), field::ROW, value);
    }

    /// Sets the first pixel's column.
    pub fn set_x(&mut self, value: u16) {
        le::write_u16(self.buffer.as_mut(), field::X, value);
    }

    /// Sets the width.
    pub fn set_width(&mut self, value: u16) {
        le::write_u16(self.buffer.as_mut(), field::WIDTH, value);
    }

    /// The pixels, as bytes to write.
    pub fn pixels_mut(&mut self) -> &mut [u8] {
        le::sub_mut(self.buffer.as_mut(), field::PIXELS..)
    }
}

/// A parsed `SobelRows`, borrowing the packet bytes (or, to send, a slice of pixels).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SobelRowsRepr<'a> {
    /// Frame number.
    pub frame_id: u32,
    /// Camera.
    pub camera: Camera,
    /// Octave.
    pub octave: u8,
    /// Scale index within the octave.
    pub scale: u8,
    /// Row number in the octave's image.
    pub row: u16,
    /// Column of the first pixel (0 for a whole row).
    pub x: u16,
    /// The pixels from column `x` on, left to right; the width is their count.
    pub pixels: Records<'a, SobelPixel>,
}

impl<'a> SobelRowsRepr<'a> {
    /// Reads a `SobelRows` payload; rejects orientations wider than 6 bits.
    pub fn parse<T: AsRef<[u8]> + ?Sized>(
        packet: &Packet<&'a T>,
    ) -> Result<SobelRowsRepr<'a>, Error> {
        packet.check_len()?;
        let data: &'a [u8] = packet.buffer.as_ref();
        let pixels = le::sub(data, field::PIXELS..);
        if !all_valid(pixels) {
            return Err(Error::DecodeBadOrientation);
        }
        Ok(SobelRowsRepr {
            frame_id: packet.frame_id(),
            camera: packet.camera(),
            octave: packet.octave(),
            scale: packet.scale(),
            row: packet.row(),
            x: packet.x(),
            pixels: Records::Wire(pixels),
        })
    }

    /// Payload length `emit` writes.
    pub fn buffer_len(&self) -> usize {
        HEADER_LEN + self.pixels.wire_len()
    }

    /// Writes the payload into `packet`.
    pub fn emit<T: AsRef<[u8]> + AsMut<[u8]>>(&self, packet: &mut Packet<T>) -> Result<(), Error> {
        let width = self.pixels.len();
        if usize::from(self.x) + width > MAX_WIDTH {
            return Err(Error::EncodeTooManyRecords);
        }
        if !all_records_valid(&self.pixels) {
            return Err(Error::EncodeBadOrientation);
        }
        check_room(packet.buffer.as_ref().len(), self.buffer_len())?;
        packet.set_frame_id(self.frame_id);
        packet.set_camera(self.camera);
        packet.set_octave(self.octave);
        packet.set_scale(self.scale);
        packet.set_row(self.row);
        packet.set_x(self.x);
        // `width <= MAX_WIDTH`, which fits a u16.
        packet.set_width(width as u16);
        self.pixels.write(packet.pixels_mut());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    static PACKET_BYTES: [u8; 19] = [
        0x07, 0x00, 0x00, 0x00, // frame_id 7
        0x01, // camera Right
        0x02, // octave 2
        0x01, // scale 1
        0x77, 0x00, // row 119
        0x05, 0x00, // x 5
        0x03, 0x00, // width 3
        0x00, 0x00, // pixel 0: magnitude 0, orientation 0
        0x80, 0x10, // pixel 1: magnitude 128, orientation 16 (90 degrees)
        0xff, 0x3f, // pixel 2: magnitude 255, orientation 63
    ];

    const PIXELS: [SobelPixel; 3] = [
        SobelPixel {
            magnitude: 0,
            orientation: 0,
        },
        SobelPixel {
            magnitude: 128,
            orientation: 16,
        },
        SobelPixel {
            magnitude: 255,
            orientation: 63,
        },
    ];

    fn repr() -> SobelRowsRepr<'static> {
        SobelRowsRepr {
            frame_id: 7,
            camera: Camera::Right,
            octave: 2,
            scale: 1,
            row: 119,
            x: 5,
            pixels: Records::Values(&PIXELS),
        }
    }

    #[test]
    fn deconstruct() {
        let packet = Packet::new_checked(&PACKET_BYTES[..]).unwrap();
        assert_eq!(packet.frame_id(), 7);
        assert_eq!(packet.camera(), Camera::Right);
        assert_eq!(packet.octave(), 2);
        assert_eq!(packet.scale(), 1);
        assert_eq!(packet.row(), 119);
        assert_eq!(packet.x(), 5);
        assert_eq!(packet.width(), 3);
        assert_eq!(packet.pixels(), &PACKET_BYTES[13..]);
    }

    #[test]
    fn construct() {
        let mut bytes = [0xa5u8; 19];
        let mut packet = Packet::new_unchecked(&mut bytes[..]);
        packet.set_frame_id(7);
        packet.set_camera(Camera::Right);
        packet.set_octave(2);
        packet.set_scale(1);
        packet.set_row(119);
        packet.set_x(5);
        packet.set_width(3);
        packet
            .pixels_mut()
            .copy_from_slice(&[0x00, 0x00, 0x80, 0x10, 0xff, 0x3f]);
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn parse() {
        let packet = Packet::new_unchecked(&PACKET_BYTES[..]);
        assert_eq!(SobelRowsRepr::parse(&packet), Ok(repr()));
    }

    #[test]
    fn emit() {
        let mut bytes = [0u8; 19];
        repr()
            .emit(&mut Packet::new_unchecked(&mut bytes[..]))
            .unwrap();
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn orientation_top_bits_are_rejected() {
        for bad in [0x40u8, 0x80, 0xc0] {
            let mut bytes = PACKET_BYTES;
            bytes[18] = 0x3f | bad;
            let packet = Packet::new_checked(&bytes[..]).unwrap();
            assert_eq!(
                SobelRowsRepr::parse(&packet),
                Err(Error::DecodeBadOrientation)
            );
        }
        let bad = [SobelPixel {
            magnitude: 1,
            orientation: 64,
        }];
        let repr = SobelRowsRepr {
            pixels: Records::Values(&bad),
            ..repr()
        };
        let mut out = [0u8; 15];
        assert_eq!(
            repr.emit(&mut Packet::new_unchecked(&mut out[..])),
            Err(Error::EncodeBadOrientation)
        );
    }

    #[test]
    fn full_hd_row_fits() {
        let row = [SobelPixel::default(); 1280];
        let repr = SobelRowsRepr {
            x: 0,
            pixels: Records::Values(&row),
            ..repr()
        };
        let mut out = [0u8; MAX_LEN];
        assert_eq!(repr.buffer_len(), MAX_LEN);
        repr.emit(&mut Packet::new_unchecked(&mut out[..])).unwrap();
        let packet = Packet::new_checked(&out[..]).unwrap();
        assert_eq!(packet.width(), 1280);
    }

    #[test]
    fn impossible_length() {
        assert_eq!(
            Packet::new_checked(&PACKET_BYTES[..10]).unwrap_err(),
            Error::DecodeUnexpectedEnd
        );
        assert_eq!(
            Packet::new_checked(&PACKET_BYTES[..18]).unwrap_err(),
            Error::DecodeUnexpectedEnd
        );
        let mut long = [0u8; 20];
        long[..19].copy_from_slice(&PACKET_BYTES);
        assert_eq!(
            Packet::new_checked(&long[..]).unwrap_err(),
            Error::DecodeBadLength
        );
        let mut over = [0u8; HEADER_LEN];
        over[11..13].copy_from_slice(&(MAX_WIDTH as u16 + 1).to_le_bytes());
        assert_eq!(
            Packet::new_checked(&over[..]).unwrap_err(),
            Error::DecodeTooManyRecords
        );
        // A segment may not reach past the widest row either.
        let mut past = [0u8; HEADER_LEN + 2];
        past[9..11].copy_from_slice(&(MAX_WIDTH as u16).to_le_bytes());
        past[11..13].copy_from_slice(&1u16.to_le_bytes());
        assert_eq!(
            Packet::new_checked(&past[..]).unwrap_err(),
            Error::DecodeTooManyRecords
        );
        let wide = [SobelPixel::default(); MAX_WIDTH];
        let repr = SobelRowsRepr {
            x: 1,
            pixels: Records::Values(&wide),
            ..repr()
        };
        let mut out = [0u8; MAX_LEN + 2];
        assert_eq!(
            repr.emit(&mut Packet::new_unchecked(&mut out[..])),
            Err(Error::EncodeTooManyRecords)
        );
        let mut short = [0u8; 18];
        assert_eq!(
            self::repr().emit(&mut Packet::new_unchecked(&mut short[..])),
            Err(Error::EncodeBufferTooSmall)
        );
    }
}
