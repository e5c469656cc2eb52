//! A datapath chosen at run time: the fast path (the default) or the register-level model.
//!
//! Both push the same points and Sobel pixels into the FIFOs in the same order, line time by
//! line time (the RTL's: by clock, octave 0 first within a clock), so the packets of a frame
//! are the same bytes; the register-level model is the clock-level specification of the RTL
//! and is much slower, so the soft-core and the host run the fast path unless asked
//! otherwise.

use crate::fabric::{
    Config, ConfigError, Extremum, FastFrontEnd, FrameError, FrontEnd, Overflow, RegisterFrontEnd,
    SobelEntry, SobelRun,
};

/// Which implementation of the fabric runs the frames.
///
/// The variants differ in size by a hundred-odd kilobytes of line memories; boxing is not an
/// option without a heap, and a channel has exactly one of these for its whole life.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum FabricModel<
    const W0: usize = 1280,
    const W1: usize = 640,
    const W2: usize = 320,
    const W3: usize = 160,
> {
    /// Row-at-a-time implementation of the fabric's arithmetic.
    Fast(FastFrontEnd<W0, W1, W2, W3>),
    /// One clock per pixel, pipeline registers and line memories as in the RTL.
    RegisterLevel(RegisterFrontEnd<W0, W1, W2, W3>),
}

impl<const W0: usize, const W1: usize, const W2: usize, const W3: usize>
    FabricModel<W0, W1, W2, W3>
{
    /// The fast path.
    pub const fn fast() -> Self {
        Self::Fast(FastFrontEnd::new())
    }

    /// The register-level model.
    pub const fn register_level() -> Self {
        Self::RegisterLevel(RegisterFrontEnd::new())
    }

    fn front_end(&mut self) -> &mut dyn FrontEnd {
        match self {
            Self::Fast(fe) => fe,
            Self::RegisterLevel(fe) => fe,
        }
    }
}

impl<const W0: usize, const W1: usize, const W2: usize, const W3: usize> Default
    for FabricModel<W0, W1, W2, W3>
{
    fn default() -> Self {
        Self::fast()
    }
}

impl<const W0: usize, const W1: usize, const W2: usize, const W3: usize> FrontEnd
    for FabricModel<W0, W1, W2, W3>
{
    fn start_frame(&mut self, config: &Config) -> Result<(), ConfigError> {
        self.front_end().start_frame(config)
    }

    fn push_row(&mut self, row: &[u8]) -> Result<(), FrameError> {
        self.front_end().push_row(row)
    }

    fn reset(&mut self) {
        self.front_end().reset()
    }

    fn blank_row(&mut self) -> bool {
        self.front_end().blank_row()
    }

    fn frame_done(&self) -> bool {
        match self {
            Self::Fast(fe) => fe.frame_done(),
            Self::RegisterLevel(fe) => fe.frame_done(),
        }
    }

    // The device pops entries one at a time, as the soft-core reads the FIFO registers:
    // matched here rather than through `front_end()`, so each pop is a direct call the
    // compiler can inline into the device's loop instead of a virtual one.
    fn pop_point(&mut self) -> Option<Extremum> {
        match self {
            Self::Fast(fe) => fe.pop_point(),
            Self::RegisterLevel(fe) => fe.pop_point(),
        }
    }

    fn pop_sobel(&mut self) -> Option<SobelEntry> {
        match self {
            Self::Fast(fe) => fe.pop_sobel(),
            Self::RegisterLevel(fe) => fe.pop_sobel(),
        }
    }

    fn overflow(&self) -> Overflow {
        match self {
            Self::Fast(fe) => fe.overflow(),
            Self::RegisterLevel(fe) => fe.overflow(),
        }
    }

    fn point_level(&self) -> usize {
        match self {
            Self::Fast(fe) => fe.point_level(),
            Self::RegisterLevel(fe) => fe.point_level(),
        }
    }

    fn sobel_level(&self) -> usize {
        match self {
            Self::Fast(fe) => fe.sobel_level(),
            Self::RegisterLevel(fe) => fe.sobel_level(),
        }
    }

    fn drain_points(&mut self, sink: &mut dyn FnMut(&[Extremum])) {
        self.front_end().drain_points(sink)
    }

    fn drain_sobel(&mut self, max: usize, sink: &mut dyn FnMut(SobelRun<'_>)) {
        self.front_end().drain_sobel(max, sink)
    }

    fn drain_sobel_by_octave(
        &mut self,
        stash: &mut [[u32; 2]],
        sink: &mut dyn FnMut(SobelRun<'_>),
    ) {
        self.front_end().drain_sobel_by_octave(stash, sink)
    }

    fn drain_sobel_words(&mut self, max: usize, words: &mut [u32]) -> usize {
        self.front_end().drain_sobel_words(max, words)
    }
}
