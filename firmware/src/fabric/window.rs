//! 3x3 window former (thesis fig. 4.7): two line buffers give the two rows above, a 3-deep
//! shift register of columns gives the horizontal neighbours. Borders are replicated by the
//! read multiplexers, so a window exists for every pixel (the extremum detector ignores the
//! border windows).
//!
//! Latency: the window of centre `(x, y)` is complete when sample `(x+1, y+1)` arrives
//! (`width + 1` samples later) and is registered: [`window_latency`] = `width + 2`.

use crate::fabric::geometry::{clamp_index, Raster};
use crate::fabric::linebuffer::LineBuffer;

/// Window former latency in enabled clocks.
pub const fn window_latency(width: u16) -> u32 {
    width as u32 + 2
}

/// A 3x3 neighbourhood `w[row][col]`, centre at `[1][1]`, with its centre position.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window3<T> {
    pub x: u16,
    pub y: u16,
    pub w: [[T; 3]; 3],
}

/// The window former.
#[derive(Clone, Debug)]
pub struct WindowFormer<T, const W: usize> {
    width: u16,
    height: u16,
    total: u32,
    lines: LineBuffer<T, W, 2>,
    /// Column vectors `[row y-2, y-1, y]`, `cols[0]` newest.
    cols: [[T; 3]; 3],
    pos: Raster,
    centre: Raster,
    taken: u32,
    emitted: u32,
    out: Option<Window3<T>>,
}

impl<T: Copy, const W: usize> WindowFormer<T, W> {
    /// Idle former; `fill` is the power-up memory content (never selected).
    pub const fn new(fill: T) -> Self {
        Self {
            width: 0,
            height: 0,
            total: 0,
            lines: LineBuffer::new(fill),
            cols: [[fill; 3]; 3],
            pos: Raster { x: 0, y: 0 },
            centre: Raster { x: 0, y: 0 },
            taken: 0,
            emitted: 0,
            out: None,
        }
    }

    /// Resets for a `width` x `height` frame.
    pub fn start(&mut self, width: u16, height: u16) {
        self.width = width;
        self.height = height;
        self.total = width as u32 * height as u32;
        self.lines.reset();
        self.pos = Raster::default();
        self.centre = Raster::default();
        self.taken = 0;
        self.emitted = 0;
        self.out = None;
    }

    /// Whether every window has been emitted.
    pub fn done(&self) -> bool {
        self.emitted == self.total && self.out.is_none()
    }

    /// One enabled clock: returns the output register, latches the next window.
    pub fn clock(&mut self, input: Option<T>) -> Option<Window3<T>> {
        let out = self.out.take();
        let sample = match input {
            Some(v) => v,
            None if self.taken >= self.total && self.emitted < self.total => self.cols[0][2],
            None => return out,
        };
        let x = self.pos.x as usize;
        let col = [self.lines.read(x, 2), self.lines.read(x, 1), sample];
        self.lines.write(x, sample);
        self.cols = [col, self.cols[0], self.cols[1]];
        self.taken += 1;
        if self.taken > self.width as u32 + 1 && self.emitted < self.total {
            let (xc, yc) = (self.centre.x as i32, self.centre.y as i32);
            let (xl, yl) = (self.width as i32 - 1, self.height as i32 - 1);
            let mut w = [[sample; 3]; 3];
            for (r, wr) in w.iter_mut().enumerate() {
                let row = clamp_index(yc + r as i32 - 1, yl);
                for (c, v) in wr.iter_mut().enumerate() {
                    let cx = clamp_index(xc + c as i32 - 1, xl);
                    // Column cx was formed xc + 1 - cx samples ago, holding rows yc-1..yc+1.
                    // Both indices are 0..=2 (cx and row are within one of the centre);
                    // `min` only rules out a panic path.
                    let (ci, ri) = ((xc + 1 - cx) as usize, (row - yc + 1) as usize);
                    *v = self.cols[ci.min(2)][ri.min(2)];
                }
            }
            self.out = Some(Window3 {
                x: self.centre.x,
                y: self.centre.y,
                w,
            });
            self.centre.advance(self.width);
            self.emitted += 1;
        }
        self.pos.advance(self.width);
        if self.pos.x == 0 {
            self.lines.next_row();
        }
        out
    }
}
