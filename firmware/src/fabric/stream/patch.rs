//! Points waiting for the Sobel rows their 16x16 patch needs.
//!
//! A point at row `y` of its octave needs Sobel rows `y-8..=y+7` (clipped to the image). The
//! fabric's point stream lags its Sobel stream by a few rows, so a point usually arrives with
//! its top rows already in the [`SobelRing`](crate::fabric::stream::sobel_ring::SobelRing) and waits
//! for the rows below it. A point whose top rows have already left the ring, or that finds
//! the queue full, gets no patch; the engine counts it in `FrameEnd.dropped_sobel`.

use heapless::Vec;
use stereocal_wire::PATCH_SIZE;

/// Points that can wait at once: the fabric's point FIFO depth, so a full FIFO drained in one
/// go never overflows the queue.
pub const MAX_PENDING: usize = 512;

/// Half the patch side: the centre pixel sits at (8, 8) of the patch.
pub const HALF: u16 = (PATCH_SIZE / 2) as u16;

/// A point waiting for its patch.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PendingPatch {
    /// Position of the point in the frame's `PointBatch` order.
    pub index: u16,
    /// Its octave.
    pub octave: u8,
    /// Its column in the octave.
    pub x: u16,
    /// Its row in the octave.
    pub y: u16,
}

impl PendingPatch {
    /// First row the patch needs (clipped at the top).
    pub fn first_row(&self) -> u16 {
        self.y.saturating_sub(HALF)
    }

    /// The patch can be cut once rows before this one are complete (clipped at the bottom).
    pub fn rows_needed_before(&self, height: u16) -> u16 {
        (self.y + HALF).min(height)
    }
}

/// A FIFO of pending patches, in point order.
pub struct PatchQueue {
    entries: Vec<PendingPatch, MAX_PENDING>,
}

impl PatchQueue {
    /// An empty queue.
    pub const fn new() -> Self {
        Self {
            entries: Vec::new(),
        }
    }

    /// Empties the queue.
    pub fn clear(&mut self) {
        self.entries.clear();
    }

    /// Queues `patch`; gives it back when the queue is full.
    pub fn push(&mut self, patch: PendingPatch) -> Result<(), PendingPatch> {
        self.entries.push(patch)
    }

    /// Removes and returns, in queue order, the first entry `ready` accepts.
    pub fn take_first(
        &mut self,
        mut ready: impl FnMut(&PendingPatch) -> bool,
    ) -> Option<PendingPatch> {
        let i = self.entries.iter().position(&mut ready)?;
        // As `Vec::remove(i)`, but without its bounds assertion, which only the optimiser can
        // prove dead (and, depending on inlining, leaves a panic path in the firmware ELF): the
        // entry is swapped along to the back, the others keeping their order, and popped.
        let mut rest = self.entries.iter_mut().skip(i);
        if let Some(mut taken) = rest.next() {
            for next in rest {
                core::mem::swap(taken, next);
                taken = next;
            }
        }
        self.entries.pop()
    }
}

impl Default for PatchQueue {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use std::vec::Vec;

    use super::*;

    #[test]
    fn patch_queue_takes_the_first_ready_entry_and_keeps_the_others_in_order() {
        let entry = |index: u16| PendingPatch {
            index,
            octave: (index % 2) as u8,
            x: index,
            y: index,
        };
        let mut queue = PatchQueue::new();
        for index in 0..6 {
            queue.push(entry(index)).unwrap();
        }
        assert_eq!(queue.take_first(|p| p.octave == 1), Some(entry(1)));
        assert_eq!(queue.take_first(|p| p.index == 5), Some(entry(5)));
        assert_eq!(queue.take_first(|p| p.index == 9), None);
        let rest: Vec<u16> = core::iter::from_fn(|| queue.take_first(|_| true))
            .map(|p| p.index)
            .collect();
        assert_eq!(rest, [0, 2, 3, 4]);
    }
}
