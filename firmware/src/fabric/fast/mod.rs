//! The fast path: the same front end computed a row at a time on slices, for the host.
//!
//! Same integers as the register-level model (plain multiplies replace the LUT distributed
//! arithmetic: `Σ_b LUT[bits_b] << b` is exactly `Σ_j tap_j · s_j`), same borders, same
//! streams, pushed into the FIFOs in the pipeline's order at the pipeline's line times
//! (`pending.rs`, `release.rs`). `tests/bit_exact.rs` proves the streams equal on random and
//! real images, `tests/fifo_order.rs` the FIFOs' contents and counters.

mod filter;
mod frontend;
mod octave;
mod pending;
mod probe;
mod release;
#[cfg(target_arch = "x86_64")]
mod simd;

pub use filter::{column_filter, cordic_row, dog_row, row_filter, sobel_row};
pub use frontend::FastFrontEnd;
pub use probe::{NoProbe, Probe};
