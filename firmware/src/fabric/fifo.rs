//! Bounded FIFO over `LINES` line memories of `W` entries (capacity `LINES·W`): the alignment
//! delays between scale images and the output FIFOs the soft-core drains. Pushing into a full
//! FIFO hands the value back; the caller counts it (nothing is dropped silently).

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
        self.mem.as_flattened_mut()[i] = v;
        self.len += 1;
        Ok(())
    }

    /// Free entries.
    pub fn free(&self) -> usize {
        Self::CAPACITY - self.len
    }

    /// Appends `n` entries `f(0), f(1), ..` (the caller checked `n <= self.free()`), writing
    /// the at most two contiguous runs of the ring directly.
    #[inline]
    pub fn extend_with(&mut self, n: usize, mut f: impl FnMut(usize) -> T) {
        debug_assert!(n <= self.free());
        let mut start = self.head + self.len;
        if start >= Self::CAPACITY {
            start -= Self::CAPACITY;
        }
        let first = n.min(Self::CAPACITY - start);
        let mem = self.mem.as_flattened_mut();
        for (i, slot) in mem[start..start + first].iter_mut().enumerate() {
            *slot = f(i);
        }
        for (i, slot) in mem[..n - first].iter_mut().enumerate() {
            *slot = f(first + i);
        }
        self.len += n;
    }

    /// Hands every entry, oldest first, to `sink` as at most two slices, and empties the FIFO.
    pub fn drain_slices(&mut self, sink: &mut dyn FnMut(&[T])) {
        let mem = self.mem.as_flattened();
        let first = self.len.min(Self::CAPACITY - self.head);
        if first > 0 {
            sink(&mem[self.head..self.head + first]);
        }
        if self.len > first {
            sink(&mem[..self.len - first]);
        }
        self.clear();
    }

    /// Removes the oldest entry.
    #[inline]
    pub fn pop(&mut self) -> Option<T> {
        if self.len == 0 {
            return None;
        }
        let v = self.mem.as_flattened()[self.head];
        self.head += 1;
        if self.head == Self::CAPACITY {
            self.head = 0;
        }
        self.len -= 1;
        Some(v)
    }
}
