//! Bounded FIFO over `LINES` line memories of `W` entries (capacity `LINES·W`): the alignment
//! delays between scale images and the point FIFO the soft-core drains (the Sobel FIFO holds
//! register words: `sobel_fifo.rs`). Pushing into a full FIFO hands the value back; the caller
//! counts it (nothing is dropped silently).
//!
//! Every access goes through `get`/`split_at_mut_checked`: the ring indices are below the
//! capacity by construction, and should one not be, a push reports the FIFO full and a pop
//! reports it empty instead of panicking.

/// Circular FIFO of capacity `LINES * W`.
#[derive(Clone, Debug)]
pub struct LineFifo<T, const W: usize, const LINES: usize> {
    mem: [[T; W]; LINES],
    head: usize,
    len: usize,
}

impl<T: Copy, const W: usize, const LINES: usize> LineFifo<T, W, LINES> {
    /// Capacity in entries.
    pub const CAPACITY: usize = W * LINES;

    /// An empty FIFO; `fill` is the power-up content of the memory, never read.
    pub const fn new(fill: T) -> Self {
        Self {
            mem: [[fill; W]; LINES],
            head: 0,
            len: 0,
        }
    }

    /// Empties the FIFO.
    pub fn clear(&mut self) {
        self.head = 0;
        self.len = 0;
    }

    /// Entries held.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether nothing is held.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Appends `v`, or returns it when the FIFO is full.
    #[inline]
    pub fn push(&mut self, v: T) -> Result<(), T> {
        if self.len == Self::CAPACITY {
            return Err(v);
        }
        let mut i = self.head + self.len;
        if i >= Self::CAPACITY {
            i -= Self::CAPACITY;
        }
        match self.mem.as_flattened_mut().get_mut(i) {
            Some(slot) => *slot = v,
            None => return Err(v),
        }
        self.len += 1;
        Ok(())
    }

    /// Hands every entry, oldest first, to `sink` as at most two slices, and empties the FIFO.
    pub fn drain_slices(&mut self, sink: &mut dyn FnMut(&[T])) {
        let mem = self.mem.as_flattened();
        let (before, after) = mem.split_at_checked(self.head).unwrap_or_default();
        let first = self.len.min(after.len());
        if let Some(run) = after.get(..first).filter(|run| !run.is_empty()) {
            sink(run);
        }
        if let Some(run) = before.get(..self.len - first).filter(|run| !run.is_empty()) {
            sink(run);
        }
        self.clear();
    }

    /// The oldest entry, left in place.
    #[inline]
    pub fn peek(&self) -> Option<&T> {
        if self.len == 0 {
            return None;
        }
        self.mem.as_flattened().get(self.head)
    }

    /// Removes the oldest entry.
    #[inline]
    pub fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        let v = *self.mem.as_flattened().get(self.head)?;
        self.head += 1;
        if self.head == Self::CAPACITY {
            self.head = 0;
        }
        self.len -= 1;
        Some(v)
    }
}
