//! The fast-path front end: octaves in cascade, a row per call.

use crate::fabric::config::{Config, ConfigError, MAX_OCTAVES};
use crate::fabric::fast::octave::FastOctave;
use crate::fabric::fast::probe::{NoProbe, Probe};
use crate::fabric::output::{Extremum, FrameError, FrontEnd, OutputFifos, Overflow, SobelPixel};
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
        }
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
        let Self {
            o0, input, fifos, ..
        } = self;
        let sub = o0.tick(Some(&input[..w]), fifos, probe);
        self.cascade(sub, probe);
        Ok(())
    }

    /// [`FrontEnd::blank_row`] with a probe.
    pub fn blank_row_probed<P: Probe>(&mut self, probe: &mut P) -> bool {
        if self.config.is_some() {
            let sub = self.o0.tick(None, &mut self.fifos, probe);
            self.cascade(sub, probe);
        }
        self.frame_done()
    }

    /// Ticks octaves 1.. with the subsampled rows (or phantom ticks).
    fn cascade<P: Probe>(&mut self, sub0: bool, probe: &mut P) {
        let n = self.config.map_or(0, |c| c.octaves);
        if n < 2 {
            return;
        }
        let sub1 = self
            .o1
            .tick(sub0.then(|| self.o0.sub_row()), &mut self.fifos, probe);
        if n < 3 {
            return;
        }
        let sub2 = self
            .o2
            .tick(sub1.then(|| self.o1.sub_row()), &mut self.fifos, probe);
        if n < 4 {
            return;
        }
        self.o3
            .tick(sub2.then(|| self.o2.sub_row()), &mut self.fifos, probe);
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
        self.rows_in == cfg.height
            && self.o0.done()
            && (n < 2 || self.o1.done())
            && (n < 3 || self.o2.done())
            && (n < 4 || self.o3.done())
    }

    fn reset(&mut self) {
        self.fifos.clear();
        self.config = None;
        self.rows_in = 0;
    }

    fn pop_point(&mut self) -> Option<Extremum> {
        self.fifos.pop_point()
    }

    fn pop_sobel(&mut self) -> Option<SobelPixel> {
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
}
