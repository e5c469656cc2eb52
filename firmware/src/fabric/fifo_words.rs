//! The register words of a FIFO entry: how a point fills POINT_FIFO_DATA, POINT_FIFO_DXDY and
//! POINT_FIFO_DSDOG, and a Sobel pixel SOBEL_FIFO_DATA and SOBEL_FIFO_POSITION.
//!
//! The fabric device ([`crate::fabric::device`]) and the Sobel FIFO that stores these words
//! ([`crate::fabric::sobel_fifo`]) encode with these functions and the driver decodes points
//! with them (Sobel words it decodes a burst at a time, with the same generated field
//! constants of the register map). A word read from an empty FIFO has VALID clear.

use stereocal_hdl::regs::{
    point_fifo_data as pdata, point_fifo_dsdog as pdsdog, point_fifo_dxdy as pdxdy,
    sobel_fifo_data as sdata, sobel_fifo_position as spos,
};
use stereocal_hdl::Field;

use crate::fabric::output::{Extremum, SobelEntry};
use crate::fabric::refine::Offset;
use crate::fabric::sobel_fifo::SobelRun;

/// The registers one point is read from, in the order the driver reads them: the pop first.
pub const POINT_OFFSETS: [u16; 3] = [pdata::OFFSET, pdxdy::OFFSET, pdsdog::OFFSET];

/// The registers one Sobel pixel is read from: the pop first.
pub const SOBEL_OFFSETS: [u16; 2] = [sdata::OFFSET, spos::OFFSET];

/// The DoG level every point reports (SCALE): with three DoG levels per octave only the middle
/// one has a level above and below.
const POINT_SCALE: u32 = 1;

/// `value` in `field`'s bits (bits above the field's width are cut, as the RTL's wires cut
/// them).
const fn put(field: &Field, value: u32) -> u32 {
    let bits = field.bits;
    match (value & bits.max_value()).checked_shl(bits.lsb as u32) {
        Some(v) => v,
        None => 0,
    }
}

/// `point` as the three words the fabric shows after popping it.
#[inline]
pub fn point_words(point: &Extremum) -> [u32; 3] {
    let bits = |o: Offset| u32::from(o.to_bits() as u16);
    [
        put(&pdata::X, point.x.into())
            | put(&pdata::Y, point.y.into())
            | put(&pdata::OCTAVE, point.octave.into())
            | put(&pdata::SCALE, POINT_SCALE)
            | put(&pdata::VALID, 1),
        put(&pdxdy::DX, bits(point.dx)) | put(&pdxdy::DY, bits(point.dy)),
        put(&pdsdog::DS, bits(point.ds)) | put(&pdsdog::DOG, u32::from(point.dog as u16)),
    ]
}

/// The point three words read after one pop hold, or `None` when the FIFO was empty.
#[inline]
pub fn point_from_words(words: [u32; 3]) -> Option<Extremum> {
    let [data, dxdy, dsdog] = words;
    if pdata::VALID.extract(data) == 0 {
        return None;
    }
    let offset = |field: &Field, word: u32| Offset::from_bits(field.extract(word) as u16 as i16);
    Some(Extremum {
        x: pdata::X.extract(data) as u16,
        y: pdata::Y.extract(data) as u16,
        octave: pdata::OCTAVE.extract(data) as u8,
        scale: pdata::SCALE.extract(data) as u8,
        dx: offset(&pdxdy::DX, dxdy),
        dy: offset(&pdxdy::DY, dxdy),
        ds: offset(&pdsdog::DS, dsdog),
        dog: pdsdog::DOG.extract(dsdog) as u16 as i16,
    })
}

/// What the words of every pixel of one row of one octave share, so that a pixel's words
/// cost its own three fields.
#[derive(Clone, Copy, Debug)]
pub struct SobelRowWords {
    data: u32,
    position: u32,
}

impl SobelRowWords {
    /// For row `y` of `octave`.
    #[inline]
    pub const fn new(octave: u8, y: u16) -> Self {
        Self {
            data: put(&sdata::OCTAVE, octave as u32) | put(&sdata::VALID, 1),
            position: put(&spos::Y, y as u32),
        }
    }

    /// The two words of the row's pixel at column `x`.
    #[inline(always)]
    pub const fn pixel(&self, x: u16, magnitude: u8, orientation: u8) -> [u32; 2] {
        [
            self.data
                | put(&sdata::MAGNITUDE, magnitude as u32)
                | put(&sdata::ORIENTATION, orientation as u32),
            self.position | put(&spos::X, x as u32),
        ]
    }
}

/// `pixel` as the two words the fabric shows after popping it.
#[inline]
pub fn sobel_words(pixel: &SobelEntry) -> [u32; 2] {
    SobelRowWords::new(pixel.octave, pixel.y).pixel(pixel.x, pixel.magnitude, pixel.orientation)
}

/// The Sobel pixel two words read after one pop hold, or `None` when the FIFO was empty.
#[inline]
pub fn sobel_from_words(words: [u32; 2]) -> Option<SobelEntry> {
    let [data, position] = words;
    if sdata::VALID.extract(data) == 0 {
        return None;
    }
    Some(SobelEntry {
        octave: sdata::OCTAVE.extract(data) as u8,
        orientation: sdata::ORIENTATION.extract(data) as u8,
        magnitude: sdata::MAGNITUDE.extract(data) as u8,
        x: spos::X.extract(position) as u16,
        y: spos::Y.extract(position) as u16,
    })
}

/// The words of `run`'s pixels, two per pixel as [`sobel_words`] gives them, into the front
/// of `words`; returns how many pixels fit.
#[inline]
pub fn sobel_run_words(run: &SobelRun<'_>, words: &mut [u32]) -> usize {
    let row = SobelRowWords::new(run.octave, run.y);
    let mut n = 0;
    let pixels = run.magnitude.iter().zip(run.orientation);
    for (entry, (&magnitude, &orientation)) in words.chunks_exact_mut(2).zip(pixels) {
        entry.copy_from_slice(&row.pixel(run.x.wrapping_add(n as u16), magnitude, orientation));
        n += 1;
    }
    n
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;

    #[test]
    fn entries_round_trip_through_their_words() {
        let point = Extremum {
            x: 1279,
            y: 1023,
            octave: 3,
            scale: 1,
            dx: Offset::from_bits(-4096),
            dy: Offset::from_bits(8191),
            ds: Offset::from_bits(-1),
            dog: -32768,
        };
        assert_eq!(point_from_words(point_words(&point)), Some(point));
        let pixel = SobelEntry {
            octave: 2,
            orientation: 63,
            magnitude: 255,
            x: 319,
            y: 255,
        };
        let [data, position] = sobel_words(&pixel);
        assert_eq!(sobel_from_words([data, position]), Some(pixel));
        assert_eq!(sdata::MAGNITUDE.extract(data), 255);
        assert_eq!(sdata::ORIENTATION.extract(data), 63);
        assert_eq!(sdata::OCTAVE.extract(data), 2);
        assert_eq!(sdata::VALID.extract(data), 1);
        assert_eq!(
            (spos::X.extract(position), spos::Y.extract(position)),
            (319, 255)
        );
    }

    #[test]
    fn a_run_gives_the_words_of_its_pixels() {
        let (magnitude, orientation) = ([9, 8, 7], [1, 2, 3]);
        let run = SobelRun {
            octave: 1,
            y: 5,
            x: 10,
            magnitude: &magnitude,
            orientation: &orientation,
        };
        let mut words = [0; 5];
        assert_eq!(sobel_run_words(&run, &mut words), 2);
        let pixels: std::vec::Vec<_> = run.pixels().take(2).collect();
        assert_eq!(words[..2], sobel_words(&pixels[0]));
        assert_eq!(words[2..4], sobel_words(&pixels[1]));
        assert_eq!(words[4], 0);
    }

    #[test]
    fn words_of_an_empty_fifo_decode_to_nothing() {
        assert_eq!(point_from_words([0; 3]), None);
        assert_eq!(sobel_from_words([0; 2]), None);
    }
}
