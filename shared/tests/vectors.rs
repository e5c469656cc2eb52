//! The test vectors of `docs/wire-format.md`, read from the document itself, so the spec and
//! the code cannot drift: every vector block in the document must have a value here and
//! every value here a block there, and both the packet and the frame bytes must match.
//!
//! A vector block in the document looks like
//! ````text
//! ```wire-vector NAME
//! packet: 01 03 ...      (header, payload, CRC: before COBS)
//!         ...            (continuation lines: more hex)
//! frame:  ...            (COBS bytes and the 0x00 delimiter: what is on the wire)
//! ```
//! ````
//! The fuzz seed corpus (`fuzz/corpus/decoder/vector-NAME`) holds the same frames; set
//! `STEREOCAL_BLESS_CORPUS=1` to rewrite it after changing a vector.

use std::collections::BTreeMap;
use std::path::Path;

use stereocal_wire::{
    decode, encode, Camera, Capabilities, EncodersRepr, ErrorCode, ErrorReportRepr, FrameEndFlags,
    FrameEndRepr, FrameStartRepr, HelloRepr, LogRepr, PacketRepr, Point, PointBatchRepr, Records,
    RegisterReadRepr, RegisterValueRepr, RegisterWriteRepr, SobelPatchRepr, SobelPixel,
    SobelRowsRepr, Source, MAX_ENCODED_LEN, PATCH_PIXELS,
};

const SPEC: &str = include_str!("../docs/wire-format.md");

const POINTS: [Point; 2] = [
    Point {
        x: 320,
        y: 240,
        octave: 0,
        scale: 1,
        dx: 0x1000,
        dy: -0x1000,
        ds: 0,
        dog: 300,
    },
    Point {
        x: 10,
        y: 20,
        octave: 3,
        scale: 1,
        dx: i16::MAX,
        dy: i16::MIN,
        ds: 0x2000,
        dog: -100,
    },
];

const ROW: [SobelPixel; 4] = [
    SobelPixel {
        magnitude: 0,
        orientation: 0,
    },
    SobelPixel {
        magnitude: 1,
        orientation: 16,
    },
    SobelPixel {
        magnitude: 128,
        orientation: 32,
    },
    SobelPixel {
        magnitude: 255,
        orientation: 63,
    },
];

/// The patch of the `sobel_patch` vector: pixel `i` has magnitude `i` and orientation `i % 64`.
fn patch() -> [SobelPixel; PATCH_PIXELS] {
    std::array::from_fn(|i| SobelPixel {
        magnitude: i as u8,
        orientation: (i % 64) as u8,
    })
}

/// Every vector: name → (source, sequence number, packet).
fn vectors(patch: &[SobelPixel]) -> BTreeMap<&'static str, (Source, u16, PacketRepr<'_>)> {
    BTreeMap::from([
        (
            "hello",
            (
                Source::Control,
                0x0001,
                PacketRepr::Hello(HelloRepr {
                    version: 2,
                    capabilities: Capabilities::POINTS
                        | Capabilities::SOBEL_PATCHES
                        | Capabilities::LOG
                        | Capabilities::REGISTERS,
                }),
            ),
        ),
        (
            "register_write",
            (
                Source::Control,
                0x0002,
                PacketRepr::RegisterWrite(RegisterWriteRepr {
                    addr: 0x0104,
                    value: 0x0000_0020,
                }),
            ),
        ),
        (
            "register_read",
            (
                Source::Control,
                0x0003,
                PacketRepr::RegisterRead(RegisterReadRepr { addr: 0x0104 }),
            ),
        ),
        (
            "register_value",
            (
                Source::Control,
                0x0001,
                PacketRepr::RegisterValue(RegisterValueRepr {
                    addr: 0x0104,
                    value: 0x0000_0020,
                }),
            ),
        ),
        (
            "frame_start",
            (
                Source::Right,
                0x0100,
                PacketRepr::FrameStart(FrameStartRepr {
                    frame_id: 42,
                    camera: Camera::Right,
                    width: 640,
                    height: 480,
                    octaves: 4,
                    timestamp_us: 1_000_000,
                }),
            ),
        ),
        (
            "point_batch",
            (
                Source::Right,
                0x0101,
                PacketRepr::PointBatch(PointBatchRepr {
                    frame_id: 42,
                    camera: Camera::Right,
                    points: Records::Values(&POINTS),
                }),
            ),
        ),
        (
            "sobel_rows",
            (
                Source::Left,
                0x0201,
                PacketRepr::SobelRows(SobelRowsRepr {
                    frame_id: 42,
                    camera: Camera::Left,
                    octave: 3,
                    scale: 1,
                    row: 59,
                    x: 36,
                    pixels: Records::Values(&ROW),
                }),
            ),
        ),
        (
            "sobel_patch",
            (
                Source::Right,
                0x0103,
                PacketRepr::SobelPatch(SobelPatchRepr {
                    frame_id: 42,
                    camera: Camera::Right,
                    point_index: 1,
                    octave: 3,
                    scale: 1,
                    x: 10,
                    y: 20,
                    pixels: Records::Values(patch),
                }),
            ),
        ),
        (
            "frame_end",
            (
                Source::Right,
                0x0104,
                PacketRepr::FrameEnd(FrameEndRepr {
                    frame_id: 42,
                    camera: Camera::Right,
                    point_count: 2,
                    sobel_count: 1,
                    flags: FrameEndFlags::POINT_FIFO_OVERFLOW | FrameEndFlags::SOBEL_FIFO_OVERFLOW,
                    dropped_points: 3,
                    dropped_sobel: 1280,
                }),
            ),
        ),
        (
            "encoders",
            (
                Source::Control,
                0x0002,
                PacketRepr::Encoders(EncodersRepr {
                    frame_id: 42,
                    left_yaw_udeg: 7_500_000,
                    right_yaw_udeg: -1_250_000,
                }),
            ),
        ),
        (
            "log",
            (
                Source::Control,
                0x0003,
                PacketRepr::Log(LogRepr {
                    frame: &[0x01, 0x00, 0x2a, 0x00],
                }),
            ),
        ),
        (
            "error_report",
            (
                Source::Control,
                0x0004,
                PacketRepr::ErrorReport(ErrorReportRepr {
                    code: ErrorCode::UnknownRegister,
                    detail: 0x9000,
                }),
            ),
        ),
        (
            "camera_unknown",
            (
                Source::Unknown(0x08),
                0xffff,
                PacketRepr::FrameStart(FrameStartRepr {
                    frame_id: u32::MAX,
                    camera: Camera::Unknown(0x07),
                    width: 1280,
                    height: 960,
                    octaves: 0,
                    timestamp_us: u64::MAX,
                }),
            ),
        ),
    ])
}

/// Packet and frame bytes of one vector block.
#[derive(Debug, Default, PartialEq)]
struct Block {
    packet: Vec<u8>,
    frame: Vec<u8>,
}

/// Reads every ```` ```wire-vector NAME ```` block of the spec.
fn spec_blocks() -> BTreeMap<String, Block> {
    let mut blocks = BTreeMap::new();
    let mut lines = SPEC.lines();
    while let Some(line) = lines.next() {
        let Some(name) = line.trim().strip_prefix("```wire-vector ") else {
            continue;
        };
        let mut block = Block::default();
        let mut target = None;
        for line in lines.by_ref() {
            let line = line.trim();
            if line == "```" {
                break;
            }
            let hex = if let Some(rest) = line.strip_prefix("packet:") {
                target = Some(&mut block.packet);
                rest
            } else if let Some(rest) = line.strip_prefix("frame:") {
                target = Some(&mut block.frame);
                rest
            } else {
                line
            };
            let out = target
                .as_mut()
                .unwrap_or_else(|| panic!("vector {name}: hex before a label"));
            for token in hex.split_whitespace() {
                let byte = u8::from_str_radix(token, 16)
                    .unwrap_or_else(|_| panic!("vector {name}: {token:?} is not a hex byte"));
                out.push(byte);
            }
        }
        assert!(
            blocks.insert(name.to_string(), block).is_none(),
            "vector {name} appears twice"
        );
    }
    blocks
}

/// The block as it must appear in the spec (printed when a vector does not match).
fn render(name: &str, block: &Block) -> String {
    let mut text = format!("```wire-vector {name}\n");
    for (label, bytes) in [("packet:", &block.packet), ("frame: ", &block.frame)] {
        for (i, line) in bytes.chunks(16).enumerate() {
            let hex: Vec<String> = line.iter().map(|b| format!("{b:02x}")).collect();
            let lead = if i == 0 { label } else { "       " };
            text += &format!("{lead} {}\n", hex.join(" "));
        }
    }
    text + "```\n"
}

fn encoded(source: Source, seq: u16, repr: &PacketRepr<'_>) -> Block {
    let mut buf = [0u8; MAX_ENCODED_LEN];
    let frame = encode(source, seq, repr, &mut buf)
        .expect("vector encodes")
        .to_vec();
    let mut packet = vec![0u8; frame.len()];
    let len = cobs::decode(&frame, &mut packet)
        .expect("own frame is valid COBS")
        .frame_size();
    packet.truncate(len);
    Block { packet, frame }
}

#[test]
fn spec_vectors_match_the_code() {
    let patch = patch();
    let vectors = vectors(&patch);
    let blocks = spec_blocks();
    let mut report = String::new();
    for (name, (source, seq, repr)) in &vectors {
        let expected = encoded(*source, *seq, repr);
        match blocks.get(*name) {
            Some(block) if *block == expected => {
                let mut frame = block.frame.clone();
                let (header, decoded) = decode(&mut frame).expect("spec frame decodes");
                assert_eq!(
                    (header.source, header.seq),
                    (*source, *seq),
                    "vector {name}"
                );
                assert_eq!(&decoded, repr, "vector {name}");
            }
            _ => report += &render(name, &expected),
        }
    }
    for name in blocks.keys() {
        if !vectors.contains_key(name.as_str()) {
            report += &format!("spec vector `{name}` has no value in tests/vectors.rs\n");
        }
    }
    assert!(
        report.is_empty(),
        "spec vectors differ from the code; the code's blocks:\n{report}"
    );
}

#[test]
fn fuzz_corpus_holds_the_vector_frames() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/decoder");
    let patch = patch();
    let bless = std::env::var_os("STEREOCAL_BLESS_CORPUS").is_some();
    let mut all = Vec::new();
    let mut stale = Vec::new();
    let mut seeds: Vec<(String, Vec<u8>)> = vectors(&patch)
        .iter()
        .map(|(name, (source, seq, repr))| {
            let frame = encoded(*source, *seq, repr).frame;
            all.extend_from_slice(&frame);
            (format!("vector-{name}"), frame)
        })
        .collect();
    seeds.push(("vector-all-kinds-stream".to_string(), all));
    for (file, bytes) in seeds {
        let path = dir.join(&file);
        if bless {
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(&path, &bytes).unwrap();
        } else if std::fs::read(&path).ok().as_deref() != Some(&bytes[..]) {
            stale.push(file);
        }
    }
    assert!(
        stale.is_empty(),
        "fuzz seeds missing or stale: {stale:?}; rerun with STEREOCAL_BLESS_CORPUS=1"
    );
}
