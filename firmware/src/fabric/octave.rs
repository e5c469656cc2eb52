//! One octave of the register-level model (thesis fig. 4.5): the base image (G0: the input
//! filter in octave 0, the subsampled G3 of the previous octave unfiltered in octaves 1..) and
//! the cascade G1..G3, the
//! alignment FIFOs, three DoG images, the 3x3x3 extremum detector with edge rejection and
//! refinement, the Sobel/CORDIC branch on the configured scale, and the subsampler.
//!
//! # Clocking
//! The octave is clock-enabled: it advances on every clock its input is valid, and after its
//! last input sample on every clock until it has emitted everything (the flush that vertical
//! blanking pays for). All latencies are counted in these enabled clocks.
//!
//! # Alignment
//! `G_i(p)` leaves its convolver `(3 - i)·(2w + 4)` enabled clocks before `G3(p)`. Rather than
//! fixed delay lines, `G0..G2` are pushed into FIFOs and popped when `G3` is valid: both streams
//! carry the same pixels in the same order, so a FIFO aligns them by construction. Occupancy is
//! at most `(3 - i)·(2w + 4)`, hence 7, 5 and 3 lines of `W` for `W ≥ 12`.
//!
//! # Widths
//! Scale images `u16` Q8.8, DoG `i16` Q8.8, Sobel 19-bit signed, offsets Q2.13.

use crate::fabric::config::Config;
use crate::fabric::convolver::{ColumnConvolver, RowConvolver};
use crate::fabric::cordic::CordicPipeline;
use crate::fabric::dog::dog3;
use crate::fabric::edge::passes_edge_test;
use crate::fabric::extrema::{is_extremum, Cube};
use crate::fabric::fifo::LineFifo;
use crate::fabric::geometry::octave_dims;
use crate::fabric::output::{Extremum, OutputFifos, SobelEntry};
use crate::fabric::probe::OctaveProbe;
use crate::fabric::refine::{refine, REFINE_LATENCY};
use crate::fabric::sobel::sobel;
use crate::fabric::subsample::Subsampler;
use crate::fabric::taps::GAUSS_LUTS;
use crate::fabric::window::WindowFormer;

/// A candidate in the detector pipeline registers: position and its DoG cube.
type Candidate = (u16, u16, Cube);

/// Refinement stages before the refine register ([`REFINE_LATENCY`] counts the register).
const REFINE_STAGES: usize = REFINE_LATENCY as usize - 1;
const _: () = assert!(REFINE_STAGES >= 1);

/// Register-level octave whose rows are at most `W` pixels.
#[derive(Clone, Debug)]
pub struct Octave<const W: usize> {
    index: u8,
    width: u16,
    height: u16,
    total: u32,
    taken: u32,
    config: Config,
    rows: [RowConvolver; 4],
    cols: [ColumnConvolver<W>; 4],
    align0: LineFifo<u16, W, 7>,
    align1: LineFifo<u16, W, 5>,
    align2: LineFifo<u16, W, 3>,
    /// Alignment FIFO under- or overflows; zero by construction, checked by the tests.
    align_errors: u32,
    dog_reg: Option<[i16; 3]>,
    dog_window: WindowFormer<[i16; 3], W>,
    detect_reg: Option<Candidate>,
    edge_reg: Option<Candidate>,
    /// The refinement pipeline (sc_refine.v stages 1..17) as a delay line of
    /// [`REFINE_STAGES`] registers, kept as a ring (`refine_head` is the oldest slot, the
    /// one that moves into `refine_reg` on the next enabled clock, then takes the new
    /// candidate). `refine()` is computed when the candidate enters; a slot is `Some` while a
    /// candidate is in flight, `Some(None)` when refine() rejected it: like the RTL's valid
    /// bits, rejected candidates occupy the pipeline (and keep `done()` false) until they
    /// reach the refine register, where they are dropped.
    refine_pipe: [Option<Option<Extremum>>; REFINE_STAGES],
    refine_head: usize,
    /// The last refinement stage, the output register: a point for the point FIFO.
    refine_reg: Option<Extremum>,
    sobel_window: WindowFormer<u16, W>,
    gradient_reg: Option<(u16, u16, i32, i32)>,
    cordic: CordicPipeline,
    subsampler: Subsampler,
}

impl<const W: usize> Octave<W> {
    /// Idle octave number `index`.
    pub const fn new(index: u8) -> Self {
        let lut = GAUSS_LUTS;
        Self {
            index,
            width: 0,
            height: 0,
            total: 0,
            taken: 0,
            config: Config::new(0, 0),
            rows: [
                RowConvolver::new(lut[0]),
                RowConvolver::new(lut[1]),
                RowConvolver::new(lut[2]),
                RowConvolver::new(lut[3]),
            ],
            cols: [
                ColumnConvolver::new(lut[0]),
                ColumnConvolver::new(lut[1]),
                ColumnConvolver::new(lut[2]),
                ColumnConvolver::new(lut[3]),
            ],
            align0: LineFifo::new(0),
            align1: LineFifo::new(0),
            align2: LineFifo::new(0),
            align_errors: 0,
            dog_reg: None,
            dog_window: WindowFormer::new([0; 3]),
            detect_reg: None,
            edge_reg: None,
            refine_pipe: [None; REFINE_STAGES],
            refine_head: 0,
            refine_reg: None,
            sobel_window: WindowFormer::new(0),
            gradient_reg: None,
            cordic: CordicPipeline::new(),
            subsampler: Subsampler::new(),
        }
    }

    /// Resets for a frame (the octave's own size is derived from `config`).
    pub fn start(&mut self, config: &Config) {
        let (w, h) = octave_dims(config.width, config.height, self.index);
        self.width = w;
        self.height = h;
        self.total = w as u32 * h as u32;
        self.taken = 0;
        self.config = *config;
        for r in &mut self.rows {
            r.start(w, h);
        }
        for c in &mut self.cols {
            c.start(w, h);
        }
        self.align0.clear();
        self.align1.clear();
        self.align2.clear();
        self.align_errors = 0;
        self.dog_reg = None;
        self.dog_window.start(w, h);
        self.detect_reg = None;
        self.edge_reg = None;
        self.refine_pipe = [None; REFINE_STAGES];
        self.refine_head = 0;
        self.refine_reg = None;
        self.sobel_window.start(w, h);
        self.gradient_reg = None;
        self.cordic = CordicPipeline::new();
        self.subsampler.start(w, h);
    }

    /// Octave size `(width, height)`.
    pub fn dims(&self) -> (u16, u16) {
        (self.width, self.height)
    }

    /// Alignment FIFO faults (must stay 0).
    pub fn align_errors(&self) -> u32 {
        self.align_errors
    }

    /// Whether every output of the frame has left the octave.
    pub fn done(&self) -> bool {
        self.taken == self.total
            && self.subsampler.done()
            && self.sobel_window.done()
            && self.gradient_reg.is_none()
            && self.cordic.is_empty()
            && self.dog_window.done()
            && self.dog_reg.is_none()
            && self.detect_reg.is_none()
            && self.edge_reg.is_none()
            && self.refine_pipe.iter().all(Option::is_none)
            && self.refine_reg.is_none()
    }

    /// One clock. `input` is a Q8.8 sample (valid strobe = `Some`). Returns the subsampler's
    /// output register: the next octave's input during this clock.
    ///
    /// With `PROBE`, on a clock the octave is enabled it records its observation signals in
    /// `probe` ([`crate::fabric::probe`]); otherwise `probe` is left as it is (the caller
    /// resets it). Without `PROBE` (the benchmarked path) nothing is recorded.
    pub fn clock<const W0: usize, const POINTS: usize, const PROBE: bool>(
        &mut self,
        input: Option<u16>,
        out: &mut OutputFifos<W0, POINTS>,
        probe: &mut OctaveProbe,
    ) -> Option<u16> {
        let flushing = self.taken == self.total && !self.done();
        if input.is_none() && !flushing {
            return None;
        }
        if input.is_some() {
            self.taken += 1;
        }
        if PROBE {
            probe.en = true;
        }

        // Gaussian cascade: every stage samples its upstream stage's output register.
        let mut g = [None; 4];
        let mut wire = input;
        for (i, gi) in g.iter_mut().enumerate() {
            *gi = if i == 0 && self.index > 0 {
                // Octaves 1.. take the subsampled G3 as their base image unfiltered.
                input
            } else {
                let r = self.rows[i].clock(wire);
                self.cols[i].clock(r)
            };
            wire = *gi;
        }
        if PROBE {
            probe.g = g;
        }

        // Sobel branch.
        if let Some((x, y, magnitude, orientation)) = self.cordic.clock(self.gradient_reg.take()) {
            let px = SobelEntry {
                octave: self.index,
                orientation,
                magnitude,
                x,
                y,
            };
            if PROBE {
                probe.sobel = Some(px);
            }
            out.push_sobel(px);
        }
        let s = self.config.sobel_scale as usize & 3;
        if let Some(win) = self.sobel_window.clock(g[s]) {
            let (sx, sy) = sobel(&win.w);
            self.gradient_reg = Some((win.x, win.y, sx, sy));
        }

        // Detector branch, last register first.
        if let Some(p) = self.refine_reg.take() {
            if PROBE {
                probe.point = Some(p);
            }
            out.push_point(p);
        }
        let cfg = self.config;
        let index = self.index;
        // Refinement pipeline: the oldest stage moves into the refine register (dropped there
        // when rejected) and its slot takes the edge register's candidate.
        // `refine_head` is always reduced; reducing again lets the compiler see the index in
        // range (no bounds check, so no panic path in the firmware).
        let head = self.refine_head % REFINE_STAGES;
        self.refine_reg = self.refine_pipe[head].take().flatten();
        self.refine_pipe[head] = self.edge_reg.take().map(|(x, y, c)| {
            refine(&c, cfg.max_offset).map(|[dx, dy, ds]| Extremum {
                x,
                y,
                octave: index,
                scale: 1,
                dx,
                dy,
                ds,
                dog: c[1][1][1],
            })
        });
        self.refine_head = (head + 1) % REFINE_STAGES;
        self.edge_reg = self
            .detect_reg
            .take()
            .filter(|(_, _, c)| passes_edge_test(&c[1], cfg.edge_ratio));
        let (w, h) = (self.width, self.height);
        let dog = self.dog_reg.take();
        if PROBE {
            probe.dog = dog;
        }
        self.detect_reg = self.dog_window.clock(dog).and_then(|win| {
            let interior = win.x >= 1 && win.y >= 1 && win.x + 2 <= w && win.y + 2 <= h;
            if !interior {
                return None;
            }
            let mut c: Cube = [[[0; 3]; 3]; 3];
            for (s, plane) in c.iter_mut().enumerate() {
                for (y, row) in plane.iter_mut().enumerate() {
                    for (x, v) in row.iter_mut().enumerate() {
                        *v = win.w[y][x][s];
                    }
                }
            }
            is_extremum(&c, cfg.contrast_threshold).then_some((win.x, win.y, c))
        });

        // DoG: pop the aligned G0..G2 (read port first), then push this clock's G0..G2.
        self.dog_reg = match g[3] {
            Some(g3) => match (self.align0.pop(), self.align1.pop(), self.align2.pop()) {
                (Some(a), Some(b), Some(c)) => Some(dog3([a, b, c, g3])),
                _ => {
                    self.align_errors += 1;
                    None
                }
            },
            None => None,
        };
        for (fifo_ok, v) in [
            (g[0].map(|v| self.align0.push(v).is_ok()), g[0]),
            (g[1].map(|v| self.align1.push(v).is_ok()), g[1]),
            (g[2].map(|v| self.align2.push(v).is_ok()), g[2]),
        ] {
            if v.is_some() && fifo_ok == Some(false) {
                self.align_errors += 1;
            }
        }

        let sub = self.subsampler.clock(g[3]);
        if PROBE {
            probe.sub = sub;
        }
        sub
    }
}
