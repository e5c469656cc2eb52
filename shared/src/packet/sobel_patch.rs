//! `SobelPatch` (`0x13`), device to host: the 16x16 Sobel pixels around one keypoint.
//!
//! ```text
//!  0          4        5             7        8        9          11         13          525
//! +----------+--------+-------------+--------+--------+----------+----------+---- ... ---+
//! | frame_id | camera | point_index | octave | scale  |    x     |    y     | 256 pixels |
//! |  u32 LE  |   u8   |   u16 LE    |   u8   |   u8   |  u16 LE  |  u16 LE  | 2 B each   |
//! +----------+--------+-------------+--------+--------+----------+----------+---- ... ---+
//! ```
//! `point_index` is the keypoint's position among the frame's points (in `PointBatch` order).
//! `x`, `y` is the patch centre in the octave's pixels; the patch covers columns `x-8..=x+7`
//! and rows `y-8..=y+7`, row-major from the top-left, each pixel a [`SobelPixel`]
//! (magnitude, then 6-bit orientation).

use crate::le::{self, Field};
use crate::packet::camera::Camera;
use crate::packet::sobel_pixel::{all_records_valid, all_valid, SobelPixel};
use crate::packet::{check_fixed_len, check_room};
use crate::records::{Record, Records};
use crate::Error;

mod field {
    use super::Field;
    pub const FRAME_ID: Field = 0..4;
    pub const CAMERA: usize = 4;
    pub const POINT_INDEX: Field = 5..7;
    pub const OCTAVE: usize = 7;
    pub const SCALE: usize = 8;
    pub const X: Field = 9..11;
    pub const Y: Field = 11..13;
    pub const PIXELS: usize = 13;
}

/// Side of the square patch, pixels.
pub const PATCH_SIZE: usize = 16;
/// Pixels in a patch.
pub const PATCH_PIXELS: usize = PATCH_SIZE * PATCH_SIZE;
/// Bytes before the pixels.
pub const HEADER_LEN: usize = field::PIXELS;
/// Payload length of a `SobelPatch` (fixed).
pub const LEN: usize = HEADER_LEN + PATCH_PIXELS * SobelPixel::LEN;

packet_view! {
    /// A view over a `SobelPatch` payload.
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

    /// The keypoint's index among the frame's points.
    pub fn point_index(&self) -> u16 {
        le::read_u16(self.buffer.as_ref(), field::POINT_INDEX)
    }

    /// Octave.
    pub fn octave(&self) -> u8 {
        le::read_u8(self.buffer.as_ref(), field::OCTAVE)
    }

    /// Scale index within the octave.
    pub fn scale(&self) -> u8 {
        le::read_u8(self.buffer.as_ref(), field::SCALE)
    }

    /// Patch centre column, octave pixels.
    pub fn x(&self) -> u16 {
        le::read_u16(self.buffer.as_ref(), field::X)
    }

    /// Patch centre row, octave pixels.
    pub fn y(&self) -> u16 {
        le::read_u16(self.buffer.as_ref(), field::Y)
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

    /// Sets the keypoint index.
    pub fn set_point_index(&mut self, value: u16) {
        le::write_u16(self.buffer.as_mut(), field::POINT_INDEX, value);
    }

    /// Sets the octave.
    pub fn set_octave(&mut self, value: u8) {
        le::write_u8(self.buffer.as_mut(), field::OCTAVE, value);
    }

    /// Sets the scale.
    pub fn set_scale(&mut self, value: u8) {
        le::write_u8(self.buffer.as_mut(), field::SCALE, value);
    }

    /// Sets the centre column.
    pub fn set_x(&mut self, value: u16) {
        le::write_u16(self.buffer.as_mut(), field::X, value);
    }

    /// Sets the centre row.
    pub fn set_y(&mut self, value: u16) {
        le::write_u16(self.buffer.as_mut(), field::Y, value);
    }

    /// The pixels, as bytes to write.
    pub fn pixels_mut(&mut self) -> &mut [u8] {
        le::sub_mut(self.buffer.as_mut(), field::PIXELS..)
    }
}

/// A parsed `SobelPatch`, borrowing the packet bytes (or, to send, a slice of 256 pixels).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SobelPatchRepr<'a> {
    /// Frame number.
    pub frame_id: u32,
    /// Camera.
    pub camera: Camera,
    /// The keypoint's index among the frame's points.
    pub point_index: u16,
    /// Octave.
    pub octave: u8,
    /// Scale index within the octave.
    pub scale: u8,
    /// Patch centre column, octave pixels.
    pub x: u16,
    /// Patch centre row, octave pixels.
    pub y: u16,
    /// Exactly [`PATCH_PIXELS`] pixels, row-major from the top-left.
    pub pixels: Records<'a, SobelPixel>,
}

impl<'a> SobelPatchRepr<'a> {
    /// Reads a `SobelPatch` payload; rejects orientations wider than 6 bits.
    pub fn parse<T: AsRef<[u8]> + ?Sized>(
        packet: &Packet<&'a T>,
    ) -> Result<SobelPatchRepr<'a>, Error> {
        packet.check_len()?;
        let data: &'a [u8] = packet.buffer.as_ref();
        let pixels = le::sub(data, field::PIXELS..);
        if !all_valid(pixels) {
            return Err(Error::DecodeBadOrientation);
        }
        Ok(SobelPatchRepr {
            frame_id: packet.frame_id(),
            camera: packet.camera(),
            point_index: packet.point_index(),
            octave: packet.octave(),
            scale: packet.scale(),
            x: packet.x(),
            y: packet.y(),
            pixels: Records::Wire(pixels),
        })
    }

    /// Payload length `emit` writes.
    pub const fn buffer_len(&self) -> usize {
        LEN
    }

    /// Writes the payload into `packet`.
    pub fn emit<T: AsRef<[u8]> + AsMut<[u8]>>(&self, packet: &mut Packet<T>) -> Result<(), Error> {
        if self.pixels.len() != PATCH_PIXELS {
            return Err(Error::EncodeBadPatchSize);
        }
        if !all_records_valid(&self.pixels) {
            return Err(Error::EncodeBadOrientation);
        }
        check_room(packet.buffer.as_ref().len(), self.buffer_len())?;
        packet.set_frame_id(self.frame_id);
        packet.set_camera(self.camera);
        packet.set_point_index(self.point_index);
        packet.set_octave(self.octave);
        packet.set_scale(self.scale);
        packet.set_x(self.x);
        packet.set_y(self.y);
        self.pixels.write(packet.pixels_mut());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pixel `i` of the test patch: magnitude `i`, orientation `i mod 64`.
    fn pixel(i: usize) -> SobelPixel {
        SobelPixel {
            magnitude: i as u8,
            orientation: (i % 64) as u8,
        }
    }

    /// The fixed fields; the pixels follow, pixel `i` = (magnitude `i`, orientation `i % 64`).
    const PACKET_HEAD: [u8; HEADER_LEN] = [
        0x07, 0x00, 0x00, 0x00, // frame_id 7
        0x00, // camera Left
        0x05, 0x00, // point_index 5
        0x01, // octave 1
        0x01, // scale 1
        0xa0, 0x00, // x 160
        0x78, 0x00, // y 120
    ];

    static PACKET_BYTES: [u8; LEN] = {
        let mut bytes = [0u8; LEN];
        let mut i = 0;
        while i < HEADER_LEN {
            bytes[i] = PACKET_HEAD[i];
            i += 1;
        }
        let mut pixel = 0;
        while pixel < PATCH_PIXELS {
            bytes[HEADER_LEN + 2 * pixel] = pixel as u8;
            bytes[HEADER_LEN + 2 * pixel + 1] = (pixel % 64) as u8;
            pixel += 1;
        }
        bytes
    };

    fn pixels() -> [SobelPixel; PATCH_PIXELS] {
        core::array::from_fn(pixel)
    }

    fn repr(pixels: &[SobelPixel]) -> SobelPatchRepr<'_> {
        SobelPatchRepr {
            frame_id: 7,
            camera: Camera::Left,
            point_index: 5,
            octave: 1,
            scale: 1,
            x: 160,
            y: 120,
            pixels: Records::Values(pixels),
        }
    }

    #[test]
    fn deconstruct() {
        let bytes = PACKET_BYTES;
        let packet = Packet::new_checked(&bytes[..]).unwrap();
        assert_eq!(packet.frame_id(), 7);
        assert_eq!(packet.camera(), Camera::Left);
        assert_eq!(packet.point_index(), 5);
        assert_eq!(packet.octave(), 1);
        assert_eq!(packet.scale(), 1);
        assert_eq!(packet.x(), 160);
        assert_eq!(packet.y(), 120);
        assert_eq!(SobelPixel::read(&packet.pixels()[2 * 100..]), pixel(100));
    }

    #[test]
    fn construct() {
        let mut bytes = [0xa5u8; LEN];
        let mut packet = Packet::new_unchecked(&mut bytes[..]);
        packet.set_frame_id(7);
        packet.set_camera(Camera::Left);
        packet.set_point_index(5);
        packet.set_octave(1);
        packet.set_scale(1);
        packet.set_x(160);
        packet.set_y(120);
        for (i, chunk) in packet.pixels_mut().chunks_exact_mut(2).enumerate() {
            pixel(i).write(chunk);
        }
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn parse() {
        let bytes = PACKET_BYTES;
        let pixels = pixels();
        let packet = Packet::new_unchecked(&bytes[..]);
        assert_eq!(SobelPatchRepr::parse(&packet), Ok(repr(&pixels)));
    }

    #[test]
    fn emit() {
        let pixels = pixels();
        let mut bytes = [0u8; LEN];
        repr(&pixels)
            .emit(&mut Packet::new_unchecked(&mut bytes[..]))
            .unwrap();
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn orientation_top_bits_are_rejected() {
        let mut bytes = PACKET_BYTES;
        bytes[LEN - 1] |= 0x80;
        let packet = Packet::new_checked(&bytes[..]).unwrap();
        assert_eq!(
            SobelPatchRepr::parse(&packet),
            Err(Error::DecodeBadOrientation)
        );
        let mut pixels = pixels();
        pixels[3].orientation = 0x40;
        let mut out = [0u8; LEN];
        assert_eq!(
            repr(&pixels).emit(&mut Packet::new_unchecked(&mut out[..])),
            Err(Error::EncodeBadOrientation)
        );
    }

    #[test]
    fn impossible_length() {
        let bytes = PACKET_BYTES;
        assert_eq!(
            Packet::new_checked(&bytes[..LEN - 1]).unwrap_err(),
            Error::DecodeUnexpectedEnd
        );
        let long = [0u8; LEN + 1];
        assert_eq!(
            Packet::new_checked(&long[..]).unwrap_err(),
            Error::DecodeBadLength
        );
        let pixels = pixels();
        let mut out = [0u8; LEN];
        assert_eq!(
            repr(&pixels[1..]).emit(&mut Packet::new_unchecked(&mut out[..])),
            Err(Error::EncodeBadPatchSize)
        );
        let mut short = [0u8; LEN - 1];
        assert_eq!(
            repr(&pixels).emit(&mut Packet::new_unchecked(&mut short[..])),
            Err(Error::EncodeBufferTooSmall)
        );
    }
}
