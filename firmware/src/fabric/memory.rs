//! Static RAM of the front end.
//!
//! Two figures: the block RAM the fabric needs (bits, as the RTL sizes its memories) and the
//! bytes the Rust models occupy (`size_of`, fixed arrays, no heap). `tests/memory.rs` prints
//! both for a 640-pixel front end and checks the 256 KiB budget.

use crate::fabric::convolver::ROW_BITS;
use crate::fabric::output::POINT_FIFO_CAPACITY;

/// Bits of one Sobel FIFO entry: octave 2 + orientation 6 + magnitude 8 + x 11 + y 11.
pub const SOBEL_ENTRY_BITS: usize = 38;
/// Bits of one point FIFO entry: x 11 + y 11 + octave 2 + scale 2 + 3 × 16 offsets + 16 DoG.
pub const POINT_ENTRY_BITS: usize = 90;

/// Line and alignment memory bits of octave `k` of width `w`, as the RTL (`sc_octave`) sizes
/// them: its convolvers (four in octave 0, three beyond: G0 is the input there) with four
/// lines of [`ROW_BITS`] = 26 bits each (the row stage's unrounded sums), the alignment FIFOs
/// of 7, 5 and 3 whole lines of 16 bits (their occupancy stays below `6w+12`, `4w+8`,
/// `2w+4`, but a line memory comes whole), the DoG
/// window's two lines of 3 × 16 bits and the Sobel window's two lines of 16 bits.
pub const fn octave_ram_bits(w: usize, k: usize) -> usize {
    let convolvers = if k == 0 { 4 } else { 3 };
    convolvers * 4 * w * ROW_BITS as usize + 15 * w * 16 + 2 * w * 48 + 2 * w * 16
}

/// Block RAM bits of the whole front end for a `width`-pixel input and `octaves` octaves,
/// including the output FIFOs (Sobel `3·width` entries, point [`POINT_FIFO_CAPACITY`]).
pub const fn front_end_ram_bits(width: usize, octaves: usize) -> usize {
    let mut bits = 0;
    let mut w = width;
    let mut k = 0;
    while k < octaves {
        bits += octave_ram_bits(w, k);
        w = w.div_ceil(2);
        k += 1;
    }
    bits + 3 * width * SOBEL_ENTRY_BITS + POINT_FIFO_CAPACITY * POINT_ENTRY_BITS
}
