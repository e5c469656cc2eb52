//! Wire points to full-resolution keypoints.
//!
//! The fabric's subsampler keeps the even columns of the even rows of each octave's last
//! scale (`stereocal_firmware::fabric::subsample`), so octave pixel `i` *is* input pixel
//! `i · 2^o`: no half-pixel shift between octaves. A refined octave position `x + dx` is
//! therefore at `(x + dx) · 2^o` in the input image, pixel centres at integers.

use stereocal_wire::{Point, OFFSET_FRAC_BITS};

use crate::features::Keypoint;

/// One unit of a Q2.13 offset.
const OFFSET_ONE: f32 = (1u32 << OFFSET_FRAC_BITS) as f32;
/// One grey level of the fabric's Q8.8 DoG.
const DOG_ONE: f32 = 256.0;

/// The keypoint of a wire point: full-resolution position, scale index plus its sub-scale
/// offset, DoG in grey levels (sign kept: positive for a maximum).
///
/// `octave` must be below 32 (the caller checks it against the frame's octave count).
pub fn keypoint(p: &Point) -> Keypoint {
    let step = (1u32 << p.octave.min(31)) as f32;
    Keypoint {
        x: (f32::from(p.x) + f32::from(p.dx) / OFFSET_ONE) * step,
        y: (f32::from(p.y) + f32::from(p.dy) / OFFSET_ONE) * step,
        octave: p.octave,
        scale: f32::from(p.scale) + f32::from(p.ds) / OFFSET_ONE,
        dog: f32::from(p.dog) / DOG_ONE,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(x: u16, y: u16, octave: u8, dx: i16, dy: i16) -> Point {
        Point {
            x,
            y,
            octave,
            scale: 1,
            dx,
            dy,
            ds: -4096,
            dog: -384,
        }
    }

    #[test]
    fn octave_zero_adds_the_offsets() {
        let k = keypoint(&point(10, 20, 0, 4096, -2048));
        assert_eq!((k.x, k.y), (10.5, 19.75));
        assert_eq!(k.scale, 0.5);
        assert_eq!(k.dog, -1.5);
    }

    #[test]
    fn higher_octaves_scale_position_and_offset() {
        // Octave 2: pixel (3, 5) is input pixel (12, 20); +0.25 octave pixel is +1 input pixel.
        let k = keypoint(&point(3, 5, 2, 2048, -8192));
        assert_eq!((k.x, k.y), (13.0, 16.0));
        assert_eq!(k.octave_position(), (3.25, 4.0));
    }
}
