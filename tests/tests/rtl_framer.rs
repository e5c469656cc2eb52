//! The stream engine's framer in RTL (`hdl-interface/rtl/sc_framer.v`) against the Rust
//! framer (`Framer::send`): the same packets, with and without forward error correction,
//! must give the same link frames byte for byte. The packets are the kinds the engine sends
//! with seeded random contents: Sobel rows of every width up to the wire's 1280 pixels (runs
//! of non-zero bytes across COBS's 254-byte blocks, rows full of zeros), point batches,
//! `FrameStart` and `FrameEnd`. The vectors are written fresh from the current Rust model
//! on every run and driven through Icarus Verilog (`hdl-interface/rtl/tb/tb_framer.v`), with
//! random gaps on the input and random stalls on the output. Without `iverilog` the test
//! prints a loud SKIPPED line and passes, except under `CI=true`, where it fails.

use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;

use stereocal_firmware::framing::{ByteSink, Framer, Numbering};
use stereocal_hil::rng::Rng;
use stereocal_wire::{
    Camera, FrameEndFlags, FrameEndRepr, FrameStartRepr, PacketRepr, Point, PointBatchRepr,
    Records, SobelPixel, SobelRowsRepr, Source,
};

/// Every byte written.
#[derive(Default)]
struct Collect(Vec<u8>);

impl ByteSink for Collect {
    fn write(&mut self, bytes: &[u8]) {
        self.0.extend_from_slice(bytes);
    }
}

/// The packet and CRC bytes a link frame without parity carries (COBS undone, delimiter
/// dropped).
fn cobs_decode(frame: &[u8]) -> Vec<u8> {
    let body = &frame[..frame.len() - 1];
    let mut out = Vec::new();
    let mut at = 0;
    while at < body.len() {
        let code = usize::from(body[at]);
        out.extend_from_slice(&body[at + 1..at + code]);
        at += code;
        if code != 255 && at < body.len() {
            out.push(0);
        }
    }
    out
}

/// Sobel pixels of a row: non-zero bytes only (long COBS blocks), zeros only, or mixed.
fn row(rng: &mut Rng, width: usize) -> Vec<SobelPixel> {
    let style = rng.below(3);
    (0..width)
        .map(|_| match style {
            0 => SobelPixel {
                magnitude: 1 + rng.below(255) as u8,
                orientation: 1 + rng.below(63) as u8,
            },
            1 => SobelPixel::default(),
            _ => SobelPixel {
                magnitude: (rng.below(4) * rng.below(256)) as u8,
                orientation: rng.below(64) as u8,
            },
        })
        .collect()
}

fn point(rng: &mut Rng) -> Point {
    Point {
        x: rng.below(1280) as u16,
        y: rng.below(1024) as u16,
        octave: rng.below(4) as u8,
        scale: 1,
        dx: rng.bits() as i16,
        dy: rng.bits() as i16,
        ds: rng.bits() as i16,
        dog: rng.bits() as i16,
    }
}

/// A frame id whose `FrameStart` (timestamp 0), numbered next by `numbering`, has a CRC
/// ending in a zero byte: COBS then ends the frame with an empty block.
fn zero_ending(framer: &mut Framer, numbering: Numbering) -> u32 {
    framer.set_fec(false);
    (0u32..)
        .find(|&frame_id| {
            let packet = PacketRepr::FrameStart(FrameStartRepr {
                frame_id,
                camera: Camera::Right,
                width: 640,
                height: 480,
                octaves: 4,
                timestamp_us: 0,
            });
            let (mut plain, mut probe) = (Collect::default(), numbering);
            framer.send(&mut plain, &mut probe, &packet).unwrap();
            cobs_decode(&plain.0).last() == Some(&0)
        })
        .unwrap_or(0)
}

/// The vector file: for each packet its bytes and the link frame `Framer::send` writes.
fn vectors() -> (String, usize) {
    let mut rng = Rng::new(0x5C_F4A3);
    let mut numbering = Numbering::new(Source::channel(Camera::Right));
    let mut framer = Framer::new();
    let mut text = String::new();
    let mut count = 0;
    // Widths around COBS's blocks (127 pixels = 254 bytes; 125 non-zero pixels and a CRC
    // without a zero end the packet with a full block), and random ones up to the limit.
    let mut widths: Vec<usize> = vec![1, 2, 124, 125, 126, 127, 128, 253, 254, 255, 1279, 1280];
    widths.extend((0..16).map(|_| 1 + rng.below(1280) as usize));
    let mut packets: Vec<(Vec<SobelPixel>, Vec<Point>, u64)> = Vec::new();
    for &width in &widths {
        packets.push((row(&mut rng, width), Vec::new(), 0));
    }
    for _ in 0..8 {
        let n = 1 + rng.below(128) as usize;
        packets.push((Vec::new(), (0..n).map(|_| point(&mut rng)).collect(), 1));
    }
    for kind in [2, 3] {
        for _ in 0..6 {
            packets.push((Vec::new(), Vec::new(), kind));
        }
    }
    packets.push((Vec::new(), Vec::new(), 4));
    for (pixels, points, kind) in &packets {
        let frame_id = if *kind == 4 {
            zero_ending(&mut framer, numbering)
        } else {
            rng.bits() as u32
        };
        let packet = match kind {
            0 => PacketRepr::SobelRows(SobelRowsRepr {
                frame_id,
                camera: Camera::Right,
                octave: rng.below(4) as u8,
                scale: 1,
                row: rng.below(1024) as u16,
                x: 0,
                pixels: Records::Values(pixels),
            }),
            1 => PacketRepr::PointBatch(PointBatchRepr {
                frame_id,
                camera: Camera::Right,
                points: Records::Values(points),
            }),
            2 | 4 => PacketRepr::FrameStart(FrameStartRepr {
                frame_id,
                camera: Camera::Right,
                width: 640,
                height: 480,
                octaves: 4,
                timestamp_us: if *kind == 4 { 0 } else { rng.bits() },
            }),
            _ => PacketRepr::FrameEnd(FrameEndRepr {
                frame_id,
                camera: Camera::Right,
                point_count: rng.below(5000) as u32,
                sobel_count: rng.below(5000) as u32,
                flags: FrameEndFlags(rng.below(4) as u8),
                dropped_points: rng.below(3) as u32,
                dropped_sobel: rng.below(3) as u32,
            }),
        };
        for fec in [false, true] {
            // The packet's bytes from the frame without parity, then the frame as sent.
            let mut plain = Collect::default();
            let mut probe = numbering;
            framer.set_fec(false);
            framer.send(&mut plain, &mut probe, &packet).unwrap();
            let with_crc = cobs_decode(&plain.0);
            if *kind == 4 && !fec {
                assert_eq!(with_crc.last(), Some(&0), "the packet's CRC ends in a zero");
            }
            let bytes = &with_crc[..with_crc.len() - 4];
            let mut sent = Collect::default();
            framer.set_fec(fec);
            framer.send(&mut sent, &mut numbering, &packet).unwrap();
            let hex = |b: &[u8]| {
                b.iter().fold(String::new(), |mut s, x| {
                    let _ = write!(s, " {x:02x}");
                    s
                })
            };
            let _ = writeln!(
                text,
                "{} {}{}\n{}{}",
                u8::from(fec),
                bytes.len(),
                hex(bytes),
                sent.0.len(),
                hex(&sent.0)
            );
            count += 1;
        }
    }
    (text, count)
}

#[test]
fn rtl_framer_sends_the_rust_framers_bytes() {
    let test = "rtl_framer_sends_the_rust_framers_bytes";
    if Command::new("iverilog").arg("-V").output().is_err() {
        stereocal_hil::skip(test, "iverilog is not installed");
        return;
    }
    let (text, count) = vectors();
    let dir = tempfile::tempdir().expect("temporary directory");
    let vectors = dir.path().join("framer.txt");
    std::fs::write(&vectors, text).expect("vectors written");
    let rtl = Path::new(env!("CARGO_MANIFEST_DIR")).join("../hdl-interface/rtl");
    let sim = dir.path().join("tb_framer.vvp");
    let built = Command::new("iverilog")
        .args(["-g2005", "-Wall", "-s", "tb_framer", "-o"])
        .arg(&sim)
        .arg(rtl.join("sc_framer.v"))
        .arg(rtl.join("sc_ram.v"))
        .arg(rtl.join("tb/tb_framer.v"))
        .output()
        .expect("iverilog runs");
    assert!(
        built.status.success(),
        "{test}: iverilog: {}",
        String::from_utf8_lossy(&built.stderr)
    );
    let ran = Command::new("vvp")
        .arg("-n")
        .arg(&sim)
        .arg(format!("+vectors={}", vectors.display()))
        .output()
        .expect("vvp runs");
    let log = String::from_utf8_lossy(&ran.stdout);
    eprintln!("{test}: {count} packets: {}", log.trim());
    assert!(
        log.lines().any(|l| l.starts_with("PASS tb_framer")),
        "{test}: {log}"
    );
}
