//! Points from the fabric's point FIFO, collected into `PointBatch` packets.

use stereocal_wire::{Point, MAX_POINTS};

use crate::fabric::Extremum;

/// The wire record of a fabric point (the offsets keep their Q2.13 bits).
pub fn wire_point(p: &Extremum) -> Point {
    Point {
        x: p.x,
        y: p.y,
        octave: p.octave,
        scale: p.scale,
        dx: p.dx.to_bits(),
        dy: p.dy.to_bits(),
        ds: p.ds.to_bits(),
        dog: p.dog,
    }
}

/// Up to [`MAX_POINTS`] points waiting for their packet.
pub struct PointBatch {
    points: [Point; MAX_POINTS],
    len: usize,
}

impl PointBatch {
    /// An empty batch.
    pub const fn new() -> Self {
        Self {
            points: [Point {
                x: 0,
                y: 0,
                octave: 0,
                scale: 0,
                dx: 0,
                dy: 0,
                ds: 0,
                dog: 0,
            }; MAX_POINTS],
            len: 0,
        }
    }

    /// Adds a point; `true` when the batch is now full and must be sent.
    pub fn push(&mut self, point: Point) -> bool {
        self.points[self.len] = point;
        self.len += 1;
        self.len == MAX_POINTS
    }

    /// The points collected.
    pub fn points(&self) -> &[Point] {
        &self.points[..self.len]
    }

    /// Forgets the points (after they were sent).
    pub fn clear(&mut self) {
        self.len = 0;
    }
}

impl Default for PointBatch {
    fn default() -> Self {
        Self::new()
    }
}
