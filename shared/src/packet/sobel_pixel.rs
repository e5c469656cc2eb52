//! One Sobel output pixel: gradient magnitude and quantized orientation (2 bytes).
//!
//! ```text
//!  0           1             2
//! +-----------+-------------+
//! | magnitude | orientation |   orientation = 0b00oo_oooo
//! |    u8     |     u8      |
//! +-----------+-------------+
//! ```
//! The fabric's 4-step CORDIC gives the magnitude (x_n * 5/8) and the gradient angle
//! quantized to 6 bits, `orientation * 360 / 64` degrees; the angle's zero and sense are the
//! fabric's (defined by its CORDIC stage in `stereocal-firmware`), the wire only carries them.
//! The two top bits are always 0; a packet with either set is rejected.

use crate::records::{Record, Records};

/// Bits of an orientation.
pub const ORIENTATION_BITS: u32 = 6;
/// Mask of the bits an orientation may use.
pub const ORIENTATION_MASK: u8 = (1 << ORIENTATION_BITS) - 1;

/// One Sobel pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SobelPixel {
    /// Gradient magnitude.
    pub magnitude: u8,
    /// Gradient orientation in 64ths of a turn, `0..=63`.
    pub orientation: u8,
}

impl SobelPixel {
    /// `true` when the orientation fits its 6 bits.
    pub const fn is_valid(&self) -> bool {
        self.orientation & !ORIENTATION_MASK == 0
    }
}

impl Record for SobelPixel {
    const LEN: usize = 2;

    fn read(bytes: &[u8]) -> Self {
        SobelPixel {
            magnitude: bytes[0],
            orientation: bytes[1],
        }
    }

    fn write(&self, bytes: &mut [u8]) {
        bytes[0] = self.magnitude;
        bytes[1] = self.orientation;
    }
}

/// Checks the orientations of wire-format pixel bytes.
///
/// Every received Sobel byte passes through here, so instead of testing pixel by pixel this
/// ORs the pixels together as little-endian `u16`s (orientation in the high byte) and tests
/// the top two orientation bits once: a branch-free loop the compiler vectorises.
pub(crate) fn all_valid(pixels: &[u8]) -> bool {
    let ored = pixels
        .chunks_exact(SobelPixel::LEN)
        .fold(0u16, |ored, pixel| {
            ored | u16::from_le_bytes(pixel.try_into().unwrap_or_default())
        });
    orientations_fit(ored)
}

/// Whether pixels ORed together as little-endian `u16`s (orientation in the high byte) have
/// no orientation bit above [`ORIENTATION_BITS`], i.e. every one of them is valid.
fn orientations_fit(ored: u16) -> bool {
    let [_, orientations] = ored.to_le_bytes();
    orientations & !ORIENTATION_MASK == 0
}

/// Checks the orientations of pixels to send, the same way as [`all_valid`]: one OR over the
/// whole run, then one test.
pub(crate) fn all_records_valid(pixels: &Records<'_, SobelPixel>) -> bool {
    match pixels {
        Records::Wire(bytes) => all_valid(bytes),
        Records::Values(values) => {
            // Both fields, as the wire has them: one 16-bit load per pixel, which vectorises
            // where ORing the orientations alone took strided byte loads.
            orientations_fit(values.iter().fold(0u16, |ored, pixel| {
                ored | u16::from_le_bytes([pixel.magnitude, pixel.orientation])
            }))
        }
    }
}
