//! The fast-path front end: octaves in cascade, a row per call, and the FIFOs filled in the
//! register-level pipeline's order.
//!
//! Each call is a line time of the pipeline (`width` clocks). The octaves compute their rows
//! as soon as the rows they need are in, which is never later than the pipeline hands the
//! rows' items out while pixels come in; during the flush the pipeline runs an octave `k`
//! through `2^k` of its rows per line time, so the octaves behind the clock are ticked on
//! until they are not. Then everything the pipeline pushes before the call's last clock
//! moves into the FIFOs in the pipeline's order ([`crate::fabric::fast::release`]), and the
//! frame is done on the line time the pipeline's octaves have drained.

use crate::fabric::config::{Config, ConfigError, MAX_OCTAVES};
use crate::fabric::fast::octave::FastOctave;
use crate::fabric::fast::probe::{NoProbe, Probe};
use crate::fabric::fast::release::{release, Waiting};
use crate::fabric::output::{Extremum, FrameError, FrontEnd, OutputFifos, Overflow, SobelEntry};
use crate::fabric::sobel_fifo::SobelRun;
use crate::fabric::taps::{Taps, GAUSS_TAPS, TAP_BITS};

/// Fast front end with the same width parameters as
/// [`crate::fabric::pipeline::RegisterFrontEnd`].
#[derive(Clone, Debug)]
pub struct FastFrontEnd<
    const W0: usize = 1280,
    const W1: usize = 640,
    const W2: usize = 320,
    const W3: usize = 160,
> {
    o0: FastOctave<W0>,
    o1: FastOctave<W1>,
    o2: FastOctave<W2>,
    o3: FastOctave<W3>,
    input: [u16; W0],
    fifos: OutputFifos<W0>,
    config: Option<Config>,
    rows_in: u16,
    /// Clocks of the pipeline since the frame's first pixel: the calls so far times `width`.
    clock: u64,
}

impl<const W0: usize, const W1: usize, const W2: usize, const W3: usize> Default
    for FastFrontEnd<W0, W1, W2, W3>
{
    fn default() -> Self {
        Self::new()
    }
}

impl<const W0: usize, const W1: usize, const W2: usize, const W3: usize>
    FastFrontEnd<W0, W1, W2, W3>
{
    /// Row-memory lengths per octave.
    pub const MAX_WIDTHS: [usize; MAX_OCTAVES] = [W0, W1, W2, W3];

    /// An idle front end with the fabric's kernels ([`GAUSS_TAPS`]).
    pub const fn new() -> Self {
        Self::build(GAUSS_TAPS)
    }

    /// An idle front end whose Gaussians G0..G3 use `taps` instead of the fabric's kernels,
    /// or `None` unless every kernel is symmetric (the column pass adds mirrored rows first)
    /// with taps summing to `1 << TAP_BITS` (unity DC gain: the widths of the row sums and of
    /// the Q8.8 results rest on it), as every Gaussian of the fabric is. The fabric's kernels
    /// are fixed in its LUT ROMs; this exists to measure what other kernels would do
    /// (`tests/scale_space.rs` runs the thesis' own).
    pub const fn with_kernels(taps: [Taps; 4]) -> Option<Self> {
        let mut k = 0;
        while k < taps.len() {
            let t = taps[k];
            let sum = t[0] as u32 + t[1] as u32 + t[2] as u32 + t[3] as u32 + t[4] as u32;
            if t[0] != t[4] || t[1] != t[3] || sum != 1 << TAP_BITS {
                return None;
            }
            k += 1;
        }
        Some(Self::build(taps))
    }

    const fn build(taps: [Taps; 4]) -> Self {
        const {
            assert!(W1 >= W0.div_ceil(2) && W2 >= W1.div_ceil(2) && W3 >= W2.div_ceil(2));
            assert!(W0 <= u16::MAX as usize);
        }
        Self {
            o0: FastOctave::new(0, taps),
            o1: FastOctave::new(1, taps),
            o2: FastOctave::new(2, taps),
            o3: FastOctave::new(3, taps),
            input: [0; W0],
            fifos: OutputFifos::new(),
            config: None,
            rows_in: 0,
            clock: 0,
        }
    }

    /// Items the octaves computed without room to wait for their clock, summed (zero unless
    /// the fast path ran further ahead of the pipeline than it holds, checked by the tests).
    pub fn overruns(&self) -> u32 {
        self.o0.pending().overruns()
            + self.o1.pending().overruns()
            + self.o2.pending().overruns()
            + self.o3.pending().overruns()
    }

    /// [`FrontEnd::push_row`] with a probe that sees every scale and DoG row.
    pub fn push_row_probed<P: Probe>(
        &mut self,
        row: &[u8],
        probe: &mut P,
    ) -> Result<(), FrameError> {
        let cfg = self.config.ok_or(FrameError::NotStarted)?;
        if row.len() != cfg.width as usize {
            return Err(FrameError::RowLength {
                expected: cfg.width,
                got: row.len(),
            });
        }
        if self.rows_in >= cfg.height {
            return Err(FrameError::TooManyRows);
        }
        for (d, &p) in self.input.iter_mut().zip(row) {
            *d = (p as u16) << 8;
        }
        self.rows_in += 1;
        // `row.len() == cfg.width <= W0` (checked above and by validation); `min` keeps the
        // slice below in bounds by construction.
        let w = row.len().min(W0);
        let Self { o0, input, .. } = self;
        let sub = o0.tick(Some(&input[..w]), probe);
        self.cascade(sub, probe);
        self.line_time(probe);
        Ok(())
    }

    /// [`FrontEnd::blank_row`] with a probe.
    pub fn blank_row_probed<P: Probe>(&mut self, probe: &mut P) -> bool {
        if self.config.is_some() {
            let sub = self.o0.tick(None, probe);
            self.cascade(sub, probe);
            self.line_time(probe);
        }
        self.frame_done()
    }

    /// Ticks octaves 1.. with the subsampled rows (or phantom ticks).
    fn cascade<P: Probe>(&mut self, sub0: bool, probe: &mut P) {
        let n = self.config.map_or(0, |c| c.octaves);
        if n < 2 {
            return;
        }
        let sub1 = self.o1.tick(sub0.then(|| self.o0.sub_row()), probe);
        if n < 3 {
            return;
        }
        let sub2 = self.o2.tick(sub1.then(|| self.o1.sub_row()), probe);
        if n < 4 {
            return;
        }
        self.o3.tick(sub2.then(|| self.o2.sub_row()), probe);
    }

    /// Octaves in use.
    fn octaves(&self) -> usize {
        self.config.map_or(0, |c| usize::from(c.octaves))
    }

    /// Ticks octave `k` without input, then hands each subsampled row a tick makes to the
    /// next octave.
    fn flush_tick<P: Probe>(&mut self, k: usize, probe: &mut P) {
        let n = self.octaves();
        let Self { o0, o1, o2, o3, .. } = self;
        let mut sub = match k {
            0 => o0.tick(None, probe),
            1 => o1.tick(None, probe),
            2 => o2.tick(None, probe),
            _ => o3.tick(None, probe),
        };
        let mut next = k + 1;
        while sub && next < n {
            sub = match next {
                1 => o1.tick(Some(o0.sub_row()), probe),
                2 => o2.tick(Some(o1.sub_row()), probe),
                _ => o3.tick(Some(o2.sub_row()), probe),
            };
            next += 1;
        }
    }

    /// Whether octave `k` can be ticked without input, and the clock of the first item it
    /// has not computed ([`FastOctave::frontier`]).
    fn octave_state(&self, k: usize) -> (bool, Option<u64>) {
        let feeds = k + 1 < self.octaves();
        match k {
            0 => (self.o0.flushing(), self.o0.frontier(feeds)),
            1 => (self.o1.flushing(), self.o1.frontier(feeds)),
            2 => (self.o2.flushing(), self.o2.frontier(feeds)),
            _ => (self.o3.flushing(), self.o3.frontier(feeds)),
        }
    }

    /// Pushes every item the pipeline pushes before `until` into the FIFOs.
    fn release(&mut self, until: u64) {
        let n = self.octaves();
        let Self {
            o0,
            o1,
            o2,
            o3,
            fifos,
            ..
        } = self;
        let mut octaves: [&mut dyn Waiting<W0>; 4] = [
            o0.pending_mut(),
            o1.pending_mut(),
            o2.pending_mut(),
            o3.pending_mut(),
        ];
        let octaves = octaves.get_mut(..n).unwrap_or_default();
        release(octaves, until, fifos);
    }

    /// The end of a line time: catches the octaves up with the pipeline's clock and fills the
    /// FIFOs up to it.
    fn line_time<P: Probe>(&mut self, probe: &mut P) {
        let width = self.config.map_or(0, |c| u64::from(c.width));
        self.clock += width;
        let n = self.octaves();
        // Each round computes a row of some octave: the frame's rows bound the rounds.
        let rounds = 4 * (usize::from(self.config.map_or(0, |c| c.height)) + 16);
        for _ in 0..rounds {
            let mut safe = self.clock;
            let mut behind = None;
            for k in 0..n {
                let (flushing, frontier) = self.octave_state(k);
                let Some(frontier) = frontier else { continue };
                safe = safe.min(frontier);
                if frontier < self.clock && flushing && behind.is_none() {
                    behind = Some(k);
                }
            }
            // Everything before the first item not computed is final.
            self.release(safe);
            match behind {
                Some(k) => self.flush_tick(k, probe),
                None => break,
            }
        }
        self.release(self.clock);
    }
}

impl<const W0: usize, const W1: usize, const W2: usize, const W3: usize> FrontEnd
    for FastFrontEnd<W0, W1, W2, W3>
{
    fn start_frame(&mut self, config: &Config) -> Result<(), ConfigError> {
        config.validate(Self::MAX_WIDTHS)?;
        self.o0.start(config);
        self.o1.start(config);
        self.o2.start(config);
        self.o3.start(config);
        self.config = Some(*config);
        self.rows_in = 0;
        self.clock = 0;
        Ok(())
    }

    fn push_row(&mut self, row: &[u8]) -> Result<(), FrameError> {
        self.push_row_probed(row, &mut NoProbe)
    }

    fn blank_row(&mut self) -> bool {
        self.blank_row_probed(&mut NoProbe)
    }

    fn frame_done(&self) -> bool {
        let Some(cfg) = self.config else { return false };
        let n = cfg.octaves;
        let t = self.clock;
        self.rows_in == cfg.height
            && self.o0.drained_by(t)
            && (n < 2 || self.o1.drained_by(t))
            && (n < 3 || self.o2.drained_by(t))
            && (n < 4 || self.o3.drained_by(t))
    }

    fn reset(&mut self) {
        self.fifos.clear();
        self.config = None;
        self.rows_in = 0;
        self.clock = 0;
    }

    fn pop_point(&mut self) -> Option<Extremum> {
        self.fifos.pop_point()
    }

    fn pop_sobel(&mut self) -> Option<SobelEntry> {
        self.fifos.pop_sobel()
    }

    fn overflow(&self) -> Overflow {
        self.fifos.overflow()
    }

    fn point_level(&self) -> usize {
        self.fifos.point_level()
    }

    fn sobel_level(&self) -> usize {
        self.fifos.sobel_level()
    }

    fn drain_points(&mut self, sink: &mut dyn FnMut(&[Extremum])) {
        self.fifos.drain_points(sink);
    }

    fn drain_sobel(&mut self, max: usize, sink: &mut dyn FnMut(SobelRun<'_>)) {
        self.fifos.drain_sobel(max, sink);
    }

    fn drain_sobel_by_octave(
        &mut self,
        stash: &mut [[u32; 2]],
        sink: &mut dyn FnMut(SobelRun<'_>),
    ) {
        self.fifos.drain_sobel_by_octave(stash, sink);
    }

    fn drain_sobel_words(&mut self, max: usize, words: &mut [u32]) -> usize {
        self.fifos.drain_sobel_words(max, words)
    }
}
