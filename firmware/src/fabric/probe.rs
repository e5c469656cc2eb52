//! Observation ports of the register-level model: what the RTL top `sc_frontend` exposes for
//! co-simulation, recorded by [`RegisterFrontEnd`](crate::fabric::RegisterFrontEnd) on every
//! clock.
//!
//! After each [`RegisterFrontEnd::clock`](crate::fabric::RegisterFrontEnd::clock),
//! [`RegisterFrontEnd::probe`](crate::fabric::RegisterFrontEnd::probe) holds the values the
//! observation ports of `sc_frontend` carry during that clock (before its rising edge), one
//! [`OctaveProbe`] per octave:
//!
//! | field | `sc_frontend` port (octave `k`) | Rust signal in [`octave`](crate::fabric::octave) |
//! |---|---|---|
//! | [`en`](OctaveProbe::en) | `oct_en[k]` | the octave's clock enable (`in_valid \|\| flushing`) |
//! | [`g`](OctaveProbe::g) | `g_valid[k*4+i]`, `g_data[(k*4+i)*16 +: 16]` | the `g[i]` wires (octaves 1..: `g[0]` = the input) |
//! | [`dog`](OctaveProbe::dog) | `dog_valid[k]`, `dog_data[(k*3+j)*16 +: 16]` | the DoG register's output entering the DoG window |
//! | [`sub`](OctaveProbe::sub) | `sub_valid[k]`, `sub_data[k*16 +: 16]` | the subsampler's output register (octave `k+1`'s input) |
//! | [`point`](OctaveProbe::point) | `pt_valid[k]`, `pt_data[k*96 +: 96]` | the refine register's output, pushed to the point FIFO |
//! | [`sobel`](OctaveProbe::sobel) | `sb_valid[k]`, `sb_data[k*46 +: 46]` | the CORDIC output, pushed to the Sobel FIFO |
//!
//! A valid strobe is `Some`. Every field of an octave that is not enabled on a clock (and of
//! every octave beyond `Config::octaves`) is `false` / `None`.
//!
//! The recording costs a few stores per octave per clock, paid by `clock` only: the row
//! interface (`push_row`, `blank_row`: the driver's and the benchmark's path) clocks without
//! it (a const generic). Nothing is allocated.

use crate::fabric::output::{Extremum, SobelEntry};

/// The observation signals of one octave during one clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OctaveProbe {
    /// The octave advanced on this clock (its clock enable).
    pub en: bool,
    /// The scale-image wires `g[0..4]` (Q8.8).
    pub g: [Option<u16>; 4],
    /// The DoG register's output `D0..D2` (i16 Q8.8), entering the DoG window.
    pub dog: Option<[i16; 3]>,
    /// The subsampler's output register: the next octave's input sample.
    pub sub: Option<u16>,
    /// The point pushed into the point FIFO.
    pub point: Option<Extremum>,
    /// The Sobel pixel pushed into the Sobel FIFO.
    pub sobel: Option<SobelEntry>,
}

impl OctaveProbe {
    /// An octave that did not advance.
    pub const IDLE: Self = Self {
        en: false,
        g: [None; 4],
        dog: None,
        sub: None,
        point: None,
        sobel: None,
    };
}

/// The observation ports of `sc_frontend` during one clock, octave by octave.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ClockProbe {
    /// Octave `k` at index `k`.
    pub octaves: [OctaveProbe; 4],
}

impl ClockProbe {
    /// No octave advanced.
    pub const IDLE: Self = Self {
        octaves: [OctaveProbe::IDLE; 4],
    };
}
