//! Frame geometry shared by every stage: octave sizes and the raster position counter.

/// Size of octave `k` for a `width` x `height` input: each octave keeps the even columns and
/// the even rows of the previous one, so sizes round up (`(n + 1) / 2`).
pub const fn octave_dims(width: u16, height: u16, k: u8) -> (u16, u16) {
    let (mut w, mut h, mut i) = (width, height, 0);
    while i < k {
        w = w.div_ceil(2);
        h = h.div_ceil(2);
        i += 1;
    }
    (w, h)
}

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
