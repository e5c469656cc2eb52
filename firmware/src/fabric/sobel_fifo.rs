//! The Sobel FIFO, held as row runs: magnitudes and orientations in two byte rings, and for
//! each run of consecutive pixels of one row its octave, row, first column and length.
//!
//! Both front ends emit the Sobel stream along rows (the fast path a whole row per call, the
//! register-level model one pixel per clock), and the driver stores it by rows. As runs, a
//! row goes in as two copies and leaves as two slices, where a queue of pixel records cost an
//! 8-byte record per pixel on the way in and, on the way out, a check per pixel that it
//! continues the row before it. The pixel stream is unchanged: the same order, the same
//! capacity in pixels, the same pixels dropped when full, and [`SobelFifo::pop`] still takes
//! one pixel at a time (the `SOBEL_FIFO_DATA` register).
//!
//! Every access is checked (`get`, iterators), so the firmware links no panicking path
//! through here (tests/tests/firmware_panic_free.rs).

use crate::fabric::output::SobelPixel;

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
    pub fn single(p: &'a SobelPixel) -> Self {
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
    pub fn pixels(&self) -> impl Iterator<Item = SobelPixel> + 'a {
        let (octave, y, x) = (self.octave, self.y, self.x);
        self.magnitude.iter().zip(self.orientation).enumerate().map(
            move |(i, (&magnitude, &orientation))| SobelPixel {
                octave,
                orientation,
                magnitude,
                x: x.wrapping_add(i as u16),
                y,
            },
        )
    }
}

/// A queued run: its pixels follow the previous run's in the rings.
#[derive(Clone, Copy, Debug)]
struct Run {
    octave: u8,
    y: u16,
    x: u16,
    len: u16,
}

impl Run {
    const EMPTY: Self = Self {
        octave: 0,
        y: 0,
        x: 0,
        len: 0,
    };
}

/// A FIFO of `W * LINES` Sobel pixels, stored as runs.
#[derive(Clone, Debug)]
pub struct SobelFifo<const W: usize, const LINES: usize> {
    magnitude: [[u8; W]; LINES],
    orientation: [[u8; W]; LINES],
    /// A ring of run headers; no run is empty, so there are never more than pixels.
    runs: [[Run; W]; LINES],
    /// Ring index of the oldest pixel.
    head: usize,
    /// Pixels queued.
    len: usize,
    /// Ring index of the oldest run.
    run_head: usize,
    /// Runs queued.
    run_count: usize,
}

impl<const W: usize, const LINES: usize> SobelFifo<W, LINES> {
    /// Pixels the FIFO holds.
    pub const CAPACITY: usize = W * LINES;

    /// An empty FIFO.
    pub const fn new() -> Self {
        Self {
            magnitude: [[0; W]; LINES],
            orientation: [[0; W]; LINES],
            runs: [[Run::EMPTY; W]; LINES],
            head: 0,
            len: 0,
            run_head: 0,
            run_count: 0,
        }
    }

    /// Empties the FIFO.
    pub fn clear(&mut self) {
        self.head = 0;
        self.len = 0;
        self.run_head = 0;
        self.run_count = 0;
    }

    /// Pixels queued.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no pixel is queued.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// `i` taken back into the rings (`i < 2 * CAPACITY`).
    fn wrap(i: usize) -> usize {
        if i >= Self::CAPACITY {
            i - Self::CAPACITY
        } else {
            i
        }
    }

    /// Enqueues one pixel; when full, hands it back.
    pub fn push(&mut self, p: SobelPixel) -> Result<(), SobelPixel> {
        if self.push_run(SobelRun::single(&p)) == 1 {
            Ok(())
        } else {
            Err(p)
        }
    }

    /// Enqueues the leading pixels of `run`, as many as fit; returns how many did.
    #[inline]
    pub fn push_run(&mut self, run: SobelRun<'_>) -> usize {
        let fit = run.len().min(Self::CAPACITY - self.len);
        let at = Self::wrap(self.head + self.len);
        // The common case, all of it before the end of the rings, byte by byte: runs of one
        // or two pixels are common (octaves interleave clock by clock), too short for a copy
        // call.
        if fit == 0 {
            return 0;
        }
        if fit == run.len() && at + fit <= Self::CAPACITY {
            let rings = (
                self.magnitude.as_flattened_mut().get_mut(at..at + fit),
                self.orientation.as_flattened_mut().get_mut(at..at + fit),
            );
            if let (Some(magnitude), Some(orientation)) = rings {
                for (d, &v) in magnitude.iter_mut().zip(run.magnitude) {
                    *d = v;
                }
                for (d, &v) in orientation.iter_mut().zip(run.orientation) {
                    *d = v;
                }
                self.len += fit;
                self.append(run.octave, run.y, run.x, fit as u16, at);
                return fit;
            }
        }
        // Up to the end of the rings, then from their start.
        let (first, second) = run.split_at(fit).0.split_at(Self::CAPACITY - at);
        let mut written = 0;
        for (at, part) in [(at, first), (0, second)] {
            if part.is_empty() {
                continue;
            }
            let rings = (
                self.magnitude
                    .as_flattened_mut()
                    .get_mut(at..at + part.magnitude.len()),
                self.orientation
                    .as_flattened_mut()
                    .get_mut(at..at + part.orientation.len()),
            );
            let (Some(magnitude), Some(orientation)) = rings else {
                break;
            };
            magnitude.copy_from_slice(part.magnitude);
            orientation.copy_from_slice(part.orientation);
            self.len += part.len();
            self.append(part.octave, part.y, part.x, part.len() as u16, at);
            written += part.len();
        }
        written
    }

    /// Records `len` pixels just stored at ring index `at` as pixels `x..` of row `y`: they
    /// extend the newest run when they continue its row and follow it in the rings (not
    /// across their end), else they start a run.
    #[inline]
    fn append(&mut self, octave: u8, y: u16, x: u16, len: u16, at: usize) {
        if at != 0 && self.run_count > 0 {
            let newest = Self::wrap(self.run_head + self.run_count - 1);
            if let Some(run) = self.runs.as_flattened_mut().get_mut(newest) {
                if run.octave == octave && run.y == y && run.x.wrapping_add(run.len) == x {
                    if let Some(longer) = run.len.checked_add(len) {
                        run.len = longer;
                        return;
                    }
                }
            }
        }
        let slot = Self::wrap(self.run_head + self.run_count);
        if let Some(run) = self.runs.as_flattened_mut().get_mut(slot) {
            *run = Run { octave, y, x, len };
            self.run_count += 1;
        }
    }

    /// Takes the oldest pixel.
    pub fn pop(&mut self) -> Option<SobelPixel> {
        if self.len == 0 {
            return None;
        }
        let run = self.runs.as_flattened_mut().get_mut(self.run_head)?;
        let pixel = SobelPixel {
            octave: run.octave,
            orientation: *self.orientation.as_flattened().get(self.head)?,
            magnitude: *self.magnitude.as_flattened().get(self.head)?,
            x: run.x,
            y: run.y,
        };
        run.x = run.x.wrapping_add(1);
        run.len = run.len.saturating_sub(1);
        if run.len == 0 {
            self.run_head = Self::wrap(self.run_head + 1);
            self.run_count -= 1;
        }
        self.head = Self::wrap(self.head + 1);
        self.len -= 1;
        Some(pixel)
    }

    /// Hands the oldest `max` queued pixels (all of them, if fewer) to `sink` in runs, oldest
    /// first, and removes them.
    pub fn drain(&mut self, max: usize, sink: &mut dyn FnMut(SobelRun<'_>)) {
        let mut left = max.min(self.len);
        while left > 0 && self.run_count > 0 {
            // Runs never straddle the end of the ring (`push_run` splits them there).
            let Some(run) = self.runs.as_flattened_mut().get_mut(self.run_head) else {
                break;
            };
            let n = usize::from(run.len).min(left);
            let at = self.head;
            let (Some(magnitude), Some(orientation)) = (
                self.magnitude.as_flattened().get(at..at + n),
                self.orientation.as_flattened().get(at..at + n),
            ) else {
                break;
            };
            sink(SobelRun {
                octave: run.octave,
                y: run.y,
                x: run.x,
                magnitude,
                orientation,
            });
            // `n <= run.len`, a u16.
            run.x = run.x.wrapping_add(n as u16);
            run.len -= n as u16;
            if run.len == 0 {
                self.run_head = Self::wrap(self.run_head + 1);
                self.run_count -= 1;
            }
            self.head = Self::wrap(self.head + n);
            self.len -= n;
            left -= n;
        }
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
        Push(SobelPixel),
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
    }

    fn pixel() -> impl Strategy<Value = SobelPixel> {
        (0u8..4, any::<u8>(), 0u8..64, 0u16..40, 0u16..4).prop_map(
            |(octave, magnitude, orientation, x, y)| SobelPixel {
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
        ]
    }

    proptest! {
        /// Pushes, runs, pops and drains give the pixels, drops and lengths of a plain FIFO
        /// of pixel records with the same capacity, whatever the wrapping; every run is
        /// consecutive pixels of one row and none is empty.
        #[test]
        fn runs_hold_the_pixel_stream(steps in prop::collection::vec(step(), 0..200)) {
            let mut runs: SobelFifo<16, 3> = SobelFifo::new();
            let mut records: LineFifo<SobelPixel, 16, 3> = LineFifo::new(SobelPixel::default());
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
            let pixels: Vec<SobelPixel> = head.pixels().chain(tail.pixels()).collect();
            prop_assert_eq!(pixels, run.pixels().collect::<Vec<_>>());
            prop_assert_eq!(head.len(), at.min(len));
        }
    }
}
