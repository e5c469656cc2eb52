//! Frame geometry shared by every stage: octave sizes and the raster position counter.

/// The octave sizes are part of the wire format (a receiver places octave-local coordinates
/// by them), so the fabric builds its octaves by the wire crate's rule.
pub use stereocal_wire::octave_dims;

/// Raster position counter (the column and row counters every stage keeps in hardware).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Raster {
    /// Column, 0..width.
    pub x: u16,
    /// Row; runs past the frame while a stage is flushed with phantom samples.
    pub y: u16,
}

impl Raster {
    /// Moves to the next sample of a `width`-wide raster.
    #[inline]
    pub fn advance(&mut self, width: u16) {
        self.x += 1;
        if self.x == width {
            self.x = 0;
            self.y = self.y.wrapping_add(1);
        }
    }
}

/// `v` clamped to `0..=max` (replicated border).
#[inline]
pub const fn clamp_index(v: i32, max: i32) -> i32 {
    if v < 0 {
        0
    } else if v > max {
        max
    } else {
        v
    }
}
