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
use crate::fabric::fast::probe::Probe;
use crate::fabric::geometry::octave_dims;
use crate::fabric::output::{Extremum, OutputFifos};
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
    magnitude: [u8; W],
    orientation: [u8; W],
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
            magnitude: [0; W],
            orientation: [0; W],
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
    pub(crate) fn tick<const W0: usize, P: Probe>(
        &mut self,
        input: Option<&[u16]>,
        out: &mut OutputFifos<W0>,
        probe: &mut P,
    ) -> bool {
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

        self.sobel_tick(out);

        self.sub_len = 0;
        if let Some(r) = emitted[3] {
            self.dog_and_extrema(r, out, probe);
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
    fn sobel_tick<const W0: usize>(&mut self, out: &mut OutputFifos<W0>) {
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
        cordic_row(
            &self.sx[..w],
            &self.sy[..w],
            &mut self.magnitude[..w],
            &mut self.orientation[..w],
        );
        out.push_sobel_row(self.index, r, &self.magnitude[..w], &self.orientation[..w]);
        self.sobel_rows += 1;
    }

    /// DoG row `r`, then the extremum scan of row `r - 1`.
    fn dog_and_extrema<const W0: usize, P: Probe>(
        &mut self,
        r: u16,
        out: &mut OutputFifos<W0>,
        probe: &mut P,
    ) {
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
        let thr = self.config.contrast_threshold as i32;
        for x in 1..w - 1 {
            // Necessary conditions first (contrast, then the four direct neighbours), so the
            // 26-neighbour test only runs on the few survivors; the verdict is unchanged.
            let row = &self.dog[1][rows[1]];
            let v = row[x] as i32;
            let (l, r) = (row[x - 1] as i32, row[x + 1] as i32);
            let (u, d) = (
                self.dog[1][rows[0]][x] as i32,
                self.dog[1][rows[2]][x] as i32,
            );
            let maybe = if v > thr {
                l < v && r < v && u < v && d < v
            } else if v < -thr {
                l > v && r > v && u > v && d > v
            } else {
                false
            };
            if !maybe {
                continue;
            }
            let mut c: Cube = [[[0; 3]; 3]; 3];
            for (s, plane) in c.iter_mut().enumerate() {
                for (row, &y) in plane.iter_mut().zip(&rows) {
                    let d = &self.dog[s][y];
                    *row = [d[x - 1], d[x], d[x + 1]];
                }
            }
            if !is_extremum(&c, self.config.contrast_threshold)
                || !passes_edge_test(&c[1], self.config.edge_ratio)
            {
                continue;
            }
            if let Some([dx, dy, ds]) = refine(&c, self.config.max_offset) {
                out.push_point(Extremum {
                    x: x as u16,
                    y: yc,
                    octave: self.index,
                    scale: 1,
                    dx,
                    dy,
                    ds,
                    dog: c[1][1][1],
                });
            }
        }
    }
}
