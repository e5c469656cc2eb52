//! The last rows of every octave's Sobel image, assembled from the fabric's Sobel stream.
//!
//! The fabric streams Sobel pixels in raster order within each octave (octaves interleaved
//! clock by clock).
//! The ring keeps the last [`RING_ROWS`] complete rows of each octave: enough for a full row
//! to be sent as `SobelRows`, or for a 16x16 patch to be cut around a point that arrives up to
//! `RING_ROWS - 17` rows after the Sobel row it sits on (the fabric's points lag its Sobel rows
//! by the DoG pipeline's few rows; see `patch.rs`).
//!
//! A row is complete when its last pixel arrives, or, if the fabric dropped that pixel on a
//! full FIFO, when the next row starts or the frame ends. Missing pixels read as zero (no
//! gradient); the drops are counted by the fabric and reported in `FrameEnd`.

use core::ops::Range;

use stereocal_wire::{SobelPixel, PATCH_PIXELS, PATCH_SIZE};

use crate::fabric::config::MAX_OCTAVES;
use crate::fabric::geometry::octave_dims;
use crate::fabric::{SobelEntry, SobelRun};

/// Complete rows kept per octave.
pub const RING_ROWS: usize = 32;
/// Rows of `W0` pixels the ring stores. Octave `k` needs `RING_ROWS` rows of `ceil(w / 2^k)`
/// for a `w <= W0` wide frame, and `sum_k ceil(w / 2^k) <= 2 * W0 + 2` (for `W0 >= 5`), so
/// `RING_ROWS * (2 * W0 + 2) <= (2 * RING_ROWS + 4) * W0` once `W0 >= RING_ROWS / 2`.
const STORE_ROWS: usize = 2 * RING_ROWS + 4;

/// Where one octave's rows live and how far its stream got.
#[derive(Clone, Copy, Debug)]
pub struct OctaveRows {
    width: u16,
    height: u16,
    /// Flat index of the octave's first slot.
    base: usize,
    /// Rows before this one are complete.
    next_row: u16,
    /// Whether `next_row` already has pixels.
    open: bool,
    /// Pixels received into each slot since it was opened.
    filled: [u16; RING_ROWS],
}

impl OctaveRows {
    const EMPTY: Self = Self {
        width: 0,
        height: 0,
        base: 0,
        next_row: 0,
        open: false,
        filled: [0; RING_ROWS],
    };

    /// Width and height of the octave's image.
    pub fn dims(&self) -> (u16, u16) {
        (self.width, self.height)
    }

    /// Rows before this one are complete.
    pub fn next_row(&self) -> u16 {
        self.next_row
    }

    /// The oldest complete row still held.
    pub fn oldest_row(&self) -> u16 {
        (self.next_row + u16::from(self.open)).saturating_sub(RING_ROWS as u16)
    }

    /// Flat store indices of `row`'s slot.
    fn slot(&self, row: u16) -> Range<usize> {
        let width = usize::from(self.width);
        let start = self.base + (usize::from(row) % RING_ROWS) * width;
        start..start + width
    }

    /// Pixels received into `row`'s slot (`RING_ROWS` is a power of two: the index is
    /// in range by construction).
    fn filled(&mut self, row: u16) -> &mut u16 {
        &mut self.filled[usize::from(row) % RING_ROWS]
    }
}

/// A Sobel pixel the ring cannot place.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OutOfOrder {
    /// The pixel's octave.
    pub octave: u8,
    /// Its column.
    pub x: u16,
    /// Its row.
    pub y: u16,
}

/// Rows of one octave that a push or [`SobelRing::finish`] completed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Completed {
    /// The octave.
    pub octave: u8,
    /// The rows, in order.
    pub rows: Range<u16>,
}

/// The ring of Sobel rows of a front end whose octave 0 is at most `W0` pixels wide.
///
/// Nothing here can panic on what the fabric sends: octave numbers, positions and slots are
/// looked up with `get`, and a pixel that finds no place is an [`OutOfOrder`] error.
pub struct SobelRing<const W0: usize> {
    store: [[SobelPixel; W0]; STORE_ROWS],
    octaves: [OctaveRows; MAX_OCTAVES],
    active: u8,
}

impl<const W0: usize> SobelRing<W0> {
    /// An empty ring.
    pub const fn new() -> Self {
        const {
            assert!(
                W0 >= RING_ROWS / 2,
                "the ring packs every octave into STORE_ROWS rows of W0"
            );
            assert!(RING_ROWS.is_power_of_two());
        };
        Self {
            store: [[SobelPixel {
                magnitude: 0,
                orientation: 0,
            }; W0]; STORE_ROWS],
            octaves: [OctaveRows::EMPTY; MAX_OCTAVES],
            active: 0,
        }
    }

    /// Prepares for a `width` x `height` frame of `octaves` octaves (`width <= W0`,
    /// `octaves <= 4`, both checked by the caller; a wider frame would find no slots and its
    /// pixels would be refused, not stored out of place).
    pub fn start(&mut self, width: u16, height: u16, octaves: u8) {
        let mut base = 0;
        self.active = octaves;
        for (k, rows) in self.octaves.iter_mut().enumerate() {
            let (w, h) = octave_dims(width, height, k as u8);
            *rows = OctaveRows {
                width: w,
                height: h,
                base,
                ..OctaveRows::EMPTY
            };
            base += RING_ROWS * usize::from(w);
        }
    }

    /// Octave `k` of the current frame, if it has one.
    pub fn rows(&self, octave: u8) -> Option<&OctaveRows> {
        self.octaves
            .get(usize::from(octave))
            .filter(|_| octave < self.active)
    }

    /// Stores one pixel of the fabric's Sobel stream and reports the rows it completed.
    pub fn push(&mut self, pixel: &SobelEntry) -> Result<Option<Completed>, OutOfOrder> {
        let out_of_order = OutOfOrder {
            octave: pixel.octave,
            x: pixel.x,
            y: pixel.y,
        };
        let active = self.active;
        let rows = self
            .octaves
            .get_mut(usize::from(pixel.octave))
            .filter(|_| pixel.octave < active)
            .ok_or(out_of_order)?;
        if pixel.x >= rows.width || pixel.y >= rows.height || pixel.y < rows.next_row {
            return Err(out_of_order);
        }
        // Rows before the pixel's own are complete, whether or not they got pixels.
        let first = rows.next_row;
        if pixel.y > rows.next_row || !rows.open {
            open_row(self.store.as_flattened_mut(), rows, pixel.y);
        }
        let cell = rows.slot(pixel.y).start + usize::from(pixel.x);
        let cell = self
            .store
            .as_flattened_mut()
            .get_mut(cell)
            .ok_or(out_of_order)?;
        *cell = SobelPixel {
            magnitude: pixel.magnitude,
            orientation: pixel.orientation,
        };
        let filled = rows.filled(pixel.y);
        *filled = filled.saturating_add(1);
        let end = if pixel.x + 1 == rows.width {
            rows.next_row = pixel.y + 1;
            rows.open = false;
            pixel.y + 1
        } else {
            rows.next_row = pixel.y;
            rows.open = true;
            pixel.y
        };
        Ok((end > first).then_some(Completed {
            octave: pixel.octave,
            rows: first..end,
        }))
    }

    /// Stores the leading pixels of `run` (at least one, when it is not empty) and reports
    /// how many it took and the rows they completed; exactly as [`Self::push`] on each of them,
    /// one at a time, would.
    ///
    /// The first pixel goes through [`Self::push`]. If it completed no row, it opened (or
    /// continued) its row, so the pixels after it, up to the row's last column, cannot fail
    /// and can only complete the row with its last column: they are copied as a block. Pixels
    /// past the row's end go through [`Self::push`] on the next call, so their error is
    /// reported as it would be pixel by pixel.
    pub fn push_run(
        &mut self,
        run: &SobelRun<'_>,
    ) -> Result<(usize, Option<Completed>), OutOfOrder> {
        let Some(first) = run.pixels().next() else {
            return Ok((0, None));
        };
        if let Some(completed) = self.push(&first)? {
            return Ok((1, Some(completed)));
        }
        let Some(rows) = self.octaves.get_mut(usize::from(first.octave)) else {
            return Ok((1, None));
        };
        // `push` accepted `first` without completing its row: `first.x + 1 < rows.width`.
        let room = usize::from(rows.width.saturating_sub(first.x + 1));
        let rest = run.split_at(1).1.split_at(room).0;
        let start = rows.slot(first.y).start + usize::from(first.x) + 1;
        let Some(cells) = self
            .store
            .as_flattened_mut()
            .get_mut(start..start + rest.len())
        else {
            return Ok((1, None));
        };
        for (cell, (&magnitude, &orientation)) in cells
            .iter_mut()
            .zip(rest.magnitude.iter().zip(rest.orientation))
        {
            *cell = SobelPixel {
                magnitude,
                orientation,
            };
        }
        // `rest.len() < rows.width`, a `u16`.
        let added = rest.len() as u16;
        let filled = rows.filled(first.y);
        *filled = filled.saturating_add(added);
        let completed = (first.x + added + 1 == rows.width).then(|| {
            rows.next_row = first.y + 1;
            rows.open = false;
            Completed {
                octave: first.octave,
                rows: first.y..first.y + 1,
            }
        });
        Ok((1 + rest.len(), completed))
    }

    /// Completes each octave's open row at the end of a frame.
    pub fn finish(&mut self) -> [Option<Completed>; MAX_OCTAVES] {
        let mut done = [const { None }; MAX_OCTAVES];
        let active = usize::from(self.active);
        for (k, (rows, done)) in self.octaves.iter_mut().zip(done.iter_mut()).enumerate() {
            if k < active && rows.open {
                *done = Some(Completed {
                    octave: k as u8,
                    rows: rows.next_row..rows.next_row + 1,
                });
                rows.next_row += 1;
                rows.open = false;
            }
        }
        done
    }

    /// A complete row that is still held and received at least one pixel.
    pub fn row(&self, octave: u8, row: u16) -> Option<&[SobelPixel]> {
        let rows = self.rows(octave)?;
        let held = row >= rows.oldest_row() && row < rows.next_row;
        let filled = rows.filled[usize::from(row) % RING_ROWS] > 0;
        if !(held && filled) {
            return None;
        }
        self.store.as_flattened().get(rows.slot(row))
    }

    /// Copies the patch whose top-left corner is (`left`, `top`) (in octave pixels, possibly
    /// outside the image) into `out`, row-major; pixels outside the image or in rows not held
    /// read as zero.
    pub fn window(&self, octave: u8, left: i32, top: i32, out: &mut [SobelPixel; PATCH_PIXELS]) {
        for (dy, out_row) in out.chunks_exact_mut(PATCH_SIZE).enumerate() {
            out_row.fill(SobelPixel::default());
            let y = top.saturating_add(dy as i32);
            let Some(row) = u16::try_from(y).ok().and_then(|y| self.row(octave, y)) else {
                continue;
            };
            for (dx, pixel) in out_row.iter_mut().enumerate() {
                let x = left.saturating_add(dx as i32);
                if let Some(p) = usize::try_from(x).ok().and_then(|x| row.get(x)) {
                    *pixel = *p;
                }
            }
        }
    }
}

/// Clears the slot of `row` and the slots of the empty rows skipped before it.
fn open_row(store: &mut [SobelPixel], rows: &mut OctaveRows, row: u16) {
    let from = if rows.open {
        rows.next_row + 1
    } else {
        rows.next_row
    };
    // Only the last RING_ROWS rows can still be read; older slots are reused anyway.
    let from = from.max(row.saturating_sub(RING_ROWS as u16 - 1));
    for r in from..=row {
        if let Some(slot) = store.get_mut(rows.slot(r)) {
            slot.fill(SobelPixel::default());
        }
        *rows.filled(r) = 0;
    }
}

impl<const W0: usize> Default for SobelRing<W0> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use std::vec::Vec;

    use super::*;
    use crate::fabric::sobel_fifo::SobelFifo;

    #[test]
    fn push_run_reports_what_pixel_by_pixel_pushes_report() {
        let px = |octave: u8, x: u16, y: u16| SobelEntry {
            octave,
            orientation: (x % 64) as u8,
            magnitude: (y % 251) as u8 + 1,
            x,
            y,
        };
        // Octave 0 is 20 wide, octave 1 is 10 wide: whole rows, rows with gaps, octaves
        // interleaved mid-row, a skipped row, an octave the frame lacks, columns going back, a row
        // gone by and a column past the edge.
        let mut stream: Vec<SobelEntry> = (0..20).map(|x| px(0, x, 0)).collect();
        stream.extend((0..6).map(|x| px(1, x, 0)));
        stream.extend((0..20).filter(|&x| x != 9).map(|x| px(0, x, 1)));
        stream.extend((6..10).map(|x| px(1, x, 0)));
        stream.extend((3..19).map(|x| px(0, x, 2)));
        stream.extend((0..20).map(|x| px(0, x, 4)));
        stream.extend((5..8).map(|x| px(0, x, 5)));
        stream.push(px(2, 0, 0));
        stream.extend((8..12).map(|x| px(0, x, 5)));
        stream.extend([px(0, 13, 5), px(0, 12, 5), px(0, 14, 5)]);
        stream.extend([px(0, 3, 2), px(0, 20, 6), px(0, 15, 5), px(0, 16, 5)]);

        // Per pixel: the pixel each completion or error came after.
        let mut single = SobelRing::<20>::new();
        single.start(20, 12, 2);
        let mut expected = Vec::new();
        for (i, p) in stream.iter().enumerate() {
            match single.push(p) {
                Ok(Some(c)) => expected.push((i, Ok(c))),
                Ok(None) => {}
                Err(e) => expected.push((i, Err(e))),
            }
        }

        // In runs, as the Sobel FIFO groups the stream, going on after an error as the per-pixel
        // loop did.
        let mut fifo: SobelFifo<64, 2> = SobelFifo::new();
        for p in &stream {
            fifo.push(*p).expect("the stream fits");
        }
        let mut runs = SobelRing::<20>::new();
        runs.start(20, 12, 2);
        let mut got = Vec::new();
        let mut next = 0;
        let mut queued = 0;
        fifo.drain(usize::MAX, &mut |mut run| {
            queued += 1;
            while !run.is_empty() {
                match runs.push_run(&run) {
                    Ok((taken, completed)) => {
                        assert!(taken >= 1);
                        next += taken;
                        run = run.split_at(taken).1;
                        if let Some(c) = completed {
                            got.push((next - 1, Ok(c)));
                        }
                    }
                    Err(e) => {
                        got.push((next, Err(e)));
                        next += 1;
                        run = run.split_at(1).1;
                    }
                }
            }
        });
        assert!(queued < stream.len(), "some pixels form runs");
        assert_eq!(got, expected);
        assert!(expected.iter().any(|(_, r)| r.is_err()));
        for octave in 0..2 {
            for row in 0..12 {
                assert_eq!(
                    single.row(octave, row),
                    runs.row(octave, row),
                    "{octave} {row}"
                );
            }
            let (a, b) = (single.rows(octave).unwrap(), runs.rows(octave).unwrap());
            assert_eq!(
                (a.next_row(), a.oldest_row()),
                (b.next_row(), b.oldest_row())
            );
        }
    }
}
