//! Line buffer: `N` rows of `W` samples as a circular memory (one block RAM per row in the
//! fabric, all addressed by the column counter). The row written `d` rows ago sits in slot
//! `(current - d) mod N`; reads happen before the write of the same clock (read-first RAM), so
//! `N` slots give delays 1..=N.
//!
//! Indexing cannot panic: the slot is taken `mod N` and the column is saturated at `W - 1`
//! (the stages only pass columns below their configured width, which is at most `W`, so the
//! saturation never changes a result; it only rules the panic path out).

/// `N` line memories of `W` samples.
#[derive(Clone, Debug)]
pub struct LineBuffer<T, const W: usize, const N: usize> {
    mem: [[T; W]; N],
    current: usize,
}

impl<T: Copy, const W: usize, const N: usize> LineBuffer<T, W, N> {
    /// Memories filled with `fill` (the power-up content is never read: borders are clamped).
    pub const fn new(fill: T) -> Self {
        Self {
            mem: [[fill; W]; N],
            current: 0,
        }
    }

    /// Back to slot 0 for a new frame.
    pub fn reset(&mut self) {
        self.current = 0;
    }

    /// Sample of column `x` written `delay` (1..=N) rows ago.
    #[inline]
    pub fn read(&self, x: usize, delay: usize) -> T {
        self.mem[(self.current + N - delay) % N][x.min(W - 1)]
    }

    /// Writes column `x` of the current row.
    #[inline]
    pub fn write(&mut self, x: usize, v: T) {
        self.mem[self.current % N][x.min(W - 1)] = v;
    }

    /// The current row is complete.
    #[inline]
    pub fn next_row(&mut self) {
        self.current = (self.current + 1) % N;
    }
}
