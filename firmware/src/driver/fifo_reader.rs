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
//! driver's ring stores in blocks. The FIFO interleaves the octaves clock by clock (octave 0
//! pushes a pixel every clock, octave 1 every other clock of every other line, ...), so a
//! burst is sorted by octave first: each octave's pixels keep their order, and each octave's
//! runs leave together, octave 0 first. How the runs of different octaves interleave is no
//! concern of the ring, which keeps a row per octave.

use stereocal_hdl::regs::{sobel_fifo_data as sdata, sobel_fifo_position as spos};
use stereocal_hdl::{RegisterBus, Registers};

use crate::fabric::config::MAX_OCTAVES;
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

/// The buffers of a drain: the words of one burst, and per octave the burst's Sobel pixels
/// and the runs they make.
#[derive(Clone, Debug)]
pub(crate) struct FifoReader {
    words: [u32; BURST_WORDS],
    magnitude: [[u8; SOBEL_BURST]; MAX_OCTAVES],
    orientation: [[u8; SOBEL_BURST]; MAX_OCTAVES],
    /// Per octave, each run's first position word and first slot.
    runs: [[(u32, u16); SOBEL_BURST]; MAX_OCTAVES],
}

impl FifoReader {
    pub(crate) const fn new() -> Self {
        Self {
            words: [0; BURST_WORDS],
            magnitude: [[0; SOBEL_BURST]; MAX_OCTAVES],
            orientation: [[0; SOBEL_BURST]; MAX_OCTAVES],
            runs: [[(0, 0); SOBEL_BURST]; MAX_OCTAVES],
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
            // Pixel by pixel up to the first entry read as not VALID: each goes to the next
            // slot of its octave, and starts a run unless it is the next column of the row
            // its octave's previous pixel is on (a column wrapping past 0xFFFF would carry into
            // the row, so runs stop short of it).
            let mut filled = [0u16; MAX_OCTAVES];
            let mut count = [0usize; MAX_OCTAVES];
            let mut next = [u64::MAX; MAX_OCTAVES];
            let mut valid = 0;
            for entry in words.chunks_exact(2) {
                let &[data, position] = entry else { break };
                if sdata::VALID.extract(data) == 0 {
                    break;
                }
                valid += 1;
                let o = sdata::OCTAVE.extract(data) as usize % MAX_OCTAVES;
                let (Some(slot), Some(runs), Some(count), Some(next)) = (
                    filled.get_mut(o),
                    self.runs.get_mut(o),
                    count.get_mut(o),
                    next.get_mut(o),
                ) else {
                    break;
                };
                if u64::from(position) != *next {
                    if let Some(run) = runs.get_mut(*count) {
                        *run = (position, *slot);
                        *count += 1;
                    }
                }
                *next = if spos::X.extract(position) == spos::X.bits.max_value() {
                    u64::MAX
                } else {
                    u64::from(position) + 1
                };
                let i = usize::from(*slot);
                if let (Some(m), Some(r)) = (
                    self.magnitude.get_mut(o).and_then(|m| m.get_mut(i)),
                    self.orientation.get_mut(o).and_then(|r| r.get_mut(i)),
                ) {
                    *m = sdata::MAGNITUDE.extract(data) as u8;
                    *r = sdata::ORIENTATION.extract(data) as u8;
                }
                *slot += 1;
            }
            for (o, ((runs, &count), &filled)) in
                self.runs.iter().zip(&count).zip(&filled).enumerate()
            {
                let (Some(magnitude), Some(orientation)) =
                    (self.magnitude.get(o), self.orientation.get(o))
                else {
                    break;
                };
                let runs = runs.get(..count).unwrap_or_default();
                let ends = runs.iter().skip(1).map(|&(_, start)| start).chain([filled]);
                for (&(position, start), end) in runs.iter().zip(ends) {
                    let span = usize::from(start)..usize::from(end);
                    on_run(SobelRun {
                        octave: o as u8,
                        y: spos::Y.extract(position) as u16,
                        x: spos::X.extract(position) as u16,
                        magnitude: magnitude.get(span.clone()).unwrap_or_default(),
                        orientation: orientation.get(span).unwrap_or_default(),
                    })?;
                }
            }
            if valid < n {
                // An entry read as not VALID: the FIFO was emptied under the drain.
                return Ok(());
            }
            left -= n;
        }
        Ok(())
    }
}
