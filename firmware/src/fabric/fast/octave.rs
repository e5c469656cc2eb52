//! One octave of the fast path: rings of rows instead of line memories.
//!
//! Each Gaussian keeps the last 5 row-filtered input rows; its output row `r` is produced when
//! input row `r + 2` arrives, or, once its input is complete, one pending row per tick (the row
//! analogue of the register model's phantom samples). Scale rows live in 8-row rings, long
//! enough for G0 row `r` to still be there when G3 row `r` appears (6 rows later).
//!
//! No index can panic: ring slots are taken modulo the ring length, and the row length is
//! `width.min(W)` ([`FastOctave::row_len`]; `start` is only called with configurations
//! validated against `W`, so the `min` never changes it), which bounds every `[..w]`.

use crate::fabric::config::Config;
use crate::fabric::edge::passes_edge_test;
use crate::fabric::extrema::{is_extremum, Cube};
use crate::fabric::fast::filter::{column_filter, cordic_row, dog_row, row_filter, sobel_row};
use crate::fabric::fast::pending::Pending;
use crate::fabric::fast::probe::Probe;
use crate::fabric::geometry::octave_dims;
use crate::fabric::latency::octave_to_next;
use crate::fabric::output::Extremum;
use crate::fabric::refine::refine;
use crate::fabric::taps::Taps;

const RING: usize = 8;

/// Row counters of one Gaussian.
#[derive(Clone, Copy, Debug, Default)]
struct GaussCount {
    rows_in: u16,
    rows_out: u16,
}

/// Fast-path octave with rows of at most `W` pixels.
#[derive(Clone, Debug)]
pub(crate) struct FastOctave<const W: usize> {
    index: u8,
    /// G0..G3 (G0 only used by octave 0).
    taps: [Taps; 4],
    width: u16,
    height: u16,
    rows_in: u16,
    config: Config,
    count: [GaussCount; 4],
    /// Row-filtered input rows of each Gaussian (the row stage's exact 26-bit sums), row `y`
    /// in slot `y % 5`.
    filtered: [[[u32; W]; 5]; 4],
    /// Scale image rows, row `y` in slot `y % 8`.
    scale: [[[u16; W]; RING]; 4],
    /// DoG rows of the three DoG images, row `y` in slot `y % 3`.
    dog: [[[i16; W]; 3]; 3],
    sobel_rows: u16,
    sx: [i32; W],
    sy: [i32; W],
    /// Sobel rows and points computed ahead of the register-level pipeline.
    pending: Pending<W>,
    /// The subsampled G3 row handed to the next octave.
    sub: [u16; W],
    sub_len: usize,
}

impl<const W: usize> FastOctave<W> {
    pub(crate) const fn new(index: u8, taps: [Taps; 4]) -> Self {
        Self {
            index,
            taps,
            width: 0,
            height: 0,
            rows_in: 0,
            config: Config::new(0, 0),
            count: [GaussCount {
                rows_in: 0,
                rows_out: 0,
            }; 4],
            filtered: [[[0; W]; 5]; 4],
            scale: [[[0; W]; RING]; 4],
            dog: [[[0; W]; 3]; 3],
            sobel_rows: 0,
            sx: [0; W],
            sy: [0; W],
            pending: Pending::new(index),
            sub: [0; W],
            sub_len: 0,
        }
    }

    pub(crate) fn start(&mut self, config: &Config) {
        let (w, h) = octave_dims(config.width, config.height, self.index);
        self.width = w;
        self.height = h;
        self.rows_in = 0;
        self.config = *config;
        self.count = [GaussCount::default(); 4];
        self.sobel_rows = 0;
        self.sub_len = 0;
        self.pending.start(config);
    }

    /// What the octave computed and the pipeline has not handed out yet.
    pub(crate) fn pending(&self) -> &Pending<W> {
        &self.pending
    }

    /// The same, to hand out.
    pub(crate) fn pending_mut(&mut self) -> &mut Pending<W> {
        &mut self.pending
    }

    /// Whether the register-level pipeline's octave has drained before clock `clock`: the
    /// octave computed everything, handed everything out, and the pipeline's last item of
    /// the frame left before that clock.
    pub(crate) fn drained_by(&self, clock: u64) -> bool {
        self.done() && self.pending.is_empty() && self.pending.drained_clock() < clock
    }

    /// Whether the input is complete and there is still something to compute: a tick
    /// without input makes progress.
    pub(crate) fn flushing(&self) -> bool {
        self.rows_in == self.height && !self.done()
    }

    /// Clock at which the register-level pipeline hands out the first item this octave has
    /// not computed yet: its next Sobel row, its next row of points, or, when `feeds` (an
    /// octave follows), its next subsampled row; `None` when everything is computed.
    pub(crate) fn frontier(&self, feeds: bool) -> Option<u64> {
        let (w, h) = (u64::from(self.width), self.height);
        let g3 = self.count[3].rows_out;
        // The extremum scan of row `r - 1` runs with DoG (and G3) row `r >= 2`.
        let scan = g3.max(2) - 1;
        let sub = g3 + (g3 & 1);
        let first = [
            (self.sobel_rows < h)
                .then(|| u64::from(self.sobel_rows) * w + self.pending.sobel_latency()),
            (scan + 2 <= h).then(|| u64::from(scan) * w + 1 + self.pending.point_latency()),
            (feeds && sub < h)
                .then(|| u64::from(sub) * w + u64::from(octave_to_next(self.width, self.index))),
        ]
        .into_iter()
        .flatten()
        .min()?;
        Some(self.pending.clock_of(first))
    }

    pub(crate) fn done(&self) -> bool {
        self.rows_in == self.height
            && self.count[3].rows_out == self.height
            && self.sobel_rows == self.height
    }

    /// The subsampled row produced by the last tick.
    pub(crate) fn sub_row(&self) -> &[u16] {
        &self.sub[..self.sub_len.min(W)]
    }

    /// Pixels per row: the octave's width, which validation keeps at most `W`.
    #[inline(always)]
    fn row_len(&self) -> usize {
        (self.width as usize).min(W)
    }

    /// One row tick: a real row, or `None` (a phantom tick once the input is complete).
    /// Returns whether a subsampled row for the next octave was produced.
    pub(crate) fn tick<P: Probe>(&mut self, input: Option<&[u16]>, probe: &mut P) -> bool {
        if input.is_some() {
            self.rows_in += 1;
        } else if self.rows_in < self.height {
            return false;
        }
        let w = self.row_len();
        let h = self.height;
        let mut emitted: [Option<u16>; 4] = [None; 4];
        for i in 0..4 {
            if i == 0 && self.index > 0 {
                // Octaves 1.. take the subsampled G3 as their base image unfiltered.
                let c = &mut self.count[0];
                if let Some(row) = input {
                    let r = c.rows_in;
                    c.rows_in += 1;
                    c.rows_out += 1;
                    let dst = &mut self.scale[0][r as usize % RING][..w];
                    for (d, &v) in dst.iter_mut().zip(row) {
                        *d = v;
                    }
                    probe.scale_row(self.index, 0, r, row);
                    emitted[0] = Some(r);
                }
                continue;
            }
            let src: Option<&[u16]> = match (i, input) {
                (0, inp) => inp,
                (_, _) => emitted[i - 1].map(|r| &self.scale[i - 1][r as usize % RING][..w]),
            };
            let c = &mut self.count[i];
            if let Some(row) = src {
                row_filter(
                    &self.taps[i],
                    row,
                    &mut self.filtered[i][c.rows_in as usize % 5],
                );
                c.rows_in += 1;
                if c.rows_in >= 3 {
                    emitted[i] = Some(c.rows_in - 3);
                }
            } else if c.rows_in == h && c.rows_out < h {
                emitted[i] = Some(c.rows_out);
            }
            if let Some(r) = emitted[i] {
                let last = h as i32 - 1;
                let slot = |k: i32| ((r as i32 + k).max(0).min(last) as usize) % 5;
                let f = &self.filtered[i];
                let rows = [
                    &f[slot(-2)][..w],
                    &f[slot(-1)][..w],
                    &f[slot(0)][..w],
                    &f[slot(1)][..w],
                    &f[slot(2)][..w],
                ];
                column_filter(
                    &self.taps[i],
                    rows,
                    &mut self.scale[i][r as usize % RING][..w],
                );
                self.count[i].rows_out += 1;
                probe.scale_row(
                    self.index,
                    i as u8,
                    r,
                    &self.scale[i][r as usize % RING][..w],
                );
            }
        }

        self.sobel_tick();

        self.sub_len = 0;
        if let Some(r) = emitted[3] {
            self.dog_and_extrema(r, probe);
            if r & 1 == 0 {
                let g3 = &self.scale[3][r as usize % RING][..w];
                self.sub_len = w.div_ceil(2);
                for (s, &g) in self.sub.iter_mut().zip(g3.iter().step_by(2)) {
                    *s = g;
                }
                return true;
            }
        }
        false
    }

    /// Emits at most one Sobel row: row `s` once scale row `s + 1` exists, or once the scale
    /// image is complete.
    /// A row without room to wait in ([`Pending::sobel_slot`]) is skipped, counted there.
    fn sobel_tick(&mut self) {
        let s = self.config.sobel_scale as usize & 3;
        let (w, h) = (self.row_len(), self.height);
        let have = self.count[s].rows_out;
        let r = self.sobel_rows;
        if r >= h || (r + 2 > have && have < h) {
            return;
        }
        let last = h as i32 - 1;
        let slot = |k: i32| ((r as i32 + k).max(0).min(last) as usize) % RING;
        let g = &self.scale[s];
        sobel_row(
            [&g[slot(-1)][..w], &g[slot(0)][..w], &g[slot(1)][..w]],
            &mut self.sx[..w],
            &mut self.sy[..w],
        );
        if let Some((magnitude, orientation)) = self.pending.sobel_slot(r) {
            cordic_row(&self.sx[..w], &self.sy[..w], magnitude, orientation);
            self.pending.sobel_done(r);
        }
        self.sobel_rows += 1;
    }

    /// DoG row `r`, then the extremum scan of row `r - 1`.
    fn dog_and_extrema<P: Probe>(&mut self, r: u16, probe: &mut P) {
        let w = self.row_len();
        let slot = r as usize % RING;
        for i in 0..3 {
            let (a, b) = (&self.scale[i][slot], &self.scale[i + 1][slot]);
            dog_row(&a[..w], &b[..w], &mut self.dog[i][r as usize % 3][..w]);
            probe.dog_row(self.index, i as u8, r, &self.dog[i][r as usize % 3][..w]);
        }
        if r < 2 || w < 3 {
            return;
        }
        let yc = r - 1;
        let rows = [(r as usize - 2) % 3, (r as usize - 1) % 3, r as usize % 3];
        let (thr, edge_ratio, max_offset) = (
            self.config.contrast_threshold,
            self.config.edge_ratio,
            self.config.max_offset,
        );
        // `get`, not indexing: the ring slots are below 3 and `w <= W`, but the optimiser
        // cannot see that through the maps, and the firmware must link no panic.
        let planes = self
            .dog
            .each_ref()
            .map(|d| rows.map(|y| d.get(y).and_then(|r| r.get(..w)).unwrap_or(&[])));
        let index = self.index;
        let pending = &mut self.pending;
        let mut verify = |x: usize| {
            let c = cube(&planes, x);
            if !is_extremum(&c, thr) {
                return;
            }
            let x = x as u16;
            if !passes_edge_test(&c[1], edge_ratio) {
                pending.candidate(x, yc, false, None);
                return;
            }
            let point = refine(&c, max_offset).map(|[dx, dy, ds]| Extremum {
                x,
                y: yc,
                octave: index,
                scale: 1,
                dx,
                dy,
                ds,
                dog: c[1][1][1],
            });
            pending.candidate(x, yc, true, point);
        };
        // Blocks of centres are screened branch-free on necessary conditions, and only the
        // survivors take the 26-neighbour test on their cube; the last centres, fewer than a
        // block, take it one by one.
        let mut x = 1;
        while x + 1 < w {
            if let Some(mut mask) = screen(&planes, x, thr) {
                while mask != 0 {
                    verify(x + mask.trailing_zeros() as usize);
                    mask &= mask - 1;
                }
                x += SCREEN_BLOCK;
            } else {
                verify(x);
                x += 1;
            }
        }
    }
}

/// Centres screened at once by [`screen`]: 16 `i16` lanes, two SSE2 registers.
const SCREEN_BLOCK: usize = 16;

/// The `SCREEN_BLOCK` samples of `row` from column `x`, or `None` past its end.
#[inline(always)]
fn block(row: &[i16], x: usize) -> Option<&[i16; SCREEN_BLOCK]> {
    row.get(x..x + SCREEN_BLOCK)?.try_into().ok()
}

/// For the centres `x .. x + SCREEN_BLOCK` (`x >= 1`) of the middle DoG `planes[1][1]`, bit
/// `j` clear when centre `x + j` cannot be an extremum: its contrast is too low, or one of its
/// six face neighbours (left, right, up, down, the DoGs below and above) is not strictly
/// beyond it. `None` when the block's right neighbours run past the row.
///
/// Fixed-size arrays, `max`/`min` and no early exit, so it compiles to SSE2 `pmaxsw`/`pminsw`
/// over eight lanes: on smooth images many centres pass the contrast test and the per-pixel
/// branches of a scalar screen mispredict.
#[inline(always)]
fn screen(planes: &[[&[i16]; 3]; 3], x: usize, threshold: u16) -> Option<u32> {
    let [below, mid, above] = planes;
    let v = block(mid[1], x)?;
    let faces = [
        block(mid[1], x - 1)?,
        block(mid[1], x + 1)?,
        block(mid[0], x)?,
        block(mid[2], x)?,
        block(below[1], x)?,
        block(above[1], x)?,
    ];
    // `v > threshold` and `v < -threshold` in i16: a threshold above i16::MAX admits no
    // maximum, one below i16::MIN no minimum, so clamping both bounds keeps the verdicts.
    let high = threshold.min(i16::MAX as u16) as i16;
    let low = (-i32::from(threshold)).max(i32::from(i16::MIN)) as i16;
    let mut mask = 0u32;
    for j in 0..SCREEN_BLOCK {
        let [a, b, c, d, e, f] = faces.map(|face| face[j]);
        let (hi, lo) = (
            a.max(b).max(c).max(d).max(e).max(f),
            a.min(b).min(c).min(d).min(e).min(f),
        );
        let v = v[j];
        let hit = (v > high && v > hi) || (v < low && v < lo);
        mask |= u32::from(hit) << j;
    }
    Some(mask)
}

/// The 3x3x3 DoG cube around column `x` (`1 <= x`) of `planes[s][row]`; samples past a
/// row's end (none for `x < w - 1`) read as 0.
#[inline(always)]
fn cube(planes: &[[&[i16]; 3]; 3], x: usize) -> Cube {
    let mut c: Cube = [[[0; 3]; 3]; 3];
    for (cs, plane) in c.iter_mut().zip(planes) {
        for (cr, row) in cs.iter_mut().zip(plane) {
            for (v, i) in cr.iter_mut().zip(x - 1..) {
                *v = row.get(i).copied().unwrap_or(0);
            }
        }
    }
    c
}
