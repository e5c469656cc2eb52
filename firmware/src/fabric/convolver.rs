//! 5-tap separable Gaussian convolver: a row stage then a column stage, both computing the dot
//! product by LUT distributed arithmetic (no multiplier on the pixel path).
//!
//! # Widths, and one rounding
//! Input and output are scale-image pixels, `u16` in Q8.8 (grey level with 8 fractional bits).
//! The row stage does not round: its output is the exact sum `Σ tap·sample`, 26 bits
//! ([`ROW_BITS`]; `65535 · 1024 < 2^26`, Q8.18), and the column stage's line memories hold
//! those 26 bits. The column stage rounds once, `(Σ tap·row + 2^19) >> 20` (round half up,
//! 36-bit accumulator), so the separable pair computes exactly the direct 2-D convolution with
//! the outer product of the quantized taps: `tests/convolver.rs` checks that against a plain
//! 2-D loop. Rounding after the row pass as well would save 10 bits per line-memory word
//! (16 instead of 26) but makes the result depend on the pass order by up to one code.
//! The output never exceeds the largest input (unity DC gain), so it fits 16 bits.
//!
//! # Border
//! Replicated: a tap that falls outside the frame reads the nearest edge pixel. The row stage
//! does it with a multiplexer on its 5-sample shift register; the column stage with a
//! multiplexer on the line-buffer read ports.
//!
//! # Latency (enabled clocks, one input sample per enabled clock)
//! Row stage: 2 samples look-ahead + 1 output register = [`ROW_LATENCY`]. Column stage: 2 rows
//! look-ahead + 1 output register = `2·width + 1` ([`column_latency`]).
//!
//! # Flush
//! The last two columns / rows need samples after the frame. When its input is complete a stage
//! treats an enabled clock without input as a *phantom* sample (value ignored, border replicated)
//! until it has produced `width·height` outputs.

use crate::fabric::geometry::{clamp_index, Raster};
use crate::fabric::linebuffer::LineBuffer;
use crate::fabric::taps::TAP_BITS;

/// Row stage latency in enabled clocks.
pub const ROW_LATENCY: u32 = 3;

/// Bits of a row-stage output (an unrounded Q8.8 x Q0.10 dot product).
pub const ROW_BITS: u32 = 16 + TAP_BITS;

/// Right shift of the column stage: both passes' tap fractions.
pub const COLUMN_SHIFT: u32 = 2 * TAP_BITS;

/// Column stage latency in enabled clocks for a `width`-pixel row.
pub const fn column_latency(width: u16) -> u32 {
    2 * width as u32 + 1
}

/// One Gaussian (row then column stage) in enabled clocks.
pub const fn gaussian_latency(width: u16) -> u32 {
    ROW_LATENCY + column_latency(width)
}

/// Distributed-arithmetic dot product of 5 samples of `planes` bits with the kernel whose DA
/// table is `lut`: for every bit plane `b` the 5 sample bits address the table and the partial
/// products are added with a shift of `b`. Exact (no rounding).
#[inline]
fn da_sum(lut: &[u16; 32], s: [u32; 5], planes: u32) -> u64 {
    let mut acc: u64 = 0;
    for b in 0..planes {
        let mut addr = 0usize;
        for (j, &v) in s.iter().enumerate() {
            addr |= (((v >> b) & 1) as usize) << j;
        }
        // `addr` has 5 bits (one per sample), so the mask is a no-op that rules out a panic.
        acc += u64::from(lut[addr & 31]) << b;
    }
    acc
}

/// The row stage's dot product of 5 Q8.8 samples: the exact [`ROW_BITS`]-bit sum.
#[inline]
pub fn da_row(lut: &[u16; 32], s: [u16; 5]) -> u32 {
    // At most 1024 · 65535 < 2^26: the cast keeps every bit.
    da_sum(lut, s.map(u32::from), 16) as u32
}

/// The column stage's dot product of 5 row-stage outputs, rounded once to Q8.8.
#[inline]
pub fn da_column(lut: &[u16; 32], s: [u32; 5]) -> u16 {
    let acc = da_sum(lut, s, ROW_BITS);
    // Unity DC gain: the rounded value is at most the largest Q8.8 input, so it fits 16 bits.
    ((acc + (1 << (COLUMN_SHIFT - 1))) >> COLUMN_SHIFT) as u16
}

/// Horizontal 5-tap stage.
#[derive(Clone, Debug)]
pub struct RowConvolver {
    lut: [u16; 32],
    width: u16,
    total: u32,
    /// Shift register, `shift[0]` newest sample.
    shift: [u16; 5],
    /// Samples (real or phantom) taken in.
    taken: u32,
    /// Position of the next output (centre) pixel.
    centre: Raster,
    emitted: u32,
    out: Option<u32>,
}

impl RowConvolver {
    /// A stage with DA table `lut`, idle until [`Self::start`].
    pub const fn new(lut: [u16; 32]) -> Self {
        Self {
            lut,
            width: 0,
            total: 0,
            shift: [0; 5],
            taken: 0,
            centre: Raster { x: 0, y: 0 },
            emitted: 0,
            out: None,
        }
    }

    /// Resets the counters for a `width` x `height` frame.
    pub fn start(&mut self, width: u16, height: u16) {
        *self = Self {
            width,
            total: width as u32 * height as u32,
            ..Self::new(self.lut)
        };
    }

    /// One enabled clock. Returns the output register (the value on the stage's output wire
    /// during this clock, [`ROW_BITS`] wide), then latches the new one.
    pub fn clock(&mut self, input: Option<u16>) -> Option<u32> {
        let out = self.out.take();
        let sample = match input {
            Some(v) => v,
            None if self.taken >= self.total && self.emitted < self.total => 0,
            None => return out,
        };
        self.shift = [
            sample,
            self.shift[0],
            self.shift[1],
            self.shift[2],
            self.shift[3],
        ];
        self.taken += 1;
        if self.taken >= 3 && self.emitted < self.total {
            // Centre sample sits at shift[2]; tap k reads column clamp(xc + k).
            let xc = self.centre.x as i32;
            let last = self.width as i32 - 1;
            let mut win = [0u16; 5];
            for (k, w) in win.iter_mut().enumerate() {
                let col = clamp_index(xc + k as i32 - 2, last);
                // `col` is within xc-2..=xc+2, so the index is 0..=4; `min` only rules out
                // a panic path.
                *w = self.shift[((2 - (col - xc)) as usize).min(4)];
            }
            self.out = Some(da_row(&self.lut, win));
            self.centre.advance(self.width);
            self.emitted += 1;
        }
        out
    }
}

/// Vertical 5-tap stage with four line buffers (circular memories) of row-stage output.
#[derive(Clone, Debug)]
pub struct ColumnConvolver<const W: usize> {
    lut: [u16; 32],
    width: u16,
    height: u16,
    total: u32,
    lines: LineBuffer<u32, W, 4>,
    pos: Raster,
    taken: u32,
    emitted: u32,
    out: Option<u16>,
}

impl<const W: usize> ColumnConvolver<W> {
    /// A stage with DA table `lut`, idle until [`Self::start`].
    pub const fn new(lut: [u16; 32]) -> Self {
        Self {
            lut,
            width: 0,
            height: 0,
            total: 0,
            lines: LineBuffer::new(0),
            pos: Raster { x: 0, y: 0 },
            taken: 0,
            emitted: 0,
            out: None,
        }
    }

    /// Resets the counters for a `width` x `height` frame (`width <= W`).
    pub fn start(&mut self, width: u16, height: u16) {
        self.width = width;
        self.height = height;
        self.total = width as u32 * height as u32;
        self.lines.reset();
        self.pos = Raster::default();
        self.taken = 0;
        self.emitted = 0;
        self.out = None;
    }

    /// One enabled clock (see [`RowConvolver::clock`]): takes a row-stage output.
    pub fn clock(&mut self, input: Option<u32>) -> Option<u16> {
        let out = self.out.take();
        let sample = match input {
            Some(v) => v,
            None if self.taken >= self.total && self.emitted < self.total => 0,
            None => return out,
        };
        let x = self.pos.x as usize;
        // Read ports: rows y-1..y-4 of this column (read before write).
        let col = [
            sample,
            self.lines.read(x, 1),
            self.lines.read(x, 2),
            self.lines.read(x, 3),
            self.lines.read(x, 4),
        ];
        self.lines.write(x, sample);
        if self.pos.y >= 2 && self.emitted < self.total {
            let yc = self.pos.y as i32 - 2;
            let last = self.height as i32 - 1;
            let mut win = [0u32; 5];
            for (k, w) in win.iter_mut().enumerate() {
                let row = clamp_index(yc + k as i32 - 2, last);
                // `row` is within y-4..=y, so the index is 0..=4 (`min` as above).
                *w = col[((self.pos.y as i32 - row) as usize).min(4)];
            }
            self.out = Some(da_column(&self.lut, win));
            self.emitted += 1;
        }
        self.taken += 1;
        self.pos.advance(self.width);
        if self.pos.x == 0 {
            self.lines.next_row();
        }
        out
    }
}
