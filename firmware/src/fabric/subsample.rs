//! Subsampler: keeps the even columns of the even rows of G3 as the next octave's input.
//!
//! Why G3: it is the most blurred image of the octave, σ = 2 relative to the octave's base
//! of σ = 1 (the tap variances are chosen so, see [`crate::fabric::taps`]); decimated by 2 it is
//! exactly a base of σ = 1 in the next octave's grid, so octaves 1.. need no input filter and
//! their scales continue the geometric series (thesis 4.2.5, Lowe 2004 §3). G3 is also the last
//! image of the octave, so nothing extra is buffered.
//! Output size `ceil(w/2) x ceil(h/2)`. Latency: one register, [`SUBSAMPLE_LATENCY`].

use crate::fabric::geometry::Raster;

/// Subsampler latency in enabled clocks.
pub const SUBSAMPLE_LATENCY: u32 = 1;

/// The subsampler.
#[derive(Clone, Debug, Default)]
pub struct Subsampler {
    width: u16,
    pos: Raster,
    taken: u32,
    total: u32,
    out: Option<u16>,
}

impl Subsampler {
    /// Idle subsampler.
    pub const fn new() -> Self {
        Self {
            width: 0,
            pos: Raster { x: 0, y: 0 },
            taken: 0,
            total: 0,
            out: None,
        }
    }

    /// Resets for a `width` x `height` input.
    pub fn start(&mut self, width: u16, height: u16) {
        *self = Self {
            width,
            total: width as u32 * height as u32,
            ..Self::new()
        };
    }

    /// Whether the last sample has left.
    pub fn done(&self) -> bool {
        self.taken == self.total && self.out.is_none()
    }

    /// One enabled clock.
    pub fn clock(&mut self, input: Option<u16>) -> Option<u16> {
        let out = self.out.take();
        if let Some(v) = input {
            if self.pos.x & 1 == 0 && self.pos.y & 1 == 0 {
                self.out = Some(v);
            }
            self.taken += 1;
            self.pos.advance(self.width);
        }
        out
    }
}
