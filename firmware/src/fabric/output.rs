//! What the front end hands the soft-core: a point stream and a Sobel stream in bounded FIFOs
//! with overflow counters, and the [`FrontEnd`] trait both implementations share.
//!
//! # Driver contract
//! 0. `reset()` (SOFT_RESET) empties the FIFOs and zeroes the drop counters.
//! 1. `start_frame(&config)` (register writes + FRAME_ARM): restarts the datapath; the FIFOs
//!    and counters keep what they hold, as in the RTL.
//! 2. For each input row: `push_row(&row)`, then drain both FIFOs (`pop_point`, `pop_sobel`
//!    until `None`). One input row produces at most `2·W0` Sobel pixels and the Sobel FIFO
//!    holds `3·W0`, so draining after every row never overflows.
//! 3. Vertical blanking: `blank_row()` (one row time of clocks without pixels) and drain, until
//!    it returns `true` (every octave has emitted everything).
//! 4. `overflow()` tells how many items were dropped because the driver fell behind; the
//!    counters are never reset silently (only `reset` clears them).
//!
//! Within one octave both streams come in raster order; the octaves interleave as the RTL
//! pushes them, by clock and octave 0 first within a clock, in both implementations: after
//! every `push_row` and `blank_row` the FIFOs hold the same entries in the same order and the
//! counters agree (`tests/fifo_order.rs`).

use crate::fabric::config::{Config, ConfigError};
use crate::fabric::fifo::LineFifo;
use crate::fabric::fifo_words::sobel_run_words;
use crate::fabric::refine::Offset;
use crate::fabric::sobel_fifo::{SobelAppend, SobelFifo, SobelRun};

/// A refined DoG extremum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Extremum {
    /// Column in the octave's own pixel grid.
    pub x: u16,
    /// Row in the octave's own pixel grid.
    pub y: u16,
    /// Octave 0..4 (octave `k` pixels are `2^k` input pixels apart).
    pub octave: u8,
    /// DoG index of the centre sample (always 1: the middle of the three DoG images).
    pub scale: u8,
    /// Sub-pixel column offset, Q2.13.
    pub dx: Offset,
    /// Sub-pixel row offset, Q2.13.
    pub dy: Offset,
    /// Sub-scale offset in DoG-index units, Q2.13.
    pub ds: Offset,
    /// DoG sample at the centre, Q8.8 grey levels (sign tells maximum from minimum).
    pub dog: i16,
}

impl Extremum {
    /// Power-up content of FIFO memories.
    pub const ZERO: Self = Self {
        x: 0,
        y: 0,
        octave: 0,
        scale: 0,
        dx: Offset::ZERO,
        dy: Offset::ZERO,
        ds: Offset::ZERO,
        dog: 0,
    };
}

/// One Sobel output pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SobelEntry {
    /// Octave 0..4.
    pub octave: u8,
    /// Orientation bin 0..64 (5.625° each, from +x toward +y).
    pub orientation: u8,
    /// Magnitude code (see [`crate::fabric::cordic`]).
    pub magnitude: u8,
    /// Column in the octave grid.
    pub x: u16,
    /// Row in the octave grid.
    pub y: u16,
}

/// Items dropped because a FIFO was full.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Overflow {
    pub points: u32,
    pub sobel: u32,
}

impl Overflow {
    /// What these counters counted since they read `before` (the counters only grow between
    /// resets, so the difference is the drops in between).
    pub fn since(self, before: Self) -> Self {
        Self {
            points: self.points.wrapping_sub(before.points),
            sobel: self.sobel.wrapping_sub(before.sobel),
        }
    }
}

/// Capacity of the point FIFO: the register map's `point_fifo_depth`.
pub const POINT_FIFO_CAPACITY: usize = stereocal_hdl::regs::POINT_FIFO_DEPTH as usize;

// The Sobel FIFO is 3 lines of octave 0: at the map's widest line that is the map's
// `sobel_fifo_depth`.
const _: () = assert!(3 * stereocal_hdl::regs::MAX_WIDTH == stereocal_hdl::regs::SOBEL_FIFO_DEPTH);

/// The two output FIFOs of a front end whose octave 0 is at most `W0` wide; the point FIFO
/// holds `POINTS` points (by default the map's `point_fifo_depth`; a co-simulation takes
/// fewer, so that small frames fill it).
#[derive(Clone, Debug)]
pub struct OutputFifos<const W0: usize, const POINTS: usize = POINT_FIFO_CAPACITY> {
    points: LineFifo<Extremum, POINTS, 1>,
    sobel: SobelFifo<W0, 3>,
    overflow: Overflow,
}

impl<const W0: usize, const POINTS: usize> Default for OutputFifos<W0, POINTS> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const W0: usize, const POINTS: usize> OutputFifos<W0, POINTS> {
    /// Empty FIFOs.
    pub const fn new() -> Self {
        Self {
            points: LineFifo::new(Extremum::ZERO),
            sobel: SobelFifo::new(),
            overflow: Overflow {
                points: 0,
                sobel: 0,
            },
        }
    }

    /// Empties both FIFOs and clears the counters.
    pub fn clear(&mut self) {
        self.points.clear();
        self.sobel.clear();
        self.overflow = Overflow::default();
    }

    /// Enqueues a point, counting it when full.
    #[inline]
    pub fn push_point(&mut self, p: Extremum) {
        if self.points.push(p).is_err() {
            self.overflow.points = self.overflow.points.saturating_add(1);
        }
    }

    /// Enqueues a Sobel pixel, counting it when full.
    #[inline]
    pub fn push_sobel(&mut self, s: SobelEntry) {
        if self.sobel.push(s).is_err() {
            self.overflow.sobel = self.overflow.sobel.saturating_add(1);
        }
    }

    /// Something that enqueues Sobel pixels until it is dropped, counting what does not fit.
    #[inline]
    pub fn append_sobel(&mut self) -> SobelAppend<'_> {
        self.sobel.append(&mut self.overflow.sobel)
    }

    /// Hands all queued points to `sink` (at most two slices) and empties the FIFO.
    pub fn drain_points(&mut self, sink: &mut dyn FnMut(&[Extremum])) {
        self.points.drain_slices(sink);
    }

    /// Hands the oldest `max` queued Sobel pixels (all, if fewer) to `sink` in row runs and
    /// removes them.
    pub fn drain_sobel(&mut self, max: usize, sink: &mut dyn FnMut(SobelRun<'_>)) {
        self.sobel.drain(max, sink);
    }

    /// Hands every queued Sobel pixel to `sink` in row runs, octave by octave (octave 0
    /// first), each octave's in FIFO order, and removes them; `stash` is room to set pixels
    /// aside ([`SobelFifo::drain_by_octave`]).
    pub fn drain_sobel_by_octave(
        &mut self,
        stash: &mut [[u32; 2]],
        sink: &mut dyn FnMut(SobelRun<'_>),
    ) {
        self.sobel.drain_by_octave(stash, sink);
    }

    /// Copies the words of the oldest `max` queued Sobel pixels (all, and no more than
    /// `words` holds, if fewer) into `words`, two per pixel, and removes them; returns how
    /// many pixels.
    pub fn drain_sobel_words(&mut self, max: usize, words: &mut [u32]) -> usize {
        self.sobel.drain_words(max, words)
    }

    /// Oldest point.
    #[inline]
    pub fn pop_point(&mut self) -> Option<Extremum> {
        self.points.pop()
    }

    /// Oldest Sobel pixel.
    #[inline]
    pub fn pop_sobel(&mut self) -> Option<SobelEntry> {
        self.sobel.pop()
    }

    /// Drop counters.
    pub fn overflow(&self) -> Overflow {
        self.overflow
    }

    /// Points held.
    pub fn point_level(&self) -> usize {
        self.points.len()
    }

    /// Sobel pixels held.
    pub fn sobel_level(&self) -> usize {
        self.sobel.len()
    }
}

/// A frame was fed wrongly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameError {
    /// `push_row` before a successful `start_frame`.
    NotStarted,
    /// A row of the wrong length.
    RowLength { expected: u16, got: usize },
    /// More rows than `Config::height`.
    TooManyRows,
    /// An image buffer whose length is not `width·height`.
    ImageSize { expected: usize, got: usize },
    /// The configuration was refused.
    Config(ConfigError),
    /// The pipeline did not drain within the bound of blanking rows (a model defect).
    FlushTimeout,
}

impl core::fmt::Display for FrameError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NotStarted => write!(f, "row pushed before start_frame"),
            Self::RowLength { expected, got } => {
                write!(f, "row of {got} pixels, configured width is {expected}")
            }
            Self::TooManyRows => write!(f, "more rows than the configured height"),
            Self::ImageSize { expected, got } => {
                write!(f, "image of {got} pixels, expected {expected}")
            }
            Self::Config(e) => write!(f, "configuration refused: {e}"),
            Self::FlushTimeout => write!(f, "front end did not drain during blanking"),
        }
    }
}

/// The interface the soft-core driver uses, implemented by the register-level model
/// ([`crate::fabric::pipeline::RegisterFrontEnd`]) and the fast path
/// ([`crate::fabric::fast::FastFrontEnd`]). Both produce bit-identical streams.
pub trait FrontEnd {
    /// Configures the datapath and starts a frame. The FIFOs and the drop counters keep what
    /// they hold (FRAME_ARM in the RTL restarts the datapath, not the FIFOs).
    fn start_frame(&mut self, config: &Config) -> Result<(), ConfigError>;
    /// Stops the frame, empties both FIFOs and zeroes the drop counters (SOFT_RESET).
    fn reset(&mut self);
    /// Feeds one row of 8-bit grey pixels.
    fn push_row(&mut self, row: &[u8]) -> Result<(), FrameError>;
    /// One row time of vertical blanking; `true` once the frame is completely processed.
    fn blank_row(&mut self) -> bool;
    /// Whether the frame is completely processed.
    fn frame_done(&self) -> bool;
    /// Oldest point of the point FIFO.
    fn pop_point(&mut self) -> Option<Extremum>;
    /// Oldest pixel of the Sobel FIFO.
    fn pop_sobel(&mut self) -> Option<SobelEntry>;
    /// Items dropped since the last [`FrontEnd::reset`] (saturating).
    fn overflow(&self) -> Overflow;
    /// Entries waiting in the point FIFO.
    fn point_level(&self) -> usize;
    /// Entries waiting in the Sobel FIFO.
    fn sobel_level(&self) -> usize;
    /// Hands every queued point to `sink`, oldest first, in at most two slices.
    fn drain_points(&mut self, sink: &mut dyn FnMut(&[Extremum]));
    /// Hands the oldest `max` queued Sobel pixels (all, if fewer) to `sink`, oldest first, in
    /// runs of consecutive pixels of one row, and removes them.
    fn drain_sobel(&mut self, max: usize, sink: &mut dyn FnMut(SobelRun<'_>));
    /// Hands every queued Sobel pixel to `sink` in runs of one row, octave 0's first, then
    /// octave 1's, 2's and 3's, each octave's in FIFO order, and removes them (what the
    /// stream engine takes at a line time). `stash` is the caller's room for two words per
    /// pixel set aside; a FIFO queueing more than it holds takes more passes, not fewer
    /// pixels.
    fn drain_sobel_by_octave(&mut self, stash: &mut [[u32; 2]], sink: &mut dyn FnMut(SobelRun<'_>));
    /// Writes the register words of the oldest `max` queued Sobel pixels (all, and no more
    /// than `words` holds, if fewer), two per pixel as [`sobel_run_words`] gives them, to the
    /// front of `words` and removes them; returns how many pixels. The fabric device serves
    /// its Sobel bursts with this; a front end whose FIFO holds the words copies them.
    fn drain_sobel_words(&mut self, max: usize, words: &mut [u32]) -> usize {
        let mut filled = 0;
        self.drain_sobel(max.min(words.len() / 2), &mut |run| {
            if let Some(free) = words.get_mut(filled * 2..) {
                filled += sobel_run_words(&run, free);
            }
        });
        filled
    }
}

/// A datapath that advances one fabric clock at a time, as `sc_frontend` does: what
/// [`crate::fabric::FabricDevice::clock`] needs to be `sc_fabric` clock for clock. The
/// register-level model is one; the fast path, which works by lines, is not.
pub trait ClockedFrontEnd: FrontEnd {
    /// One clock of the started frame; `pixel` is the pixel entering on it (`None`: none).
    /// The clock's pushes meet the FIFOs as they were before it.
    fn clock(&mut self, pixel: Option<u8>);
    /// Whether every configured octave has emitted everything (`sc_frontend`'s `done`).
    fn octaves_done(&self) -> bool;
    /// The clock, counting [`ClockedFrontEnd::clock`]s since `start_frame` from 0, on which
    /// octave `octave` took its first input sample.
    fn first_input_clock(&self, octave: usize) -> Option<u64>;
}

/// Runs a whole `config.width x config.height` frame through `fe`, draining the FIFOs after
/// every row into the two callbacks (slices of consecutive points and runs of Sobel pixels,
/// oldest first). Resets `fe` first; returns the frame's overflow counters.
pub fn run_frame<F: FrontEnd + ?Sized>(
    fe: &mut F,
    config: &Config,
    image: &[u8],
    on_points: &mut dyn FnMut(&[Extremum]),
    on_sobel: &mut dyn FnMut(SobelRun<'_>),
) -> Result<Overflow, FrameError> {
    let (w, h) = (config.width as usize, config.height as usize);
    if image.len() != w * h {
        return Err(FrameError::ImageSize {
            expected: w * h,
            got: image.len(),
        });
    }
    fe.reset();
    fe.start_frame(config).map_err(FrameError::Config)?;
    let mut drain = |fe: &mut F| {
        fe.drain_points(on_points);
        fe.drain_sobel(usize::MAX, on_sobel);
    };
    for row in image.chunks_exact(w) {
        fe.push_row(row)?;
        drain(fe);
    }
    // Octave k drains in about 10·2^k input rows; 4·h + 64 is a generous bound.
    for _ in 0..4 * h + 64 {
        let done = fe.blank_row();
        drain(fe);
        if done {
            return Ok(fe.overflow());
        }
    }
    Err(FrameError::FlushTimeout)
}

impl core::error::Error for FrameError {}
