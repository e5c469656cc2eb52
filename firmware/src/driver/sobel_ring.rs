//! The last rows of every octave's Sobel image, assembled from the fabric's Sobel stream.
//!
//! The fabric streams Sobel pixels in raster order within each octave (octaves interleaved).
//! The ring keeps the last [`RING_ROWS`] complete rows of each octave: enough for a full row
//! to be sent as `SobelRows`, or for a 16x16 patch to be cut around a point that arrives up to
//! `RING_ROWS - 17` rows after the Sobel row it sits on (the fabric's points lag its Sobel rows
//! by the DoG pipeline's few rows; see `patch.rs`).
//!
//! A row is complete when its last pixel arrives, or, if the fabric dropped that pixel on a
//! full FIFO, when the next row starts or the frame ends. Missing pixels read as zero (no
//! gradient); the drops are counted by the fabric and reported in `FrameEnd`.

use core::ops::Range;

use stereocal_wire::SobelPixel;

use crate::fabric::config::MAX_OCTAVES;
use crate::fabric::geometry::octave_dims;
use crate::fabric::SobelPixel as FabricSobel;

/// Complete rows kept per octave.
pub const RING_ROWS: usize = 32;
/// Rows of `W0` pixels the ring stores. Octave `k` needs `RING_ROWS` rows of `ceil(w / 2^k)`
/// for a `w <= W0` wide frame, and `sum_k ceil(w / 2^k) <= 2 * W0 + 2` (for `W0 >= 5`), so
/// `RING_ROWS * (2 * W0 + 2) <= (2 * RING_ROWS + 4) * W0` once `W0 >= RING_ROWS / 2`.
const STORE_ROWS: usize = 2 * RING_ROWS + 4;

/// Where each octave's rows live and how far its stream got.
#[derive(Clone, Copy, Debug, Default)]
struct OctaveRows {
    width: u16,
    height: u16,
    /// Flat index of the octave's first slot.
    base: usize,
    /// Rows before this one are complete.
    next_row: u16,
    /// Whether `next_row` already has pixels.
    open: bool,
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
pub struct SobelRing<const W0: usize> {
    store: [[SobelPixel; W0]; STORE_ROWS],
    /// Pixels received into each slot since it was opened.
    filled: [[u16; RING_ROWS]; MAX_OCTAVES],
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
            )
        };
        Self {
            store: [[SobelPixel {
                magnitude: 0,
                orientation: 0,
            }; W0]; STORE_ROWS],
            filled: [[0; RING_ROWS]; MAX_OCTAVES],
            octaves: [OctaveRows {
                width: 0,
                height: 0,
                base: 0,
                next_row: 0,
                open: false,
            }; MAX_OCTAVES],
            active: 0,
        }
    }

    /// Prepares for a `width` x `height` frame of `octaves` octaves (`width <= W0`,
    /// `octaves <= 4`, both checked by the caller).
    pub fn start(&mut self, width: u16, height: u16, octaves: u8) {
        let mut base = 0;
        self.active = octaves;
        for (k, rows) in self.octaves.iter_mut().enumerate() {
            let (w, h) = octave_dims(width, height, k as u8);
            *rows = OctaveRows {
                width: w,
                height: h,
                base,
                next_row: 0,
                open: false,
            };
            base += RING_ROWS * usize::from(w);
        }
        debug_assert!(base <= STORE_ROWS * W0, "width {width} > W0 {W0}");
        self.filled = [[0; RING_ROWS]; MAX_OCTAVES];
    }

    /// Octaves of the current frame.
    pub fn octaves(&self) -> u8 {
        self.active
    }

    /// Width and height of octave `k`'s image.
    pub fn dims(&self, octave: u8) -> (u16, u16) {
        let rows = &self.octaves[usize::from(octave)];
        (rows.width, rows.height)
    }

    fn slot_range(&self, octave: u8, row: u16) -> Range<usize> {
        let rows = &self.octaves[usize::from(octave)];
        let width = usize::from(rows.width);
        let start = rows.base + (usize::from(row) % RING_ROWS) * width;
        start..start + width
    }

    /// Stores one pixel of the fabric's Sobel stream and reports the rows it completed.
    pub fn push(&mut self, pixel: &FabricSobel) -> Result<Option<Completed>, OutOfOrder> {
        let out_of_order = OutOfOrder {
            octave: pixel.octave,
            x: pixel.x,
            y: pixel.y,
        };
        if pixel.octave >= self.active {
            return Err(out_of_order);
        }
        let k = usize::from(pixel.octave);
        let OctaveRows {
            width,
            height,
            next_row,
            open,
            ..
        } = self.octaves[k];
        if pixel.x >= width || pixel.y >= height || pixel.y < next_row {
            return Err(out_of_order);
        }
        // Rows before the pixel's own are complete, whether or not they got pixels.
        let first = next_row;
        if pixel.y > next_row || !open {
            self.open_row(pixel.octave, pixel.y);
        }
        let slot = self.slot_range(pixel.octave, pixel.y);
        self.store.as_flattened_mut()[slot.start + usize::from(pixel.x)] = SobelPixel {
            magnitude: pixel.magnitude,
            orientation: pixel.orientation,
        };
        let filled = &mut self.filled[k][usize::from(pixel.y) % RING_ROWS];
        *filled = filled.saturating_add(1);
        let end = if pixel.x + 1 == width {
            self.octaves[k].next_row = pixel.y + 1;
            self.octaves[k].open = false;
            pixel.y + 1
        } else {
            self.octaves[k].next_row = pixel.y;
            self.octaves[k].open = true;
            pixel.y
        };
        Ok((end > first).then_some(Completed {
            octave: pixel.octave,
            rows: first..end,
        }))
    }

    /// Clears the slot of `row` and the slots of the empty rows skipped before it.
    fn open_row(&mut self, octave: u8, row: u16) {
        let k = usize::from(octave);
        let from = if self.octaves[k].open {
            self.octaves[k].next_row + 1
        } else {
            self.octaves[k].next_row
        };
        // Only the last RING_ROWS rows can still be read; older slots are reused anyway.
        let from = from.max(row.saturating_sub(RING_ROWS as u16 - 1));
        for r in from..=row {
            let slot = self.slot_range(octave, r);
            self.store.as_flattened_mut()[slot].fill(SobelPixel::default());
            self.filled[k][usize::from(r) % RING_ROWS] = 0;
        }
    }

    /// Completes each octave's open row at the end of a frame.
    pub fn finish(&mut self) -> [Option<Completed>; MAX_OCTAVES] {
        let mut done = [const { None }; MAX_OCTAVES];
        for (k, (rows, done)) in self.octaves.iter_mut().zip(done.iter_mut()).enumerate() {
            if k < usize::from(self.active) && rows.open {
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

    /// Rows of `octave` before this one are complete.
    pub fn next_row(&self, octave: u8) -> u16 {
        self.octaves[usize::from(octave)].next_row
    }

    /// The oldest complete row of `octave` still held.
    pub fn oldest_row(&self, octave: u8) -> u16 {
        let rows = &self.octaves[usize::from(octave)];
        (rows.next_row + u16::from(rows.open)).saturating_sub(RING_ROWS as u16)
    }

    /// A complete row that is still held and received at least one pixel.
    pub fn row(&self, octave: u8, row: u16) -> Option<&[SobelPixel]> {
        let k = usize::from(octave);
        let held = row >= self.oldest_row(octave) && row < self.octaves[k].next_row;
        let filled = self.filled[k][usize::from(row) % RING_ROWS] > 0;
        (held && filled).then(|| &self.store.as_flattened()[self.slot_range(octave, row)])
    }

    /// Copies the `size` x `size` window whose top-left corner is (`left`, `top`) (in octave
    /// pixels, possibly outside the image) into `out`, row-major; pixels outside the image or
    /// in rows not held read as zero.
    pub fn window(&self, octave: u8, left: i32, top: i32, size: usize, out: &mut [SobelPixel]) {
        let (width, _) = self.dims(octave);
        for (dy, out_row) in out.chunks_exact_mut(size).enumerate() {
            out_row.fill(SobelPixel::default());
            let y = top + dy as i32;
            let Some(row) = u16::try_from(y).ok().and_then(|y| self.row(octave, y)) else {
                continue;
            };
            let x0 = left.max(0);
            let x1 = (left + size as i32).min(i32::from(width));
            if x0 < x1 {
                let (x0, x1) = (x0 as usize, x1 as usize);
                let dest = (x0 as i32 - left) as usize;
                out_row[dest..dest + (x1 - x0)].copy_from_slice(&row[x0..x1]);
            }
        }
    }
}

impl<const W0: usize> Default for SobelRing<W0> {
    fn default() -> Self {
        Self::new()
    }
}
