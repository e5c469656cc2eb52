//! Driver tests on the host, on the register path: the driver drives the fabric's device model
//! ([`FabricDevice`]) through its registers and PIXEL_IN, over a scripted datapath that emits
//! exactly the points and Sobel pixels a test needs, or over the real fast path and
//! register-level model.

extern crate std;

use std::collections::{BTreeMap, VecDeque};
use std::vec;
use std::vec::Vec;

use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_hdl::{register_at, regs, FabricConfig, PixelIn, RegisterBus};
use stereocal_wire::{
    decode, Camera, ErrorCode, FrameEndFlags, Header, HelloRepr, PacketRepr, Point,
    RegisterReadRepr, RegisterWriteRepr, SobelPixel, Source, PATCH_PIXELS,
};

use super::*;
use crate::fabric::geometry::octave_dims;
use crate::fabric::refine::Offset;
use crate::fabric::stream::{wire_point, OutOfOrder, MAX_PENDING, RING_ROWS};
use crate::fabric::{
    Config, ConfigError, Extremum, FabricDevice, FabricModel, FrameError, FrontEnd, Overflow,
    SobelEntry, SobelRun,
};
use crate::framing::{ByteSink, PacketWriter};

/// A sink that keeps every byte.
#[derive(Default)]
struct Collect(Vec<u8>);

impl ByteSink for Collect {
    fn write(&mut self, bytes: &[u8]) {
        self.0.extend_from_slice(bytes);
    }
}

/// A device whose stream engine's link is a [`Collect`].
trait Collected {
    /// Takes what the link collected.
    fn take_sent(&mut self) -> Vec<u8>;
}

impl<F: FrontEnd, const W0: usize> Collected for FabricDevice<F, W0, Collect> {
    fn take_sent(&mut self) -> Vec<u8> {
        core::mem::take(&mut self.link_mut().0)
    }
}

impl<D: Collected> Collected for Watched<D> {
    fn take_sent(&mut self) -> Vec<u8> {
        self.device.take_sent()
    }
}

/// What the driver's fabric sent on its link since the last call.
fn sent<B: RegisterBus + PixelIn + Collected, const W0: usize>(
    driver: &mut Driver<B, W0>,
) -> Vec<u8> {
    driver.bus_mut().take_sent()
}

/// A decoded packet, owned.
#[derive(Clone, Debug, PartialEq)]
enum Packet {
    Hello(HelloRepr),
    Value {
        addr: u16,
        value: u32,
    },
    Error {
        code: ErrorCode,
        detail: u32,
    },
    Start {
        frame_id: u32,
        camera: Camera,
        width: u16,
        height: u16,
        octaves: u8,
        timestamp_us: u64,
    },
    Points {
        frame_id: u32,
        points: Vec<Point>,
    },
    Row {
        frame_id: u32,
        octave: u8,
        scale: u8,
        row: u16,
        pixels: Vec<SobelPixel>,
    },
    Patch {
        frame_id: u32,
        index: u16,
        octave: u8,
        x: u16,
        y: u16,
        pixels: Vec<SobelPixel>,
    },
    End(stereocal_wire::FrameEndRepr),
}

/// Decodes every frame of `bytes`; also checks that a frame's packets come from its camera's
/// channel and the others from control, and that each source numbers its packets from 0
/// without a gap.
fn decode_all(bytes: &[u8]) -> Vec<Packet> {
    let mut packets = Vec::new();
    let mut next_seq = BTreeMap::new();
    for frame in bytes.split_inclusive(|&b| b == 0) {
        let mut frame = frame.to_vec();
        let (header, repr): (Header, PacketRepr<'_>) = decode(&mut frame).expect("decodes");
        let camera = match repr {
            PacketRepr::FrameStart(p) => Some(p.camera),
            PacketRepr::PointBatch(p) => Some(p.camera),
            PacketRepr::SobelRows(p) => Some(p.camera),
            PacketRepr::SobelPatch(p) => Some(p.camera),
            PacketRepr::FrameEnd(p) => Some(p.camera),
            _ => None,
        };
        assert_eq!(
            header.source,
            camera.map_or(Source::Control, Source::channel),
            "{repr:?}"
        );
        let seq = next_seq.entry(header.source).or_insert(0u16);
        assert_eq!(header.seq, *seq, "sequence numbers have no gap");
        *seq = seq.wrapping_add(1);
        packets.push(match repr {
            PacketRepr::Hello(h) => Packet::Hello(h),
            PacketRepr::RegisterValue(v) => Packet::Value {
                addr: v.addr,
                value: v.value,
            },
            PacketRepr::ErrorReport(e) => Packet::Error {
                code: e.code,
                detail: e.detail,
            },
            PacketRepr::FrameStart(s) => Packet::Start {
                frame_id: s.frame_id,
                camera: s.camera,
                width: s.width,
                height: s.height,
                octaves: s.octaves,
                timestamp_us: s.timestamp_us,
            },
            PacketRepr::PointBatch(b) => Packet::Points {
                frame_id: b.frame_id,
                points: b.points.iter().collect(),
            },
            PacketRepr::SobelRows(r) => Packet::Row {
                frame_id: r.frame_id,
                octave: r.octave,
                scale: r.scale,
                row: r.row,
                pixels: r.pixels.iter().collect(),
            },
            PacketRepr::SobelPatch(p) => Packet::Patch {
                frame_id: p.frame_id,
                index: p.point_index,
                octave: p.octave,
                x: p.x,
                y: p.y,
                pixels: p.pixels.iter().collect(),
            },
            PacketRepr::FrameEnd(e) => Packet::End(e),
            other => panic!("unexpected packet {other:?}"),
        });
    }
    packets
}

/// The Sobel pixel the scripted front end emits at (x, y) of octave k.
fn scripted_pixel(octave: u8, x: u16, y: u16) -> SobelPixel {
    SobelPixel {
        magnitude: ((u32::from(x) * 7 + u32::from(y) * 13 + u32::from(octave) * 31) % 251 + 1)
            as u8,
        orientation: ((x + 3 * y + u16::from(octave)) % 64) as u8,
    }
}

fn extremum(octave: u8, x: u16, y: u16) -> Extremum {
    Extremum {
        x,
        y,
        octave,
        scale: 1,
        dx: Offset::from_bits(100),
        dy: Offset::from_bits(-200),
        ds: Offset::from_bits(0),
        dog: 512,
    }
}

/// A front end that emits Sobel row `r` of octave `k` after input row `(r + 1) * 2^k - 1`
/// (every pixel, from [`scripted_pixel`], except the ones listed in `drop`), and each scripted
/// point after its input row (rows past the frame: during blanking).
#[derive(Default)]
struct Scripted {
    config: Option<Config>,
    rows_in: u16,
    points: Vec<(u16, Extremum)>,
    drop: Vec<(u8, u16, u16)>,
    dropped_points: u32,
    point_fifo: VecDeque<Extremum>,
    sobel_fifo: VecDeque<SobelEntry>,
    overflow: Overflow,
    blank_rows: u16,
}

impl Scripted {
    fn emit_points_for(&mut self, input_row: u16) {
        for &(row, p) in &self.points {
            if row == input_row {
                self.point_fifo.push_back(p);
            }
        }
    }
}

impl FrontEnd for Scripted {
    fn start_frame(&mut self, config: &Config) -> Result<(), ConfigError> {
        self.config = Some(*config);
        self.rows_in = 0;
        self.blank_rows = 0;
        self.overflow.points += self.dropped_points;
        Ok(())
    }

    fn reset(&mut self) {
        self.config = None;
        self.point_fifo.clear();
        self.sobel_fifo.clear();
        self.overflow = Overflow::default();
    }

    fn push_row(&mut self, row: &[u8]) -> Result<(), FrameError> {
        let c = self.config.ok_or(FrameError::NotStarted)?;
        assert_eq!(row.len(), usize::from(c.width));
        let r = self.rows_in;
        for k in 0..c.octaves {
            let step = 1u16 << k;
            let (w, h) = octave_dims(c.width, c.height, k);
            if r % step == step - 1 && r / step < h {
                let y = r / step;
                for x in 0..w {
                    if self.drop.contains(&(k, x, y)) {
                        self.overflow.sobel += 1;
                        continue;
                    }
                    let p = scripted_pixel(k, x, y);
                    self.sobel_fifo.push_back(SobelEntry {
                        octave: k,
                        orientation: p.orientation,
                        magnitude: p.magnitude,
                        x,
                        y,
                    });
                }
            }
        }
        self.emit_points_for(r);
        self.rows_in += 1;
        Ok(())
    }

    fn blank_row(&mut self) -> bool {
        let c = self.config.expect("started");
        self.emit_points_for(c.height + self.blank_rows);
        self.blank_rows += 1;
        self.frame_done()
    }

    fn frame_done(&self) -> bool {
        self.blank_rows >= 64
    }

    fn pop_point(&mut self) -> Option<Extremum> {
        self.point_fifo.pop_front()
    }

    fn pop_sobel(&mut self) -> Option<SobelEntry> {
        self.sobel_fifo.pop_front()
    }

    fn overflow(&self) -> Overflow {
        self.overflow
    }

    fn point_level(&self) -> usize {
        self.point_fifo.len()
    }

    fn sobel_level(&self) -> usize {
        self.sobel_fifo.len()
    }

    fn drain_points(&mut self, sink: &mut dyn FnMut(&[Extremum])) {
        let (a, b) = self.point_fifo.as_slices();
        sink(a);
        sink(b);
        self.point_fifo.clear();
    }

    fn drain_sobel(&mut self, max: usize, sink: &mut dyn FnMut(SobelRun<'_>)) {
        let n = max.min(self.sobel_fifo.len());
        self.sobel_fifo
            .drain(..n)
            .for_each(|p| sink(SobelRun::single(&p)));
    }

    fn drain_sobel_by_octave(
        &mut self,
        _stash: &mut [[u32; 2]],
        sink: &mut dyn FnMut(SobelRun<'_>),
    ) {
        for octave in 0..4 {
            self.sobel_fifo
                .iter()
                .filter(|p| p.octave == octave)
                .for_each(|p| sink(SobelRun::single(p)));
        }
        self.sobel_fifo.clear();
    }
}

type ScriptedDriver = Driver<Watched<FabricDevice<Scripted, 64, Collect>>, 64>;

/// A fabric's bus as an MMIO bus is: every burst read word by word. It counts accesses to
/// offsets where no register lives.
struct Watched<D> {
    device: D,
    unmapped: u32,
}

impl<D> Watched<D> {
    fn new(device: D) -> Self {
        Self {
            device,
            unmapped: 0,
        }
    }

    fn watch(&mut self, offset: u16) {
        if offset % 4 != 0 || register_at(offset).is_none() {
            self.unmapped += 1;
        }
    }
}

impl<D: RegisterBus> RegisterBus for Watched<D> {
    fn read(&mut self, offset: u16) -> u32 {
        self.watch(offset);
        self.device.read(offset)
    }

    fn write(&mut self, offset: u16, value: u32) {
        self.watch(offset);
        self.device.write(offset, value)
    }
}

impl<D: PixelIn> PixelIn for Watched<D> {
    fn push(&mut self, pixels: &[u8], start_of_frame: bool) {
        self.device.push(pixels, start_of_frame)
    }

    fn idle(&mut self, clocks: u32) {
        self.device.idle(clocks)
    }
}

fn scripted_driver(script: Scripted, config: &FabricConfig) -> std::boxed::Box<ScriptedDriver> {
    let mut driver = std::boxed::Box::new(Driver::new(
        Watched::new(FabricDevice::with_link(script, Collect::default())),
        Camera::Right,
    ));
    driver.configure(config).expect("valid configuration");
    driver
}

const SMALL: FabricConfig = FabricConfig {
    width: 48,
    height: 40,
    octaves: 2,
    contrast_threshold: 8 << 8,
    edge_ratio: 10,
    sobel_output: SobelOutput::Patches,
    sobel_scale: 1,
    points_per_batch: 16,
    row_segment: 1280,
    max_offset: 4096,
};

/// The patch a point at (x, y) of `octave` must get: the scripted image, zero outside it and
/// where pixels were dropped.
fn expected_patch(
    config: &FabricConfig,
    octave: u8,
    x: u16,
    y: u16,
    drop: &[(u8, u16, u16)],
) -> Vec<SobelPixel> {
    let (w, h) = octave_dims(config.width, config.height, octave);
    let mut out = Vec::new();
    for dy in 0..16i32 {
        for dx in 0..16i32 {
            let (px, py) = (i32::from(x) - 8 + dx, i32::from(y) - 8 + dy);
            let inside = (0..i32::from(w)).contains(&px) && (0..i32::from(h)).contains(&py);
            let (px, py) = (px as u16, py as u16);
            out.push(if inside && !drop.contains(&(octave, px, py)) {
                scripted_pixel(octave, px, py)
            } else {
                SobelPixel::default()
            });
        }
    }
    out
}

#[test]
fn frame_packets_come_in_order_with_consecutive_sequence_numbers_of_their_channel() {
    let script = Scripted {
        points: vec![(12, extremum(0, 20, 10)), (30, extremum(1, 5, 6))],
        ..Scripted::default()
    };
    let mut driver = scripted_driver(script, &SMALL);
    let image = vec![0u8; 48 * 40];
    let first = driver.process_frame(&image, 1234).unwrap();
    let second = driver.process_frame(&image, 5678).unwrap();
    assert_eq!((first.frame_id, second.frame_id), (0, 1));
    assert_eq!(first.points, 2);
    assert_eq!(first.sobel_packets, 2);

    let packets = decode_all(&sent(&mut driver));
    let per_frame = packets.len() / 2;
    assert_eq!(
        packets[0],
        Packet::Start {
            frame_id: 0,
            camera: Camera::Right,
            width: 48,
            height: 40,
            octaves: 2,
            timestamp_us: 1234
        }
    );
    assert!(matches!(
        packets[per_frame],
        Packet::Start {
            frame_id: 1,
            timestamp_us: 5678,
            ..
        }
    ));
    let frame0 = &packets[..per_frame];
    // Start, two patches (sent as their rows complete), one point batch (at frame end), End.
    assert_eq!(frame0.len(), 5);
    assert!(matches!(
        frame0[1],
        Packet::Patch {
            index: 0,
            octave: 0,
            x: 20,
            y: 10,
            ..
        }
    ));
    assert!(matches!(
        frame0[2],
        Packet::Patch {
            index: 1,
            octave: 1,
            x: 5,
            y: 6,
            ..
        }
    ));
    let Packet::Points {
        frame_id: 0,
        points,
    } = &frame0[3]
    else {
        panic!("{:?}", frame0[3])
    };
    assert_eq!(points.len(), 2);
    assert_eq!(
        (
            points[0].x,
            points[0].y,
            points[0].dx,
            points[0].dy,
            points[0].dog
        ),
        (20, 10, 100, -200, 512)
    );
    let Packet::End(end) = &frame0[4] else {
        panic!("{:?}", frame0[4])
    };
    assert_eq!(
        (end.frame_id, end.camera, end.point_count, end.sobel_count),
        (0, Camera::Right, 2, 2)
    );
    assert_eq!(
        (end.flags, end.dropped_points, end.dropped_sobel),
        (FrameEndFlags(0), 0, 0)
    );
}

#[test]
fn rows_mode_sends_every_row_of_every_octave_once() {
    let config = FabricConfig {
        sobel_output: SobelOutput::Rows,
        octaves: 3,
        ..SMALL
    };
    let mut driver = scripted_driver(Scripted::default(), &config);
    let summary = driver.process_frame(&vec![0u8; 48 * 40], 0).unwrap();
    let packets = decode_all(&sent(&mut driver));
    let mut seen = Vec::new();
    for p in &packets {
        if let Packet::Row {
            frame_id,
            octave,
            scale,
            row,
            pixels,
        } = p
        {
            assert_eq!((*frame_id, *scale), (0, 1));
            let (w, _) = octave_dims(48, 40, *octave);
            let expected: Vec<_> = (0..w).map(|x| scripted_pixel(*octave, x, *row)).collect();
            assert_eq!(pixels, &expected, "octave {octave} row {row}");
            seen.push((*octave, *row));
        }
    }
    let mut expected = Vec::new();
    for k in 0..3 {
        let (_, h) = octave_dims(48, 40, k);
        expected.extend((0..h).map(|r| (k, r)));
    }
    seen.sort();
    assert_eq!(seen, expected);
    assert_eq!(summary.sobel_packets as usize, expected.len());
}

#[test]
fn patches_at_the_borders_are_zero_outside_the_image() {
    // Corners and edges of octave 0 (48x40) and octave 1 (24x20), and an odd-size octave 2.
    let config = FabricConfig {
        octaves: 3,
        width: 48,
        height: 36,
        ..SMALL
    };
    let points = [
        (0, 0, 0),
        (0, 47, 0),
        (0, 0, 35),
        (0, 47, 35),
        (0, 8, 8),
        (0, 7, 28),
        (1, 23, 17),
        (1, 0, 9),
        (2, 11, 8),
    ];
    let script = Scripted {
        // Each point arrives two input rows after its octave's Sobel row (a realistic lag).
        points: points
            .iter()
            .map(|&(k, x, y)| (((y + 3) << k).min(36 + 5), extremum(k, x, y)))
            .collect(),
        ..Scripted::default()
    };
    let mut driver = scripted_driver(script, &config);
    let summary = driver.process_frame(&vec![0u8; 48 * 36], 0).unwrap();
    assert_eq!(summary.patches_dropped, 0);
    let patches: Vec<_> = decode_all(&sent(&mut driver))
        .into_iter()
        .filter_map(|p| match p {
            Packet::Patch {
                index,
                octave,
                x,
                y,
                pixels,
                ..
            } => Some((index, octave, x, y, pixels)),
            _ => None,
        })
        .collect();
    assert_eq!(patches.len(), points.len());
    for (index, octave, x, y, pixels) in patches {
        assert_eq!(pixels.len(), PATCH_PIXELS);
        // Points arrive in row order, so match by position rather than arrival.
        assert!(points.contains(&(octave, x, y)), "index {index}");
        assert_eq!(
            pixels,
            expected_patch(&config, octave, x, y, &[]),
            "point ({x}, {y}) of octave {octave}"
        );
    }
}

#[test]
fn fifo_overflow_is_counted_and_flagged() {
    let drop = vec![(0, 47, 3), (0, 0, 12), (0, 1, 12), (1, 10, 2)];
    let script = Scripted {
        points: vec![(14, extremum(0, 2, 12))],
        drop: drop.clone(),
        dropped_points: 3,
        ..Scripted::default()
    };
    let mut driver = scripted_driver(script, &SMALL);
    let summary = driver.process_frame(&vec![0u8; 48 * 40], 0).unwrap();
    assert_eq!(
        summary.overflow,
        Overflow {
            points: 3,
            sobel: 4
        }
    );
    let packets = decode_all(&sent(&mut driver));
    let Some(Packet::End(end)) = packets.last() else {
        panic!()
    };
    assert_eq!((end.dropped_points, end.dropped_sobel), (3, 4));
    assert!(end.flags.contains(FrameEndFlags::POINT_FIFO_OVERFLOW));
    assert!(end.flags.contains(FrameEndFlags::SOBEL_FIFO_OVERFLOW));
    // The patch over the dropped pixels has zeros there (row 3 lost its last pixel, so that
    // row was completed by the next row's start).
    let patch = packets.iter().find_map(|p| match p {
        Packet::Patch { pixels, .. } => Some(pixels.clone()),
        _ => None,
    });
    assert_eq!(patch, Some(expected_patch(&SMALL, 0, 2, 12, &drop)));
}

#[test]
fn rows_whose_pixels_were_all_dropped_are_not_sent() {
    let config = FabricConfig {
        sobel_output: SobelOutput::Rows,
        octaves: 1,
        ..SMALL
    };
    let drop: Vec<_> = (0..48).map(|x| (0, x, 7)).collect();
    let script = Scripted {
        drop,
        ..Scripted::default()
    };
    let mut driver = scripted_driver(script, &config);
    let summary = driver.process_frame(&vec![0u8; 48 * 40], 0).unwrap();
    assert_eq!(summary.sobel_packets, 39);
    let packets = decode_all(&sent(&mut driver));
    assert!(!packets
        .iter()
        .any(|p| matches!(p, Packet::Row { row: 7, .. })));
    let Some(Packet::End(end)) = packets.last() else {
        panic!()
    };
    assert_eq!((end.sobel_count, end.dropped_sobel), (39, 48));
}

#[test]
fn points_too_late_for_the_ring_or_the_queue_are_counted() {
    // A point arriving when its top row has left the 32-row ring gets no patch.
    let late = (10 + 8 + RING_ROWS as u16, extremum(0, 5, 10));
    // One input row brings more points than the queue holds; they wait for rows 9..=25.
    let burst: Vec<_> = (0..MAX_PENDING as u16 + 5)
        .map(|i| (2, extremum(0, i % 48, 17)))
        .collect();
    let script = Scripted {
        points: [vec![late], burst].concat(),
        ..Scripted::default()
    };
    let mut driver = scripted_driver(script, &SMALL);
    let summary = driver.process_frame(&vec![0u8; 48 * 40], 0).unwrap();
    assert_eq!(summary.points, MAX_PENDING as u32 + 6);
    assert_eq!(summary.patches_dropped, 1 + 5);
    assert_eq!(summary.sobel_packets, MAX_PENDING as u32);
    let packets = decode_all(&sent(&mut driver));
    let Some(Packet::End(end)) = packets.last() else {
        panic!()
    };
    assert_eq!(
        (end.dropped_sobel, end.point_count),
        (6, MAX_PENDING as u32 + 6)
    );
    assert!(end.flags.contains(FrameEndFlags::SOBEL_FIFO_OVERFLOW));
    assert!(!end.flags.contains(FrameEndFlags::POINT_FIFO_OVERFLOW));
    // 518 points go out in batches of the configured 16 (OUTPUT_MODE.POINTS_PER_BATCH).
    let batches: Vec<_> = packets
        .iter()
        .filter_map(|p| match p {
            Packet::Points { points, .. } => Some(points.len()),
            _ => None,
        })
        .collect();
    let mut expected = vec![16; 518 / 16];
    expected.push(518 % 16);
    assert_eq!(batches, expected);
}

#[test]
fn host_packets_are_answered() {
    let mut driver = scripted_driver(Scripted::default(), &SMALL);
    let mut link = PacketWriter::new(Collect::default());
    let requests = [
        PacketRepr::Hello(HelloRepr {
            version: 1,
            capabilities: stereocal_wire::Capabilities(0),
        }),
        PacketRepr::RegisterWrite(RegisterWriteRepr {
            addr: regs::contrast_threshold::OFFSET,
            value: 21,
        }),
        PacketRepr::RegisterRead(RegisterReadRepr {
            addr: regs::contrast_threshold::OFFSET,
        }),
        PacketRepr::RegisterRead(RegisterReadRepr {
            addr: regs::width::OFFSET,
        }),
        PacketRepr::RegisterRead(RegisterReadRepr {
            addr: regs::version::OFFSET,
        }),
        PacketRepr::RegisterWrite(RegisterWriteRepr {
            addr: 0x00FC,
            value: 1,
        }),
        PacketRepr::RegisterRead(RegisterReadRepr { addr: 0x0006 }),
        PacketRepr::FrameEnd(stereocal_wire::FrameEndRepr {
            frame_id: 0,
            camera: Camera::Left,
            point_count: 0,
            sobel_count: 0,
            flags: FrameEndFlags(0),
            dropped_points: 0,
            dropped_sobel: 0,
        }),
        PacketRepr::ErrorReport(stereocal_wire::ErrorReportRepr {
            code: ErrorCode::Busy,
            detail: 0,
        }),
    ];
    for request in &requests {
        driver.handle_host_packet(request, &mut link).unwrap();
    }
    assert_eq!(
        decode_all(&link.sink().0),
        [
            Packet::Hello(HelloRepr {
                version: stereocal_wire::PROTOCOL_VERSION,
                capabilities: CHANNEL_CAPABILITIES
            }),
            Packet::Value {
                addr: regs::contrast_threshold::OFFSET,
                value: 21
            },
            Packet::Value {
                addr: regs::width::OFFSET,
                value: 48
            },
            Packet::Value {
                addr: regs::version::OFFSET,
                value: regs::version::RESET
            },
            Packet::Error {
                code: ErrorCode::UnknownRegister,
                detail: 0x00FC
            },
            Packet::Error {
                code: ErrorCode::UnknownRegister,
                detail: 0x0006
            },
            Packet::Error {
                code: ErrorCode::UnexpectedKind,
                detail: 0x14
            },
        ]
    );
    assert_eq!(
        driver.bus().unmapped,
        0,
        "unmapped addresses never reach the bus"
    );
}

#[test]
fn bad_configuration_or_image_sends_nothing() {
    let mut driver = scripted_driver(Scripted::default(), &SMALL);
    assert_eq!(
        driver.process_frame(&[0u8; 10], 0),
        Err(DriverError::ImageSize {
            expected: 48 * 40,
            got: 10
        })
    );
    // Width 49 is not a multiple of 2, as two octaves need.
    driver.bus_mut().write(regs::width::OFFSET, 49);
    let err = driver.process_frame(&vec![0u8; 49 * 40], 0).unwrap_err();
    assert!(matches!(
        err,
        DriverError::Registers(stereocal_hdl::Error::FrameNotDivisible { .. })
    ));
    assert_eq!(
        err.report(),
        (ErrorCode::InvalidConfig, u32::from(regs::width::OFFSET))
    );
    driver.bus_mut().write(regs::width::OFFSET, 96);
    assert!(matches!(
        driver.process_frame(&vec![0u8; 96 * 40], 0),
        Err(DriverError::TooWide { width: 96, max: 64 })
    ));
    assert!(sent(&mut driver).is_empty());
    assert_eq!(driver.next_frame_id(), 0, "refused frames take no number");
}

#[test]
fn a_fabric_emitting_out_of_order_is_an_error() {
    struct Backwards(Scripted);
    impl FrontEnd for Backwards {
        fn start_frame(&mut self, c: &Config) -> Result<(), ConfigError> {
            self.0.start_frame(c)
        }
        fn push_row(&mut self, row: &[u8]) -> Result<(), FrameError> {
            self.0.push_row(row)?;
            // Re-send the first pixel of the row just emitted.
            if let Some(&p) = self.0.sobel_fifo.front() {
                self.0.sobel_fifo.push_back(p);
            }
            Ok(())
        }
        fn reset(&mut self) {
            self.0.reset()
        }
        fn blank_row(&mut self) -> bool {
            self.0.blank_row()
        }
        fn frame_done(&self) -> bool {
            self.0.frame_done()
        }
        fn pop_point(&mut self) -> Option<Extremum> {
            self.0.pop_point()
        }
        fn pop_sobel(&mut self) -> Option<SobelEntry> {
            self.0.pop_sobel()
        }
        fn overflow(&self) -> Overflow {
            self.0.overflow()
        }
        fn point_level(&self) -> usize {
            self.0.point_level()
        }
        fn sobel_level(&self) -> usize {
            self.0.sobel_level()
        }
        fn drain_points(&mut self, sink: &mut dyn FnMut(&[Extremum])) {
            self.0.drain_points(sink)
        }
        fn drain_sobel(&mut self, max: usize, sink: &mut dyn FnMut(SobelRun<'_>)) {
            self.0.drain_sobel(max, sink)
        }
        fn drain_sobel_by_octave(
            &mut self,
            stash: &mut [[u32; 2]],
            sink: &mut dyn FnMut(SobelRun<'_>),
        ) {
            self.0.drain_sobel_by_octave(stash, sink)
        }
    }
    let mut driver: Driver<FabricDevice<Backwards, 64, Collect>, 64> = Driver::new(
        FabricDevice::with_link(Backwards(Scripted::default()), Collect::default()),
        Camera::Left,
    );
    driver.configure(&SMALL).unwrap();
    let err = driver.process_frame(&vec![0u8; 48 * 40], 0).unwrap_err();
    assert_eq!(
        err,
        DriverError::SobelOutOfOrder(OutOfOrder {
            octave: 0,
            x: 0,
            y: 0
        })
    );
}

/// A 8-bit image with dark and bright blobs on a gentle gradient: plenty of DoG extrema.
fn blob_image(width: usize, height: usize, seed: u32) -> Vec<u8> {
    let mut state = seed;
    let mut next = move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1u32 << 24) as f32
    };
    let blobs: Vec<(f32, f32, f32, f32)> = (0..width * height / 100)
        .map(|_| {
            let sign = if next() < 0.5 { -1.0 } else { 1.0 };
            (
                next() * width as f32,
                next() * height as f32,
                1.2 + next() * 2.5,
                sign * (40.0 + next() * 60.0),
            )
        })
        .collect();
    let mut image = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let mut v = 100.0 + 40.0 * x as f32 / width as f32;
            for &(cx, cy, r, a) in &blobs {
                let d2 = (x as f32 - cx).powi(2) + (y as f32 - cy).powi(2);
                if d2 < 16.0 * r * r {
                    v += a * (-d2 / (2.0 * r * r)).exp();
                }
            }
            image.push(v.clamp(0.0, 255.0) as u8);
        }
    }
    image
}

/// Points and full Sobel images of every octave, straight from the fast path.
struct Reference {
    points: Vec<Extremum>,
    sobel: Vec<Vec<Vec<SobelPixel>>>,
}

fn reference(config: &FabricConfig, image: &[u8]) -> Reference {
    let mut fe: std::boxed::Box<crate::fabric::FastFrontEnd<160, 80, 40, 20>> =
        std::boxed::Box::default();
    let mut sobel: Vec<Vec<Vec<SobelPixel>>> = (0..config.octaves)
        .map(|k| {
            let (w, h) = octave_dims(config.width, config.height, k);
            vec![vec![SobelPixel::default(); usize::from(w)]; usize::from(h)]
        })
        .collect();
    let mut points = Vec::new();
    let mut drain = |fe: &mut crate::fabric::FastFrontEnd<160, 80, 40, 20>| {
        while let Some(p) = fe.pop_point() {
            points.push(p);
        }
        while let Some(s) = fe.pop_sobel() {
            sobel[usize::from(s.octave)][usize::from(s.y)][usize::from(s.x)] = SobelPixel {
                magnitude: s.magnitude,
                orientation: s.orientation,
            };
        }
    };
    fe.start_frame(&Config::from(config)).unwrap();
    for row in image.chunks_exact(usize::from(config.width)) {
        fe.push_row(row).unwrap();
        drain(&mut fe);
    }
    let flushed = (0..4 * usize::from(config.height) + 64).any(|_| {
        let done = fe.blank_row();
        drain(&mut fe);
        done
    });
    assert!(flushed);
    assert_eq!(fe.overflow(), Overflow::default());
    Reference { points, sobel }
}

fn window(image: &[Vec<SobelPixel>], x: u16, y: u16) -> Vec<SobelPixel> {
    let mut out = Vec::new();
    for py in i32::from(y) - 8..i32::from(y) + 8 {
        for px in i32::from(x) - 8..i32::from(x) + 8 {
            let pixel = usize::try_from(py)
                .ok()
                .and_then(|py| image.get(py))
                .and_then(|row| usize::try_from(px).ok().and_then(|px| row.get(px)));
            out.push(pixel.copied().unwrap_or_default());
        }
    }
    out
}

const TEXTURED: FabricConfig = FabricConfig {
    width: 160,
    height: 120,
    octaves: 3,
    contrast_threshold: 6 << 8,
    edge_ratio: 10,
    sobel_output: SobelOutput::Patches,
    sobel_scale: 1,
    points_per_batch: 16,
    row_segment: 1280,
    max_offset: 4096,
};

#[test]
fn fast_path_points_and_patches_match_its_sobel_images() {
    let image = blob_image(160, 120, 11);
    let reference = reference(&TEXTURED, &image);
    assert!(reference.points.len() >= 10, "the test image has features");
    let mut driver: std::boxed::Box<
        Driver<FabricDevice<FabricModel<160, 80, 40, 20>, 160, Collect>, 160>,
    > = std::boxed::Box::new(Driver::new(
        FabricDevice::with_link(FabricModel::fast(), Collect::default()),
        Camera::Left,
    ));
    driver.configure(&TEXTURED).unwrap();
    let summary = driver.process_frame(&image, 0).unwrap();
    assert_eq!(summary.patches_dropped, 0);
    assert_eq!(summary.points as usize, reference.points.len());

    let packets = decode_all(&sent(&mut driver));
    let sent: Vec<Point> = packets
        .iter()
        .filter_map(|p| match p {
            Packet::Points { points, .. } => Some(points.clone()),
            _ => None,
        })
        .flatten()
        .collect();
    let expected: Vec<Point> = reference.points.iter().map(wire_point).collect();
    assert_eq!(sent, expected);
    let mut patched = vec![false; sent.len()];
    for p in &packets {
        if let Packet::Patch {
            index,
            octave,
            x,
            y,
            pixels,
            ..
        } = p
        {
            let point = sent[usize::from(*index)];
            assert_eq!((point.octave, point.x, point.y), (*octave, *x, *y));
            assert_eq!(
                pixels,
                &window(&reference.sobel[usize::from(*octave)], *x, *y)
            );
            assert!(
                !std::mem::replace(&mut patched[usize::from(*index)], true),
                "one patch per point"
            );
        }
    }
    assert!(patched.iter().all(|&p| p), "every point got its patch");
}

#[test]
fn fast_path_rows_are_its_sobel_images() {
    let config = FabricConfig {
        sobel_output: SobelOutput::Rows,
        ..TEXTURED
    };
    let image = blob_image(160, 120, 5);
    let reference = reference(&config, &image);
    let mut driver: std::boxed::Box<
        Driver<FabricDevice<FabricModel<160, 80, 40, 20>, 160, Collect>, 160>,
    > = std::boxed::Box::new(Driver::new(
        FabricDevice::with_link(FabricModel::fast(), Collect::default()),
        Camera::Left,
    ));
    driver.configure(&config).unwrap();
    driver.process_frame(&image, 0).unwrap();
    let mut rows = 0;
    for p in decode_all(&sent(&mut driver)) {
        if let Packet::Row {
            octave,
            row,
            pixels,
            ..
        } = p
        {
            assert_eq!(
                pixels,
                reference.sobel[usize::from(octave)][usize::from(row)]
            );
            rows += 1;
        }
    }
    assert_eq!(rows, 120 + 60 + 30);
}

#[test]
fn register_level_model_sends_the_same_bytes_as_the_fast_path() {
    let config = FabricConfig {
        width: 64,
        height: 48,
        octaves: 2,
        contrast_threshold: 4 << 8,
        ..TEXTURED
    };
    let image = blob_image(64, 48, 2);
    let mut results = Vec::new();
    for model in [
        FabricModel::<64, 32, 16, 12>::fast(),
        FabricModel::register_level(),
    ] {
        let mut driver: std::boxed::Box<
            Driver<FabricDevice<FabricModel<64, 32, 16, 12>, 64, Collect>, 64>,
        > = std::boxed::Box::new(Driver::new(
            FabricDevice::with_link(model, Collect::default()),
            Camera::Left,
        ));
        driver.configure(&config).unwrap();
        let summary = driver.process_frame(&image, 0).unwrap();
        assert!(summary.points > 0);
        results.push(sent(&mut driver));
    }
    assert_eq!(results[0], results[1]);
}
