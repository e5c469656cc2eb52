//! The register-level front end: up to four [`Octave`]s in cascade, one input pixel per clock,
//! and the output FIFOs. This is the clock-for-clock specification of the RTL.
//!
//! Octave `k` has line memories for `Wk` pixels; the defaults (1280, 640, 320, 160) take any
//! input up to 1280 wide. Each `Wk` must be at least `ceil(W(k-1) / 2)` and at least 12 (the
//! alignment FIFOs are sized in whole lines), checked at compile time. The point FIFO holds
//! `P` points (by default the map's `point_fifo_depth`).

use crate::fabric::config::{Config, ConfigError, MAX_OCTAVES};
use crate::fabric::octave::Octave;
use crate::fabric::output::{
    ClockedFrontEnd, Extremum, FrameError, FrontEnd, OutputFifos, Overflow, SobelEntry,
    POINT_FIFO_CAPACITY,
};
use crate::fabric::probe::ClockProbe;
use crate::fabric::sobel_fifo::SobelRun;

/// Register-level front end (see the module docs for the width parameters).
#[derive(Clone, Debug)]
pub struct RegisterFrontEnd<
    const W0: usize = 1280,
    const W1: usize = 640,
    const W2: usize = 320,
    const W3: usize = 160,
    const P: usize = POINT_FIFO_CAPACITY,
> {
    o0: Octave<W0>,
    o1: Octave<W1>,
    o2: Octave<W2>,
    o3: Octave<W3>,
    fifos: OutputFifos<W0, P>,
    config: Option<Config>,
    rows_in: u16,
    clock: u64,
    first_input: [Option<u64>; MAX_OCTAVES],
    probe: ClockProbe,
}

impl<const W0: usize, const W1: usize, const W2: usize, const W3: usize, const P: usize> Default
    for RegisterFrontEnd<W0, W1, W2, W3, P>
{
    fn default() -> Self {
        Self::new()
    }
}

impl<const W0: usize, const W1: usize, const W2: usize, const W3: usize, const P: usize>
    RegisterFrontEnd<W0, W1, W2, W3, P>
{
    /// An idle front end.
    pub const fn new() -> Self {
        const {
            assert!(W1 >= W0.div_ceil(2) && W2 >= W1.div_ceil(2) && W3 >= W2.div_ceil(2));
            assert!(W0 >= 12 && W1 >= 12 && W2 >= 12 && W3 >= 12);
            assert!(W0 <= u16::MAX as usize);
            assert!(P >= 1);
        }
        Self {
            o0: Octave::new(0),
            o1: Octave::new(1),
            o2: Octave::new(2),
            o3: Octave::new(3),
            fifos: OutputFifos::new(),
            config: None,
            rows_in: 0,
            clock: 0,
            first_input: [None; MAX_OCTAVES],
            probe: ClockProbe::IDLE,
        }
    }

    /// Line-memory lengths per octave.
    pub const MAX_WIDTHS: [usize; MAX_OCTAVES] = [W0, W1, W2, W3];

    /// Clocks since `start_frame`.
    pub fn clocks(&self) -> u64 {
        self.clock
    }

    /// Clock (counted from the first pixel of the frame at clock 0) at which octave `k` took
    /// its first input sample.
    pub fn first_input_clock(&self, k: usize) -> Option<u64> {
        self.first_input.get(k).copied().flatten()
    }

    /// Alignment FIFO faults summed over the octaves (zero unless the model is wrong).
    pub fn align_errors(&self) -> u32 {
        self.o0.align_errors()
            + self.o1.align_errors()
            + self.o2.align_errors()
            + self.o3.align_errors()
    }

    /// Whether every configured octave has emitted everything: [`FrontEnd::frame_done`]
    /// without its input-row count (the RTL's `done` output).
    pub fn octaves_done(&self) -> bool {
        let Some(cfg) = self.config else { return false };
        let n = cfg.octaves;
        self.o0.done()
            && (n < 2 || self.o1.done())
            && (n < 3 || self.o2.done())
            && (n < 4 || self.o3.done())
    }

    /// The observation signals of the last [`Self::clock`]: the `sc_frontend` observation
    /// ports during that clock ([`crate::fabric::probe`]); idle before the first clock of a
    /// frame. The row interface ([`FrontEnd::push_row`], [`FrontEnd::blank_row`]) does not
    /// record them (the probe reads idle after it).
    pub fn probe(&self) -> &ClockProbe {
        &self.probe
    }

    /// One pixel clock; `pixel = None` is a clock without a valid pixel (blanking). Records
    /// the clock's observation signals ([`Self::probe`]).
    pub fn clock(&mut self, pixel: Option<u8>) {
        self.step::<true>(pixel);
    }

    /// One clock; with `PROBE` its observation signals are recorded. The row interface
    /// clocks without (the benchmarked path pays nothing for the probe).
    fn step<const PROBE: bool>(&mut self, pixel: Option<u8>) {
        if PROBE {
            self.probe = ClockProbe::IDLE;
        }
        let Some(cfg) = self.config else { return };
        let n = cfg.octaves as usize;
        let now = self.clock;
        let mut note = |k: usize, v: Option<u16>| {
            if v.is_some() && self.first_input[k].is_none() {
                self.first_input[k] = Some(now);
            }
        };
        let x0 = pixel.map(|p| (p as u16) << 8);
        note(0, x0);
        let [p0, p1, p2, p3] = &mut self.probe.octaves;
        let x1 = self.o0.clock::<W0, P, PROBE>(x0, &mut self.fifos, p0);
        if n > 1 {
            note(1, x1);
            let x2 = self.o1.clock::<W0, P, PROBE>(x1, &mut self.fifos, p1);
            if n > 2 {
                note(2, x2);
                let x3 = self.o2.clock::<W0, P, PROBE>(x2, &mut self.fifos, p2);
                if n > 3 {
                    note(3, x3);
                    self.o3.clock::<W0, P, PROBE>(x3, &mut self.fifos, p3);
                }
            }
        }
        self.clock += 1;
    }
}

impl<const W0: usize, const W1: usize, const W2: usize, const W3: usize, const P: usize>
    ClockedFrontEnd for RegisterFrontEnd<W0, W1, W2, W3, P>
{
    fn clock(&mut self, pixel: Option<u8>) {
        self.step::<true>(pixel);
    }

    fn octaves_done(&self) -> bool {
        Self::octaves_done(self)
    }

    fn first_input_clock(&self, octave: usize) -> Option<u64> {
        Self::first_input_clock(self, octave)
    }
}

impl<const W0: usize, const W1: usize, const W2: usize, const W3: usize, const P: usize> FrontEnd
    for RegisterFrontEnd<W0, W1, W2, W3, P>
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
        self.first_input = [None; MAX_OCTAVES];
        self.probe = ClockProbe::IDLE;
        Ok(())
    }

    fn push_row(&mut self, row: &[u8]) -> Result<(), FrameError> {
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
        self.probe = ClockProbe::IDLE;
        for &p in row {
            self.step::<false>(Some(p));
        }
        self.rows_in += 1;
        Ok(())
    }

    fn blank_row(&mut self) -> bool {
        if let Some(cfg) = self.config {
            self.probe = ClockProbe::IDLE;
            for _ in 0..cfg.width {
                self.step::<false>(None);
            }
        }
        self.frame_done()
    }

    fn frame_done(&self) -> bool {
        let Some(cfg) = self.config else { return false };
        self.rows_in == cfg.height && self.octaves_done()
    }

    fn reset(&mut self) {
        self.fifos.clear();
        self.config = None;
        self.rows_in = 0;
        self.clock = 0;
        self.first_input = [None; MAX_OCTAVES];
        self.probe = ClockProbe::IDLE;
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
