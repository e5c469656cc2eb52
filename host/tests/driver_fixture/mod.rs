//! Hand-built wire traffic for the driver and link tests: packets encoded with the wire
//! crate, each numbered as its source like the soft-core numbers them (a frame's packets as
//! its camera's channel, every other packet as control), with a record of where each one sits so
//! a test can drop, cut or corrupt exactly one.
#![allow(dead_code)] // each test binary uses part of the fixture

pub mod device;

use std::collections::BTreeMap;
use std::ops::Range;

use stereocal_wire::{
    encode, octave_dims, Camera, FrameEndFlags, FrameEndRepr, FrameStartRepr, LogRepr, PacketRepr,
    Point, PointBatchRepr, Records, SobelPatchRepr, SobelPixel, SobelRowsRepr, Source,
    MAX_ENCODED_LEN, MAX_POINTS, PATCH_PIXELS,
};

/// The Sobel pixel the fixture sends at octave pixel `(x, y)` of `octave`.
pub fn pattern(octave: u8, x: i32, y: i32) -> SobelPixel {
    SobelPixel {
        magnitude: (x * 7 + y * 13 + i32::from(octave) * 29).rem_euclid(256) as u8,
        orientation: (x + 3 * y + i32::from(octave)).rem_euclid(64) as u8,
    }
}

/// How a frame's gradients are sent.
#[derive(Clone, Debug)]
pub enum Sobel {
    None,
    /// Every row of every octave.
    Rows,
    /// Every row of every octave, cut into segments of this many pixels.
    Segments(u16),
    /// A patch for each listed point index, all before the points.
    Patches(Vec<u16>),
}

/// One camera frame to send.
#[derive(Clone, Debug)]
pub struct FrameSpec {
    pub frame_id: u32,
    pub camera: Camera,
    pub width: u16,
    pub height: u16,
    pub octaves: u8,
    pub timestamp_us: u64,
    pub points: Vec<Point>,
    pub sobel: Sobel,
}

impl FrameSpec {
    /// A 32x16 frame with 2 octaves and two points.
    pub fn small(frame_id: u32, camera: Camera) -> Self {
        Self {
            frame_id,
            camera,
            width: 32,
            height: 16,
            octaves: 2,
            timestamp_us: 1000 * u64::from(frame_id),
            points: vec![point(5, 6, 0, 4096, -2048), point(3, 4, 1, -4096, 2048)],
            sobel: Sobel::Rows,
        }
    }
}

pub fn point(x: u16, y: u16, octave: u8, dx: i16, dy: i16) -> Point {
    Point {
        x,
        y,
        octave,
        scale: 1,
        dx,
        dy,
        ds: 0,
        dog: 512,
    }
}

/// Wire bytes and where each packet sits in them.
#[derive(Default)]
pub struct Wire {
    pub bytes: Vec<u8>,
    pub packets: Vec<Range<usize>>,
    /// The next sequence number of each source.
    seq: BTreeMap<Source, u16>,
}

/// The source the device sends `packet` as: a frame's packets its camera's channel, any
/// other packet control.
pub fn source_of(packet: &PacketRepr<'_>) -> Source {
    let camera = match packet {
        PacketRepr::FrameStart(p) => p.camera,
        PacketRepr::PointBatch(p) => p.camera,
        PacketRepr::SobelRows(p) => p.camera,
        PacketRepr::SobelPatch(p) => p.camera,
        PacketRepr::FrameEnd(p) => p.camera,
        _ => return Source::Control,
    };
    Source::channel(camera)
}

impl Wire {
    pub fn new() -> Self {
        Self::default()
    }

    /// Sequence number the next packet of `source` gets.
    pub fn next_seq(&self, source: Source) -> u16 {
        self.seq.get(&source).copied().unwrap_or(0)
    }

    /// Uses up the next sequence number of `source`.
    fn take_seq(&mut self, source: Source) -> u16 {
        let next = self.seq.entry(source).or_insert(0);
        let seq = *next;
        *next = seq.wrapping_add(1);
        seq
    }

    /// Encodes `packet` with the next sequence number of its source.
    pub fn push(&mut self, packet: &PacketRepr<'_>) -> Range<usize> {
        let mut buf = [0u8; MAX_ENCODED_LEN];
        let source = source_of(packet);
        let seq = self.take_seq(source);
        let frame = encode(source, seq, packet, &mut buf).expect("fixture packets encode");
        let start = self.bytes.len();
        self.bytes.extend_from_slice(frame);
        let range = start..self.bytes.len();
        self.packets.push(range.clone());
        range
    }

    /// A packet the device numbered but the link lost.
    pub fn lose(&mut self, packet: &PacketRepr<'_>) {
        let mut buf = [0u8; MAX_ENCODED_LEN];
        let source = source_of(packet);
        let seq = self.take_seq(source);
        encode(source, seq, packet, &mut buf).expect("fixture packets encode");
    }

    /// Bytes that are no packet.
    pub fn raw(&mut self, bytes: &[u8]) {
        self.bytes.extend_from_slice(bytes);
    }

    pub fn log(&mut self, bytes: &[u8]) -> Range<usize> {
        self.push(&PacketRepr::Log(LogRepr { frame: bytes }))
    }

    /// All packets of a frame; returns the byte range of the whole frame. `lose` names
    /// packet indices (0 = FrameStart) the link loses.
    pub fn frame_losing(&mut self, spec: &FrameSpec, lose: &[usize]) -> Range<usize> {
        let start = self.bytes.len();
        let packets = frame_packets(spec);
        for (i, p) in packets.iter().enumerate() {
            let repr = p.repr();
            if lose.contains(&i) {
                self.lose(&repr);
            } else {
                self.push(&repr);
            }
        }
        start..self.bytes.len()
    }

    pub fn frame(&mut self, spec: &FrameSpec) -> Range<usize> {
        self.frame_losing(spec, &[])
    }
}

/// An owned packet of a frame (the wire reprs borrow their records).
pub enum Owned {
    Start(FrameStartRepr),
    Points(u32, Camera, Vec<Point>),
    /// Frame, camera, octave, row, first column, pixels.
    Row(u32, Camera, u8, u16, u16, Vec<SobelPixel>),
    Patch(u32, Camera, u16, Point, Vec<SobelPixel>),
    End(FrameEndRepr),
}

impl Owned {
    pub fn repr(&self) -> PacketRepr<'_> {
        match self {
            Owned::Start(s) => PacketRepr::FrameStart(*s),
            Owned::Points(id, camera, points) => PacketRepr::PointBatch(PointBatchRepr {
                frame_id: *id,
                camera: *camera,
                points: Records::Values(points),
            }),
            Owned::Row(id, camera, octave, row, x, pixels) => {
                PacketRepr::SobelRows(SobelRowsRepr {
                    frame_id: *id,
                    camera: *camera,
                    octave: *octave,
                    scale: 1,
                    row: *row,
                    x: *x,
                    pixels: Records::Values(pixels),
                })
            }
            Owned::Patch(id, camera, index, p, pixels) => PacketRepr::SobelPatch(SobelPatchRepr {
                frame_id: *id,
                camera: *camera,
                point_index: *index,
                octave: p.octave,
                scale: p.scale,
                x: p.x,
                y: p.y,
                pixels: Records::Values(pixels),
            }),
            Owned::End(e) => PacketRepr::FrameEnd(*e),
        }
    }
}

/// The packets the soft-core would send for `spec`, in order.
pub fn frame_packets(spec: &FrameSpec) -> Vec<Owned> {
    let (id, cam) = (spec.frame_id, spec.camera);
    let mut out = vec![Owned::Start(FrameStartRepr {
        frame_id: id,
        camera: cam,
        width: spec.width,
        height: spec.height,
        octaves: spec.octaves,
        timestamp_us: spec.timestamp_us,
    })];
    let mut sobel_count = 0;
    match &spec.sobel {
        Sobel::None => {}
        Sobel::Rows | Sobel::Segments(_) => {
            let segment = match spec.sobel {
                Sobel::Segments(s) => s,
                _ => u16::MAX,
            };
            for octave in 0..spec.octaves {
                let (w, h) = octave_dims(spec.width, spec.height, octave);
                for y in 0..h {
                    for x0 in (0..w).step_by(usize::from(segment)) {
                        let row = (x0..w.min(x0.saturating_add(segment)))
                            .map(|x| pattern(octave, i32::from(x), i32::from(y)))
                            .collect();
                        out.push(Owned::Row(id, cam, octave, y, x0, row));
                        sobel_count += 1;
                    }
                }
            }
        }
        Sobel::Patches(indices) => {
            for &i in indices {
                let p = spec.points[usize::from(i)];
                let (w, h) = octave_dims(spec.width, spec.height, p.octave);
                let pixels = (0..PATCH_PIXELS as i32)
                    .map(|k| {
                        let (x, y) = (i32::from(p.x) - 8 + k % 16, i32::from(p.y) - 8 + k / 16);
                        if x < 0 || y < 0 || x >= i32::from(w) || y >= i32::from(h) {
                            SobelPixel::default()
                        } else {
                            pattern(p.octave, x, y)
                        }
                    })
                    .collect();
                out.push(Owned::Patch(id, cam, i, p, pixels));
                sobel_count += 1;
            }
        }
    }
    for chunk in spec.points.chunks(MAX_POINTS) {
        out.push(Owned::Points(id, cam, chunk.to_vec()));
    }
    out.push(Owned::End(FrameEndRepr {
        frame_id: id,
        camera: cam,
        point_count: spec.points.len() as u32,
        sobel_count,
        flags: FrameEndFlags(0),
        dropped_points: 0,
        dropped_sobel: 0,
    }));
    out
}

impl Wire {
    /// An intact packet of a kind the host does not know (a newer device's) from `source`,
    /// numbered like the others. Built by hand because the wire crate only encodes kinds it
    /// knows.
    pub fn unknown_kind(&mut self, source: Source, kind: u8, payload: &[u8]) {
        let mut packet = vec![stereocal_wire::PROTOCOL_VERSION, kind, u8::from(source)];
        packet.extend_from_slice(&self.take_seq(source).to_le_bytes());
        packet.extend_from_slice(&(payload.len() as u16).to_le_bytes());
        packet.extend_from_slice(payload);
        let crc = stereocal_wire::crc32c(&packet);
        packet.extend_from_slice(&crc.to_le_bytes());
        let start = self.bytes.len();
        let mut encoded = vec![0u8; cobs::max_encoding_length(packet.len())];
        let n = cobs::encode(&packet, &mut encoded);
        self.bytes.extend_from_slice(&encoded[..n]);
        self.bytes.push(0);
        self.packets.push(start..self.bytes.len());
    }
}
