//! Static RAM of the front end.
//!
//! Two figures: the block RAM the fabric needs (bits, as the RTL sizes its memories) and the
//! bytes the Rust models occupy (`size_of`, fixed arrays, no heap). `tests/memory.rs` prints
//! both for a 640-pixel front end and checks the 256 KiB budget.

use crate::fabric::convolver::ROW_BITS;
use crate::fabric::output::POINT_FIFO_CAPACITY;

/// Bits of one entry of each output FIFO. The RTL declares them (the `DW` of `sc_fabric`'s
/// two `sc_out_fifo` instances: a point is octave 2 + DoG, ds, dy, dx 4 × 16 + y 11 + x 11 =
/// 88, a Sobel pixel octave 2 + orientation 6 + magnitude 8 + y 16 + x 16 = 48), and
/// `tests/memory.rs` reads them from there.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FifoEntryBits {
    pub point: usize,
    pub sobel: usize,
}

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
/// including the output FIFOs (Sobel `3·width` entries, point [`POINT_FIFO_CAPACITY`]) with
/// entries of `entry` bits.
pub const fn front_end_ram_bits(width: usize, octaves: usize, entry: FifoEntryBits) -> usize {
    let mut bits = 0;
    let mut w = width;
    let mut k = 0;
    while k < octaves {
        bits += octave_ram_bits(w, k);
        w = w.div_ceil(2);
        k += 1;
    }
    bits + 3 * width * entry.sobel + POINT_FIFO_CAPACITY * entry.point
}
