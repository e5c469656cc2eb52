//! What one fast-path octave has computed and the register-level pipeline has not yet handed
//! out: Sobel rows and points waiting for the clock at which the pipeline would push them into
//! the FIFOs ([`crate::fabric::fast::release`] moves them there in the pipeline's order).
//!
//! The fast path computes a row when its last input row arrives; the pipeline hands the same
//! row's items out one per enabled clock over the following clocks, up to a line and a half
//! later in octave 0 and, in octave `k`, while octave `k - 1`'s next rows come in. Four Sobel
//! rows and two rows' worth of points (at most every other column of a row is an extremum)
//! hold that; an item that finds no room is counted ([`Pending::overruns`], zero unless the
//! fast path ran further ahead than that, which the tests check).

use crate::fabric::config::Config;
use crate::fabric::edge::EDGE_LATENCY;
use crate::fabric::extrema::EXTREMA_LATENCY;
use crate::fabric::fast::release::Waiting;
use crate::fabric::fifo::LineFifo;
use crate::fabric::geometry::octave_dims;
use crate::fabric::latency::{
    enabled_clock, enabled_run, octave_to_point, octave_to_sobel, ClockRun,
};
use crate::fabric::output::{Extremum, OutputFifos};
use crate::fabric::refine::REFINE_LATENCY;
use crate::fabric::sobel_fifo::SobelRun;

/// Sobel rows an octave holds (see the module docs).
const SOBEL_ROWS: usize = 4;

/// Enabled clocks from a candidate entering the extremum detector's register to its point
/// leaving the refinement: a candidate occupies the pipeline this long before its point.
const DETECT_TO_POINT: u64 = (EXTREMA_LATENCY + EDGE_LATENCY + REFINE_LATENCY) as u64;

/// The items of one octave computed ahead of the pipeline, rows of at most `W` pixels.
#[derive(Clone, Debug)]
pub(crate) struct Pending<const W: usize> {
    octave: u8,
    width: u16,
    height: u16,
    /// The frame's size (octave 0), which the schedule of every octave derives from.
    frame: (u16, u16),
    /// Enabled clocks from a sample to its Sobel pixel, and to its point.
    sobel_latency: u64,
    point_latency: u64,
    /// Sobel row `y` in slot `y % SOBEL_ROWS`.
    magnitude: [[u8; W]; SOBEL_ROWS],
    orientation: [[u8; W]; SOBEL_ROWS],
    /// Sobel rows computed.
    sobel_rows: u16,
    /// Raster index of the oldest Sobel pixel not yet handed out, and its row and column.
    sobel_next: u32,
    sobel_at: (u16, u16),
    points: LineFifo<Extremum, W, 1>,
    /// The enabled clock after which no candidate of the frame so far occupies the detector
    /// and refinement pipeline.
    candidates_out: u64,
    /// Items computed without room to wait in.
    overruns: u32,
}

impl<const W: usize> Pending<W> {
    pub(crate) const fn new(octave: u8) -> Self {
        Self {
            octave,
            width: 0,
            height: 0,
            frame: (0, 0),
            sobel_latency: 0,
            point_latency: 0,
            magnitude: [[0; W]; SOBEL_ROWS],
            orientation: [[0; W]; SOBEL_ROWS],
            sobel_rows: 0,
            sobel_next: 0,
            sobel_at: (0, 0),
            points: LineFifo::new(Extremum::ZERO),
            candidates_out: 0,
            overruns: 0,
        }
    }

    /// Empties it for a frame of `config`.
    pub(crate) fn start(&mut self, config: &Config) {
        let (w, h) = octave_dims(config.width, config.height, self.octave);
        self.width = w;
        self.height = h;
        self.frame = (config.width, config.height);
        self.sobel_latency = octave_to_sobel(w, self.octave, config.sobel_scale).into();
        self.point_latency = octave_to_point(w, self.octave).into();
        self.sobel_rows = 0;
        self.sobel_next = 0;
        self.sobel_at = (0, 0);
        self.points.clear();
        self.candidates_out = 0;
        self.overruns = 0;
    }

    /// Items computed without room to wait in since the frame started.
    pub(crate) fn overruns(&self) -> u32 {
        self.overruns
    }

    /// Enabled clocks from a sample to its Sobel pixel leaving the octave.
    pub(crate) fn sobel_latency(&self) -> u64 {
        self.sobel_latency
    }

    /// Enabled clocks from a sample to its point leaving the octave.
    pub(crate) fn point_latency(&self) -> u64 {
        self.point_latency
    }

    /// Clock of the octave's enabled clock `m`.
    pub(crate) fn clock_of(&self, m: u64) -> u64 {
        let (width, height) = self.frame;
        enabled_clock(width, height, self.octave, m)
    }

    /// The two slots Sobel row `y` (the next row) is computed into, or `None` when the row
    /// `SOBEL_ROWS` back still waits there (counted).
    pub(crate) fn sobel_slot(&mut self, y: u16) -> Option<(&mut [u8], &mut [u8])> {
        let w = usize::from(self.width).min(W);
        let oldest = u32::from(y).saturating_sub(SOBEL_ROWS as u32 - 1);
        if self.sobel_next < oldest * u32::from(self.width) {
            self.overruns = self.overruns.saturating_add(1);
            return None;
        }
        let slot = usize::from(y) % SOBEL_ROWS;
        Some((
            self.magnitude.get_mut(slot)?.get_mut(..w)?,
            self.orientation.get_mut(slot)?.get_mut(..w)?,
        ))
    }

    /// Sobel row `y`, computed into its slots, waits.
    pub(crate) fn sobel_done(&mut self, y: u16) {
        self.sobel_rows = y + 1;
    }

    /// A candidate at `(x, y)` entered the detector; `point` is what the refinement made of
    /// it, `None` when the edge test (`passed_edge` false) or the refinement rejected it.
    pub(crate) fn candidate(&mut self, x: u16, y: u16, passed_edge: bool, point: Option<Extremum>) {
        let n = u64::from(y) * u64::from(self.width) + u64::from(x);
        // Entering the detector register at `n + latency - DETECT_TO_POINT`: an edge-rejected
        // candidate is gone after the edge register's clock, a refine-rejected one after the
        // clock it reaches the refine register (the one before its point would have left), a
        // point after the clock it is pushed.
        let last = match (passed_edge, point.is_some()) {
            (false, _) => n + self.point_latency + EDGE_LATENCY as u64 - DETECT_TO_POINT,
            (true, false) => n + self.point_latency - 1,
            (true, true) => n + self.point_latency,
        };
        self.candidates_out = self.candidates_out.max(last);
        if let Some(p) = point {
            if self.points.push(p).is_err() {
                self.overruns = self.overruns.saturating_add(1);
            }
        }
    }

    /// Whether nothing waits.
    pub(crate) fn is_empty(&self) -> bool {
        self.points.is_empty()
            && self.sobel_next >= u32::from(self.sobel_rows) * u32::from(self.width)
    }

    /// The clock after which the pipeline of this octave holds nothing of the frame, once the
    /// frame is computed: the clock it pushes its last Sobel pixel, its last DoG window enters
    /// the detector, or its last candidate leaves the refinement.
    pub(crate) fn drained_clock(&self) -> u64 {
        let last = (u64::from(self.width) * u64::from(self.height)).saturating_sub(1);
        let windows = (last + self.point_latency).saturating_sub(DETECT_TO_POINT);
        let out = (last + self.sobel_latency)
            .max(windows)
            .max(self.candidates_out);
        self.clock_of(out)
    }
}

impl<const W: usize, const W0: usize> Waiting<W0> for Pending<W> {
    /// The clocks of the oldest waiting Sobel pixel and those after it, with how many pixels
    /// of its row wait (itself included); `None` when none waits.
    fn sobel_run(&self) -> Option<(ClockRun, u32)> {
        let computed = u32::from(self.sobel_rows) * u32::from(self.width);
        let n = self.sobel_next;
        if n >= computed {
            return None;
        }
        let row_left = u32::from(self.width.saturating_sub(self.sobel_at.1));
        let (width, height) = self.frame;
        let run = enabled_run(
            width,
            height,
            self.octave,
            u64::from(n) + self.sobel_latency,
        );
        Some((run, row_left.min(computed - n)))
    }

    /// The waiting Sobel pixels of the oldest one's row.
    fn sobel_waiting(&self) -> SobelRun<'_> {
        let (y, x) = self.sobel_at;
        let slot = usize::from(y) % SOBEL_ROWS;
        let computed = u32::from(self.sobel_rows) * u32::from(self.width);
        let left =
            u32::from(self.width.saturating_sub(x)).min(computed.saturating_sub(self.sobel_next));
        let span = usize::from(x)..usize::from(x) + left as usize;
        SobelRun {
            octave: self.octave,
            y,
            x,
            magnitude: self
                .magnitude
                .get(slot)
                .and_then(|r| r.get(span.clone()))
                .unwrap_or_default(),
            orientation: self
                .orientation
                .get(slot)
                .and_then(|r| r.get(span))
                .unwrap_or_default(),
        }
    }

    /// Lets go of the oldest `len` waiting Sobel pixels (of one row).
    fn sobel_released(&mut self, len: u32) {
        let (y, x) = self.sobel_at;
        self.sobel_next += len;
        // `len` is at most what is left of the row.
        let x = x + len as u16;
        self.sobel_at = if x >= self.width { (y + 1, 0) } else { (y, x) };
    }

    /// Clock at which the pipeline pushes the oldest waiting point, or `None` when none waits.
    fn point_clock(&self) -> Option<u64> {
        let p = self.points.peek()?;
        let n = u64::from(p.y) * u64::from(self.width) + u64::from(p.x);
        Some(self.clock_of(n + self.point_latency))
    }

    /// Hands the oldest waiting point to `out`.
    fn release_point(&mut self, out: &mut OutputFifos<W0>) {
        if let Some(p) = self.points.pop() {
            out.push_point(p);
        }
    }
}
