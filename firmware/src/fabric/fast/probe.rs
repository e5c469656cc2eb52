//! Observation hooks into the fast path (for pictures and debugging): called with every scale
//! and DoG row as it is produced. [`NoProbe`] compiles to nothing.

/// Receives intermediate rows. Every method has an empty default.
pub trait Probe {
    /// Row `y` of scale image `scale` (0 = G0 .. 3 = G3) of `octave`, Q8.8.
    fn scale_row(&mut self, _octave: u8, _scale: u8, _y: u16, _row: &[u16]) {}
    /// Row `y` of DoG image `index` (0..3) of `octave`, Q8.8.
    fn dog_row(&mut self, _octave: u8, _index: u8, _y: u16, _row: &[i16]) {}
}

/// The probe that observes nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoProbe;

impl Probe for NoProbe {}
