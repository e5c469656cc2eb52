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

/// Up to `limit` points (OUTPUT_MODE.POINTS_PER_BATCH, at most [`MAX_POINTS`]) waiting for
/// their packet.
pub struct PointBatch {
    points: Vec<Point, MAX_POINTS>,
    limit: usize,
}

impl PointBatch {
    /// An empty batch of the wire's largest size.
    pub const fn new() -> Self {
        Self {
            points: Vec::new(),
            limit: MAX_POINTS,
        }
    }

    /// Empties the batch and sets the frame's batch size, `limit` clamped to `1..=MAX_POINTS`.
    pub fn start(&mut self, limit: u8) {
        self.points.clear();
        self.limit = usize::from(limit).clamp(1, MAX_POINTS);
    }

    /// Adds a point; `true` when the batch is now full and must be sent.
    ///
    /// The caller sends and clears the batch on the push that fills it, so there is always
    /// room; a push onto a full batch would be refused (the point dropped) and answer `true`.
    pub fn push(&mut self, point: Point) -> bool {
        self.points.push(point).is_err() || self.points.len() >= self.limit
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
