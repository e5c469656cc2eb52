//! The framing path on a realistic Sobel stream: 1264-pixel `SobelRows` rows of a synthetic
//! gradient image with flat (all-zero) regions, about 40% zero bytes, as `stereocal run` sends
//! on 1264x376 frames. Criterion reports bytes per second over the frame bytes; the ns/B
//! figures are printed after the run.
//!
//! `cobs_crate` is the in-run baseline: the `cobs` crate's per-byte encoder over the same
//! packets, so a change to `frame.rs` shows as a ratio measured on the same machine state.

use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use stereocal_wire::{
    crc32c, decode, encode, max_encoded_len, Camera, PacketRepr, Records, SobelPixel,
    SobelRowsRepr, Source, MAX_SOBEL_ROW_WIDTH,
};

const WIDTH: usize = 1264;
const ROWS: usize = 64;

/// One row of a smooth gradient image: flat bands give zero pixels (both bytes 0), edges give
/// magnitudes and orientations, so COBS sees the short runs of real Sobel output.
fn row(y: usize) -> Vec<SobelPixel> {
    (0..WIDTH)
        .map(|x| {
            let (fx, fy) = (x as f32, y as f32);
            let g = (fx * 0.031 + fy * 0.017).sin() * (fx * 0.007).cos() + (fx * 0.11).sin() * 0.3;
            if g.abs() < 0.28 {
                SobelPixel::default()
            } else {
                SobelPixel {
                    magnitude: (g.abs() * 200.0) as u8,
                    orientation: ((fx * 0.05 + fy * 0.02) as u32 % 64) as u8,
                }
            }
        })
        .collect()
}

fn rows() -> Vec<Vec<SobelPixel>> {
    (0..ROWS).map(row).collect()
}

fn repr(y: usize, pixels: &[SobelPixel]) -> PacketRepr<'_> {
    PacketRepr::SobelRows(SobelRowsRepr {
        frame_id: 1,
        camera: Camera::Left,
        octave: 0,
        scale: 1,
        row: y as u16,
        x: 0,
        pixels: Records::Values(pixels),
    })
}

/// Every row encoded into one frame each.
fn frames(rows: &[Vec<SobelPixel>]) -> Vec<Vec<u8>> {
    let mut buf = vec![0u8; max_encoded_len(11 + 2 * MAX_SOBEL_ROW_WIDTH)];
    rows.iter()
        .enumerate()
        .map(|(y, pixels)| {
            encode(Source::Left, y as u16, &repr(y, pixels), &mut buf)
                .unwrap()
                .to_vec()
        })
        .collect()
}

fn encode_all(rows: &[Vec<SobelPixel>], buf: &mut [u8]) -> usize {
    rows.iter()
        .enumerate()
        .map(|(y, pixels)| {
            encode(Source::Left, y as u16, &repr(y, pixels), buf)
                .unwrap()
                .len()
        })
        .sum()
}

/// Decodes copies of the frames (decoding is in place); the copy is part of what a receiver
/// does anyway (the accumulator gathers the link bytes).
fn decode_all(frames: &[Vec<u8>], scratch: &mut [u8]) -> usize {
    frames
        .iter()
        .map(|frame| {
            let copy = &mut scratch[..frame.len()];
            copy.copy_from_slice(frame);
            let (header, _) = decode(copy).unwrap();
            usize::from(header.payload_len)
        })
        .sum()
}

/// The `cobs` crate's encoder over the same unencoded packets (the baseline).
fn cobs_crate_all(packets: &[Vec<u8>], out: &mut [u8]) -> usize {
    packets.iter().map(|p| cobs::encode(p, out)).sum()
}

fn crc_all(packets: &[Vec<u8>]) -> u32 {
    packets.iter().fold(0, |acc, p| acc ^ crc32c(p))
}

fn ns_per_byte(bytes: usize, mut f: impl FnMut() -> usize) -> f64 {
    black_box(f());
    let reps = 50;
    let t = Instant::now();
    for _ in 0..reps {
        black_box(f());
    }
    t.elapsed().as_nanos() as f64 / f64::from(reps) / bytes as f64
}

fn bench(c: &mut Criterion) {
    let rows = rows();
    let frames = frames(&rows);
    let mut packets: Vec<Vec<u8>> = frames.clone();
    for p in &mut packets {
        let encoded_len = p.len() - 1;
        let len = cobs::decode_in_place(&mut p[..encoded_len]).unwrap();
        p.truncate(len);
    }
    let frame_bytes: usize = frames.iter().map(Vec::len).sum();
    let packet_bytes: usize = packets.iter().map(Vec::len).sum();
    let zeros = packets.iter().flatten().filter(|&&b| b == 0).count();
    println!(
        "{ROWS} rows of {WIDTH} pixels: {packet_bytes} packet bytes ({:.0}% zero), {frame_bytes} frame bytes",
        100.0 * zeros as f64 / packet_bytes as f64
    );
    let mut buf = vec![0u8; max_encoded_len(11 + 2 * MAX_SOBEL_ROW_WIDTH)];
    let mut scratch = buf.clone();

    let mut g = c.benchmark_group("framing");
    g.throughput(Throughput::Bytes(packet_bytes as u64));
    g.bench_function("encode", |b| b.iter(|| encode_all(&rows, &mut buf)));
    g.bench_function("decode", |b| b.iter(|| decode_all(&frames, &mut scratch)));
    g.bench_function("cobs_crate", |b| {
        b.iter(|| cobs_crate_all(&packets, &mut scratch))
    });
    g.bench_function("crc32c", |b| b.iter(|| crc_all(&packets)));
    g.finish();

    println!(
        "ns/B: encode {:.3}, decode {:.3}, cobs crate encode {:.3}, crc32c {:.3}",
        ns_per_byte(packet_bytes, || encode_all(&rows, &mut buf)),
        ns_per_byte(packet_bytes, || decode_all(&frames, &mut scratch)),
        ns_per_byte(packet_bytes, || cobs_crate_all(&packets, &mut scratch)),
        ns_per_byte(packet_bytes, || crc_all(&packets) as usize),
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
