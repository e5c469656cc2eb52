//! The FPGA front end ("fabric"), modelled stage by stage.
//!
//! [`FabricDevice`] is the fabric as a program sees it, `sc_fabric` behind its register map
//! and PIXEL_IN port ([`device`]), with its [`stream`] engine sending the frame's packets on
//! the LINK_OUT port. Its datapath is one of two implementations producing
//! bit-identical outputs behind one trait, [`FrontEnd`] ([`FabricModel`] picks one at run
//! time):
//! - [`RegisterFrontEnd`]: the register-level model, one [`RegisterFrontEnd::clock`] per pixel
//!   with explicit pipeline registers, line memories and the hardware's bit widths. It is the
//!   specification the RTL must match clock for clock.
//! - [`FastFrontEnd`]: a row-at-a-time implementation of the same arithmetic for the host.
//!
//! # Data path and widths
//! | signal | format |
//! |---|---|
//! | camera pixel | `u8` |
//! | scale images G0..G3 | `u16` Q8.8 (octave 0 input is `pixel << 8`; G0 is the input filter in octave 0 and the subsampled G3 of the previous octave in octaves 1..) |
//! | taps | 10-bit, sum 1024 ([`taps`]) |
//! | DoG | `i16` Q8.8, saturating |
//! | Sobel `Sx, Sy` | 19-bit signed |
//! | offsets `dx, dy, ds` | `I3F13` (Q2.13) |
//! | magnitude / orientation | `u8` / 6-bit |
//!
//! Stages: [`linebuffer`], [`convolver`] (row then column, LUT distributed arithmetic), [`dog`],
//! [`window`], [`extrema`], [`edge`], [`refine`], [`sobel`], [`cordic`], [`subsample`],
//! assembled in [`octave`] and [`pipeline`] ([`probe`]: the RTL's observation ports);
//! [`latency`] and [`memory`] give the figures.

pub mod config;
pub mod convolver;
pub mod cordic;
pub mod device;
pub mod dog;
pub mod edge;
pub mod extrema;
pub mod fast;
pub mod fifo;
pub mod fifo_words;
pub mod geometry;
pub mod latency;
pub mod linebuffer;
pub mod memory;
pub mod model;
pub mod octave;
pub mod output;
pub mod pipeline;
pub mod probe;
pub mod refine;
pub mod sobel;
pub mod sobel_fifo;
pub mod stream;
pub mod subsample;
pub mod taps;
pub mod window;

pub use config::{Config, ConfigError};
pub use device::FabricDevice;
pub use fast::FastFrontEnd;
pub use model::FabricModel;
pub use output::{
    run_frame, ClockedFrontEnd, Extremum, FrameError, FrontEnd, Overflow, SobelEntry,
};
pub use pipeline::RegisterFrontEnd;
pub use probe::{ClockProbe, OctaveProbe};
pub use sobel_fifo::SobelRun;
