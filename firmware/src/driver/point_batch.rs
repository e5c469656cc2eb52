//! Points from the fabric's point FIFO, collected into `PointBatch` packets.

use heapless::Vec;
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
    points: Vec<Point, MAX_POINTS>,
}

impl PointBatch {
    /// An empty batch.
    pub const fn new() -> Self {
        Self { points: Vec::new() }
    }

    /// Adds a point; `true` when the batch is now full and must be sent.
    ///
    /// The caller sends and clears the batch on the push that fills it, so there is always
    /// room; a push onto a full batch would be refused (the point dropped) and answer `true`.
    pub fn push(&mut self, point: Point) -> bool {
        self.points.push(point).is_err() || self.points.is_full()
    }

    /// The points collected.
    pub fn points(&self) -> &[Point] {
        &self.points
    }

    /// Forgets the points (after they were sent).
    pub fn clear(&mut self) {
        self.points.clear();
    }
}

impl Default for PointBatch {
    fn default() -> Self {
        Self::new()
    }
}
