//! Draining the fabric's two FIFOs through their registers, in bursts.
//!
//! Each drain reads the FIFO's level, then pops that many entries with
//! [`RegisterBus::read_burst`] over the entry's registers (the pop first, then its holding
//! registers): one call per burst, which an MMIO bus turns into a loop of volatile loads and
//! a software fabric serves without a call per word. Entries that arrive while draining wait
//! for the next drain; an entry read as not VALID ends the drain (the FIFO was emptied under
//! it, by a soft reset).
//!
//! Sobel pixels leave in runs of consecutive pixels of one row of one octave, the form the
//! driver's ring stores in blocks.

use stereocal_hdl::regs::{sobel_fifo_data as sdata, sobel_fifo_position as spos};
use stereocal_hdl::{RegisterBus, Registers};

use crate::fabric::fifo_words::{point_from_words, POINT_OFFSETS, SOBEL_OFFSETS};
use crate::fabric::{Extremum, SobelRun};

/// Points popped per burst.
const POINT_BURST: usize = 64;
/// Sobel pixels popped per burst.
const SOBEL_BURST: usize = 256;
/// Words a burst reads at most.
const BURST_WORDS: usize = max(
    POINT_BURST * POINT_OFFSETS.len(),
    SOBEL_BURST * SOBEL_OFFSETS.len(),
);

const fn max(a: usize, b: usize) -> usize {
    if a > b {
        a
    } else {
        b
    }
}

/// The buffers of a drain: the words of one burst and one run of Sobel pixels.
#[derive(Clone, Debug)]
pub(crate) struct FifoReader {
    words: [u32; BURST_WORDS],
    magnitude: [u8; SOBEL_BURST],
    orientation: [u8; SOBEL_BURST],
}

impl FifoReader {
    pub(crate) const fn new() -> Self {
        Self {
            words: [0; BURST_WORDS],
            magnitude: [0; SOBEL_BURST],
            orientation: [0; SOBEL_BURST],
        }
    }

    /// Pops every point the point FIFO holds now, oldest first, into `on_point`.
    pub(crate) fn drain_points<B: RegisterBus, E>(
        &mut self,
        bus: &mut B,
        on_point: &mut impl FnMut(&Extremum) -> Result<(), E>,
    ) -> Result<(), E> {
        let mut left = usize::from(bus.point_fifo_level_level());
        while left > 0 {
            let n = left.min(POINT_BURST);
            let Some(words) = self.words.get_mut(..n * POINT_OFFSETS.len()) else {
                return Ok(());
            };
            bus.read_burst(&POINT_OFFSETS, words);
            for entry in words.chunks_exact(POINT_OFFSETS.len()) {
                let Some(point) = <[u32; 3]>::try_from(entry).ok().and_then(point_from_words)
                else {
                    return Ok(());
                };
                on_point(&point)?;
            }
            left -= n;
        }
        Ok(())
    }

    /// Pops every Sobel pixel the Sobel FIFO holds now, oldest first, into `on_run` in runs.
    pub(crate) fn drain_sobel<B: RegisterBus, E>(
        &mut self,
        bus: &mut B,
        on_run: &mut impl FnMut(SobelRun<'_>) -> Result<(), E>,
    ) -> Result<(), E> {
        let mut left = usize::from(bus.sobel_fifo_level_level());
        while left > 0 {
            let n = left.min(SOBEL_BURST);
            let Some(words) = self.words.get_mut(..n * SOBEL_OFFSETS.len()) else {
                return Ok(());
            };
            bus.read_burst(&SOBEL_OFFSETS, words);
            // Pixel i goes to slot i (up to the first entry read as not VALID); a run is a
            // stretch of slots whose positions follow one another along a row of one octave.
            let end = words
                .chunks_exact(2)
                .position(|entry| entry.first().is_none_or(|&d| sdata::VALID.extract(d) == 0))
                .unwrap_or(n);
            let slots = self.magnitude.iter_mut().zip(self.orientation.iter_mut());
            for (entry, (magnitude, orientation)) in words.chunks_exact(2).take(end).zip(slots) {
                let data = entry.first().copied().unwrap_or(0);
                *magnitude = sdata::MAGNITUDE.extract(data) as u8;
                *orientation = sdata::ORIENTATION.extract(data) as u8;
            }
            let entries = words.get(..end * 2).unwrap_or_default();
            let mut start = 0;
            while let Some(first) = entries.get(start * 2..start * 2 + 2) {
                let &[data, position] = first else {
                    break;
                };
                // The run goes on while each entry is the next column of the row, in the same
                // octave: its position minus its distance from the start stays the start's (a
                // column wrapping past 0xFFFF would carry into the row, so runs stop short of
                // it).
                let octave_bits = data & sdata::OCTAVE.mask();
                let room = 0x1_0000 - spos::X.extract(position) as usize;
                let len = entries
                    .get(start * 2..)
                    .unwrap_or_default()
                    .chunks_exact(2)
                    .take(room)
                    .enumerate()
                    .position(|(k, e)| {
                        let &[d, p] = e else { return true };
                        d & sdata::OCTAVE.mask() != octave_bits
                            || p.wrapping_sub(k as u32) != position
                    })
                    .unwrap_or_else(|| (end - start).min(room));
                let run = RunStart {
                    octave: sdata::OCTAVE.extract(data) as u8,
                    position,
                    start,
                };
                // `len >= 1`: the first entry is its own run's start.
                on_run(run.of(&self.magnitude, &self.orientation, start + len.max(1)))?;
                start += len.max(1);
            }
            if end < n {
                // An entry read as not VALID: the FIFO was emptied under the drain.
                return Ok(());
            }
            left -= n;
        }
        Ok(())
    }
}

/// A run being gathered: its first pixel's octave, position word and slot.
#[derive(Clone, Copy)]
struct RunStart {
    octave: u8,
    position: u32,
    start: usize,
}

impl RunStart {
    /// The run of slots `start..end` of `magnitude` and `orientation`.
    fn of<'a>(&self, magnitude: &'a [u8], orientation: &'a [u8], end: usize) -> SobelRun<'a> {
        SobelRun {
            octave: self.octave,
            y: spos::Y.extract(self.position) as u16,
            x: spos::X.extract(self.position) as u16,
            magnitude: magnitude.get(self.start..end).unwrap_or_default(),
            orientation: orientation.get(self.start..end).unwrap_or_default(),
        }
    }
}
