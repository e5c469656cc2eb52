//! The Sobel FIFO, held as the register words its pixels are read as: per pixel the
//! SOBEL_FIFO_DATA word and the SOBEL_FIFO_POSITION word ([`crate::fabric::fifo_words`]).
//!
//! The device reads the FIFO in bursts over those two registers, so a burst is a copy out of
//! the ring ([`SobelFifo::drain_words`]), and a pixel costs its words once, on the way in.
//! Two words are no more than a pixel's bytes with a share of a run record cost, and unlike
//! runs they cost nothing extra when the octaves interleave clock by clock and every run is
//! a pixel or two long. [`SobelFifo::pop`] takes one pixel (the `SOBEL_FIFO_DATA` register)
//! and [`SobelFifo::drain`] gathers pixels back into row runs for programs that take the
//! stream without the registers.
//!
//! Every access is checked (`get`, iterators), so the firmware links no panicking path
//! through here (tests/tests/firmware_panic_free.rs).

use crate::fabric::config::MAX_OCTAVES;
use stereocal_hdl::regs::{sobel_fifo_data as sdata, sobel_fifo_position as spos};

use crate::fabric::fifo_words::{sobel_from_words, SobelRowWords};
use crate::fabric::output::SobelEntry;

/// Consecutive pixels `x, x + 1, ..` of row `y` of `octave`, oldest first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SobelRun<'a> {
    /// Octave 0..4.
    pub octave: u8,
    /// Row in the octave grid.
    pub y: u16,
    /// Column of the first pixel in the octave grid.
    pub x: u16,
    /// Magnitude codes, one per pixel.
    pub magnitude: &'a [u8],
    /// Orientation bins, one per pixel (as many as `magnitude`).
    pub orientation: &'a [u8],
}

impl<'a> SobelRun<'a> {
    /// The run of the one pixel `p`.
    #[inline]
    pub fn single(p: &'a SobelEntry) -> Self {
        Self {
            octave: p.octave,
            y: p.y,
            x: p.x,
            magnitude: core::slice::from_ref(&p.magnitude),
            orientation: core::slice::from_ref(&p.orientation),
        }
    }

    /// Pixels in the run.
    #[inline]
    pub fn len(&self) -> usize {
        self.magnitude.len().min(self.orientation.len())
    }

    /// Whether the run has no pixel.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The first `n` pixels (all of them if fewer) and the rest.
    #[inline]
    pub fn split_at(&self, n: usize) -> (Self, Self) {
        let n = n.min(self.len());
        let (m0, m1) = self.magnitude.split_at_checked(n).unwrap_or_default();
        let (o0, o1) = self.orientation.split_at_checked(n).unwrap_or_default();
        let head = Self {
            magnitude: m0,
            orientation: o0,
            ..*self
        };
        let tail = Self {
            x: self.x.wrapping_add(n as u16),
            magnitude: m1,
            orientation: o1,
            ..*self
        };
        (head, tail)
    }

    /// The pixels, oldest first.
    #[inline]
    pub fn pixels(&self) -> impl Iterator<Item = SobelEntry> + 'a {
        let (octave, y, x) = (self.octave, self.y, self.x);
        self.magnitude.iter().zip(self.orientation).enumerate().map(
            move |(i, (&magnitude, &orientation))| SobelEntry {
                octave,
                orientation,
                magnitude,
                x: x.wrapping_add(i as u16),
                y,
            },
        )
    }
}

/// A FIFO of `W * LINES` Sobel pixels, each stored as its two register words.
#[derive(Clone, Debug)]
pub struct SobelFifo<const W: usize, const LINES: usize> {
    /// A ring of pixels: SOBEL_FIFO_DATA's word, then SOBEL_FIFO_POSITION's.
    words: [[[u32; 2]; W]; LINES],
    /// Ring index of the oldest pixel.
    head: usize,
    /// Pixels queued.
    len: usize,
}

/// Pixels [`SobelFifo::drain`] decodes into one run at most.
const DRAIN_RUN: usize = 256;

impl<const W: usize, const LINES: usize> SobelFifo<W, LINES> {
    /// Pixels the FIFO holds.
    pub const CAPACITY: usize = W * LINES;

    /// An empty FIFO.
    pub const fn new() -> Self {
        Self {
            words: [[[0; 2]; W]; LINES],
            head: 0,
            len: 0,
        }
    }

    /// Empties the FIFO.
    pub fn clear(&mut self) {
        self.head = 0;
        self.len = 0;
    }

    /// Pixels queued.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no pixel is queued.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// `i` taken back into the ring (`i < 2 * CAPACITY`).
    fn wrap(i: usize) -> usize {
        if i >= Self::CAPACITY {
            i - Self::CAPACITY
        } else {
            i
        }
    }

    /// Enqueues one pixel; when full, hands it back.
    pub fn push(&mut self, p: SobelEntry) -> Result<(), SobelEntry> {
        if self.push_run(SobelRun::single(&p)) == 1 {
            Ok(())
        } else {
            Err(p)
        }
    }

    /// Enqueues the leading pixels of `run`, as many as fit, as their words; returns how
    /// many did.
    pub fn push_run(&mut self, run: SobelRun<'_>) -> usize {
        let mut dropped = 0;
        let mut append = self.append(&mut dropped);
        append.push_run(run)
    }

    /// Something that enqueues pixels until it is dropped, counting what does not fit into
    /// `dropped` (saturating): one pass over the FIFO's state for many short runs.
    #[inline]
    pub fn append<'a>(&'a mut self, dropped: &'a mut u32) -> SobelAppend<'a> {
        let at = Self::wrap(self.head + self.len);
        SobelAppend {
            ring: self.words.as_flattened_mut(),
            at,
            free: Self::CAPACITY - self.len,
            pushed: 0,
            len: &mut self.len,
            lost: 0,
            dropped,
        }
    }

    /// Takes the oldest pixel.
    pub fn pop(&mut self) -> Option<SobelEntry> {
        if self.len == 0 {
            return None;
        }
        let words = *self.words.as_flattened().get(self.head)?;
        self.head = Self::wrap(self.head + 1);
        self.len -= 1;
        sobel_from_words(words)
    }

    /// Copies the words of the oldest `max` queued pixels (all of them, and no more than
    /// `words` holds, if fewer) to the front of `words` and removes them; returns how many
    /// pixels it copied.
    pub fn drain_words(&mut self, max: usize, words: &mut [u32]) -> usize {
        let n = max.min(self.len).min(words.len() / 2);
        let (first, second) = self.queued();
        let tail = first.get(..n.min(first.len())).unwrap_or_default();
        let start = second.get(..n - tail.len()).unwrap_or_default();
        let (tail, start) = (tail.as_flattened(), start.as_flattened());
        let Some((to_tail, rest)) = words.split_at_mut_checked(tail.len()) else {
            return 0;
        };
        let Some(to_start) = rest.get_mut(..start.len()) else {
            return 0;
        };
        to_tail.copy_from_slice(tail);
        to_start.copy_from_slice(start);
        self.head = Self::wrap(self.head + n);
        self.len -= n;
        n
    }

    /// Hands the oldest `max` queued pixels (all of them, if fewer) to `sink` in runs, oldest
    /// first, and removes them.
    pub fn drain(&mut self, max: usize, sink: &mut dyn FnMut(SobelRun<'_>)) {
        let n = max.min(self.len);
        let (first, second) = self.queued();
        let first = first.get(..n).unwrap_or(first);
        let second = second
            .get(..n.saturating_sub(first.len()))
            .unwrap_or_default();
        let mut runs = Runs::new();
        for words in [first, second] {
            runs.gather(words, None, |_| {}, sink);
        }
        runs.flush(sink);
        self.head = Self::wrap(self.head + n);
        self.len -= n;
    }

    /// The queued pixels' words, oldest first: up to the end of the ring, then from its
    /// start.
    fn queued(&self) -> (&[[u32; 2]], &[[u32; 2]]) {
        let ring = self.words.as_flattened();
        let (after, before) = ring
            .split_at_checked(self.head)
            .map_or((ring, &[][..]), |(b, a)| (a, b));
        let first = after.get(..self.len.min(after.len())).unwrap_or_default();
        let second = before.get(..self.len - first.len()).unwrap_or_default();
        (first, second)
    }

    /// Hands every queued pixel to `sink` in runs, octave 0's first, then octave 1's, 2's
    /// and 3's, each octave's pixels in FIFO order, and empties the FIFO: the order in which
    /// the stream engine stores a line time's pixels (one row ring per octave, so only the
    /// order within an octave matters to it), and long runs where the FIFO interleaves the
    /// octaves clock by clock. `stash` is the caller's room for setting the deeper octaves'
    /// pixels aside: with room for every queued pixel, one pass over the FIFO and one per
    /// deeper octave over what was set aside; with less, a pass over the FIFO per octave.
    pub fn drain_by_octave(&mut self, stash: &mut [[u32; 2]], sink: &mut dyn FnMut(SobelRun<'_>)) {
        let (first, second) = self.queued();
        if stash.len() < self.len {
            // No room to set pixels aside: a pass over the FIFO per octave.
            for octave in 0..MAX_OCTAVES as u32 {
                runs_of(octave, [first, second], sink);
            }
        } else {
            // Octave 0's pixels (most of them) go out on the one pass over the FIFO; the
            // deeper octaves' are set aside, in order, for a pass each over what was set
            // aside.
            let mut stashed = 0;
            let mut runs = Runs::new();
            for words in [first, second] {
                let set_aside = |w| {
                    if let Some(slot) = stash.get_mut(stashed) {
                        *slot = w;
                        stashed += 1;
                    }
                };
                runs.gather(words, Some(0), set_aside, sink);
            }
            runs.flush(sink);
            let stash = stash.get(..stashed).unwrap_or_default();
            for octave in 1..MAX_OCTAVES as u32 {
                runs_of(octave, [stash, &[]], sink);
            }
        }
        self.clear();
    }
}

/// Enqueues pixels into a [`SobelFifo`] ([`SobelFifo::append`]); the FIFO takes them, and
/// the drop counter what did not fit, when this is dropped.
pub struct SobelAppend<'a> {
    /// The FIFO's pixels, two words each.
    ring: &'a mut [[u32; 2]],
    /// Ring index of the next free pixel.
    at: usize,
    /// Free pixels.
    free: usize,
    /// Pixels enqueued, and pixels that did not fit.
    pushed: usize,
    lost: usize,
    len: &'a mut usize,
    dropped: &'a mut u32,
}

impl SobelAppend<'_> {
    /// Enqueues one pixel's words, or counts it when the FIFO is full.
    #[inline(always)]
    pub fn push(&mut self, words: [u32; 2]) {
        if let Some(slot) = self.space().first_mut() {
            *slot = words;
            self.commit(1);
        } else {
            self.lost += 1;
        }
    }

    /// The free pixels from the next one on, up to the end of the ring: fill the front of
    /// them and [`SobelAppend::commit`] as many. Empty only when the FIFO is full.
    #[inline(always)]
    pub fn space(&mut self) -> &mut [[u32; 2]] {
        let end = self.ring.len().min(self.at + self.free);
        self.ring.get_mut(self.at..end).unwrap_or_default()
    }

    /// The first `n` pixels of [`SobelAppend::space`] are filled: enqueues them.
    #[inline(always)]
    pub fn commit(&mut self, n: usize) {
        let n = n.min(self.free);
        self.at += n;
        if self.at >= self.ring.len() {
            self.at -= self.ring.len();
        }
        self.free -= n;
        self.pushed += n;
    }

    /// Enqueues the leading pixels of `run`, as many as fit; returns how many did.
    #[inline(always)]
    pub fn push_run(&mut self, run: SobelRun<'_>) -> usize {
        let row = SobelRowWords::new(run.octave, run.y);
        let fit = run.len().min(self.free);
        let (mut part, _) = run.split_at(fit);
        // Up to the end of the ring, then from its start.
        while !part.is_empty() {
            let space = self.space();
            let pixels = part.magnitude.iter().zip(part.orientation);
            let mut written = 0;
            for (slot, (&m, &o)) in space.iter_mut().zip(pixels) {
                *slot = row.pixel(part.x.wrapping_add(written as u16), m, o);
                written += 1;
            }
            if written == 0 {
                break;
            }
            self.commit(written);
            part = part.split_at(written).1;
        }
        self.lost += run.len() - fit + part.len();
        fit - part.len()
    }
}

impl Drop for SobelAppend<'_> {
    fn drop(&mut self) {
        *self.len += self.pushed;
        let lost = u32::try_from(self.lost).unwrap_or(u32::MAX);
        *self.dropped = self.dropped.saturating_add(lost);
    }
}

/// Hands `octave`'s pixels among `words` (two slices, in order) to `sink` in runs.
fn runs_of(octave: u32, words: [&[[u32; 2]]; 2], sink: &mut dyn FnMut(SobelRun<'_>)) {
    let mut runs = Runs::new();
    for words in words {
        runs.gather(words, Some(octave), |_| {}, sink);
    }
    runs.flush(sink);
}

/// Row runs gathered from pixels' register words.
struct Runs {
    magnitude: [u8; DRAIN_RUN],
    orientation: [u8; DRAIN_RUN],
    /// The run's data word (its octave) and its first position word.
    data: u32,
    start: u32,
    /// Pixels in the run.
    n: usize,
    /// The most pixels the run may hold: [`DRAIN_RUN`], or fewer where its row ends in the
    /// position word's `x` field (whose next value would carry into `y`); 0 while empty.
    room: usize,
}

impl Runs {
    fn new() -> Self {
        Self {
            magnitude: [0; DRAIN_RUN],
            orientation: [0; DRAIN_RUN],
            data: 0,
            start: 0,
            n: 0,
            room: 0,
        }
    }

    /// Adds the pixels of `words` (of `octave` only, when given; the others go to `other`),
    /// handing the run to `sink` whenever a pixel does not continue it (another octave or
    /// row, a gap, a full buffer). The position word is `y` above `x`, so the next column of
    /// the row is the next word, unless `x` would wrap: `room` stops the run there. An empty
    /// run has no room, so its first pixel starts one. The run's state stays in locals over
    /// the loop: this is the in-process device's per-pixel path.
    #[inline]
    fn gather(
        &mut self,
        words: &[[u32; 2]],
        octave: Option<u32>,
        mut other: impl FnMut([u32; 2]),
        sink: &mut dyn FnMut(SobelRun<'_>),
    ) {
        let (mut n, mut room) = (self.n, self.room);
        let mut next = self.start.wrapping_add(n as u32);
        let mut run_octave = sdata::OCTAVE.extract(self.data);
        for &[data, position] in words {
            let pixel_octave = sdata::OCTAVE.extract(data);
            if octave.is_some_and(|o| o != pixel_octave) {
                other([data, position]);
                continue;
            }
            if n >= room || position != next || pixel_octave != run_octave {
                self.n = n;
                self.flush(sink);
                (self.data, self.start) = (data, position);
                (n, next, run_octave) = (0, position, pixel_octave);
                let to_row_end = spos::X
                    .bits
                    .max_value()
                    .saturating_sub(spos::X.extract(position));
                room = DRAIN_RUN.min(to_row_end as usize + 1);
            }
            if let (Some(m), Some(o)) = (self.magnitude.get_mut(n), self.orientation.get_mut(n)) {
                *m = sdata::MAGNITUDE.extract(data) as u8;
                *o = sdata::ORIENTATION.extract(data) as u8;
            }
            n += 1;
            next = next.wrapping_add(1);
        }
        (self.n, self.room) = (n, room);
    }

    /// Hands the run gathered so far to `sink`, and empties it.
    fn flush(&mut self, sink: &mut dyn FnMut(SobelRun<'_>)) {
        if self.n == 0 {
            return;
        }
        sink(SobelRun {
            octave: sdata::OCTAVE.extract(self.data) as u8,
            y: spos::Y.extract(self.start) as u16,
            x: spos::X.extract(self.start) as u16,
            magnitude: self.magnitude.get(..self.n).unwrap_or_default(),
            orientation: self.orientation.get(..self.n).unwrap_or_default(),
        });
        self.n = 0;
        self.room = 0;
    }
}

impl<const W: usize, const LINES: usize> Default for SobelFifo<W, LINES> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;
    use crate::fabric::fifo::LineFifo;
    use proptest::prelude::*;
    use std::vec::Vec;

    /// What one step does to the FIFO.
    #[derive(Clone, Debug)]
    enum Step {
        /// One pixel.
        Push(SobelEntry),
        /// Pixels `x..x + len` of a row, their values drawn from `seed`.
        Run {
            octave: u8,
            y: u16,
            x: u16,
            len: usize,
            seed: u8,
        },
        Pop,
        Drain,
        /// Every pixel, octave by octave, with this much room to set pixels aside.
        DrainByOctave(usize),
        /// At most this many pixels as words.
        DrainWords(usize),
    }

    fn pixel() -> impl Strategy<Value = SobelEntry> {
        (0u8..4, any::<u8>(), 0u8..64, 0u16..40, 0u16..4).prop_map(
            |(octave, magnitude, orientation, x, y)| SobelEntry {
                octave,
                orientation,
                magnitude,
                x,
                y,
            },
        )
    }

    fn step() -> impl Strategy<Value = Step> {
        prop_oneof![
            4 => pixel().prop_map(Step::Push),
            2 => (0u8..4, 0u16..4, 0u16..40, 0usize..40, any::<u8>())
                .prop_map(|(octave, y, x, len, seed)| Step::Run { octave, y, x, len, seed }),
            2 => Just(Step::Pop),
            1 => Just(Step::Drain),
            1 => (0usize..=48).prop_map(Step::DrainByOctave),
            1 => (0usize..60).prop_map(Step::DrainWords),
        ]
    }

    proptest! {
        /// Pushes, runs, pops and drains (as runs, octave by octave or as words) give the
        /// pixels, drops and
        /// lengths of a plain FIFO of pixel records with the same capacity, whatever the
        /// wrapping; every run is consecutive pixels of one row and none is empty.
        #[test]
        fn runs_hold_the_pixel_stream(steps in prop::collection::vec(step(), 0..200)) {
            let mut runs: SobelFifo<16, 3> = SobelFifo::new();
            let mut records: LineFifo<SobelEntry, 16, 3> = LineFifo::new(SobelEntry::default());
            for step in steps {
                match step {
                    Step::Push(p) => {
                        prop_assert_eq!(runs.push(p).is_ok(), records.push(p).is_ok());
                    }
                    Step::Run { octave, y, x, len, seed } => {
                        let magnitude: Vec<u8> =
                            (0..len).map(|i| seed.wrapping_add(i as u8)).collect();
                        let orientation: Vec<u8> = magnitude.iter().map(|m| m % 64).collect();
                        let run = SobelRun {
                            octave,
                            y,
                            x,
                            magnitude: &magnitude,
                            orientation: &orientation,
                        };
                        let written = runs.push_run(run);
                        let fit = run.pixels().map(|p| records.push(p)).take_while(Result::is_ok).count();
                        prop_assert_eq!(written, fit);
                    }
                    Step::Pop => prop_assert_eq!(runs.pop(), records.pop()),
                    Step::Drain => {
                        let mut from_runs = Vec::new();
                        runs.drain(usize::MAX, &mut |run| {
                            assert!(!run.is_empty());
                            from_runs.extend(run.pixels());
                        });
                        let mut from_records = Vec::new();
                        records.drain_slices(&mut |s| from_records.extend_from_slice(s));
                        prop_assert_eq!(from_runs, from_records);
                    }
                    Step::DrainByOctave(room) => {
                        let mut from_runs = Vec::new();
                        let mut stash = [[0; 2]; 48];
                        let stash = &mut stash[..room];
                        runs.drain_by_octave(stash, &mut |run| {
                            assert!(!run.is_empty());
                            from_runs.extend(run.pixels());
                        });
                        let mut from_records = Vec::new();
                        records.drain_slices(&mut |s| from_records.extend_from_slice(s));
                        // A stable sort: each octave's pixels keep their FIFO order.
                        from_records.sort_by_key(|p| p.octave);
                        prop_assert_eq!(from_runs, from_records);
                    }
                    Step::DrainWords(max) => {
                        let mut words = [0; 100];
                        let n = runs.drain_words(max, &mut words);
                        let from_words: Vec<SobelEntry> = words
                            .chunks_exact(2)
                            .take(n)
                            .filter_map(|w| sobel_from_words([w[0], w[1]]))
                            .collect();
                        let from_records: Vec<SobelEntry> =
                            core::iter::from_fn(|| records.pop()).take(max.min(50)).collect();
                        prop_assert_eq!(from_words, from_records);
                    }
                }
                prop_assert_eq!(runs.len(), records.len());
            }
        }

        /// Splitting a run anywhere keeps its pixels, in order.
        #[test]
        fn split_runs_keep_their_pixels(p in pixel(), len in 0usize..20, at in 0usize..25) {
            let magnitude: Vec<u8> = (0..len as u8).collect();
            let orientation: Vec<u8> = (0..len as u8).map(|i| i % 64).collect();
            let run = SobelRun { magnitude: &magnitude, orientation: &orientation, ..SobelRun::single(&p) };
            let (head, tail) = run.split_at(at);
            let pixels: Vec<SobelEntry> = head.pixels().chain(tail.pixels()).collect();
            prop_assert_eq!(pixels, run.pixels().collect::<Vec<_>>());
            prop_assert_eq!(head.len(), at.min(len));
        }
    }
}
