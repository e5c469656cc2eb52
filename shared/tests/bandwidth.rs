//! The bandwidth table of `docs/wire-format.md`, recomputed from the packet layouts.
//!
//! Frame sizes are the COBS worst case ([`max_encoded_len`]), so the table is an upper bound.
//! The scene: one 640x480 camera frame, 4 octaves (each half the size of the one before),
//! 500 keypoints. Two packings: the registers' defaults for a clean link (16-point batches,
//! whole rows), and the noisy-link guard (8-point batches, 64-pixel row segments, forward
//! error correction on every link frame).

use stereocal_wire::{
    fec, max_encoded_len, Camera, FrameEndRepr, FrameStartRepr, PacketRepr, PointBatchRepr,
    Records, SobelPatchRepr, SobelPixel, SobelRowsRepr, PATCH_PIXELS,
};

const SPEC: &str = include_str!("../docs/wire-format.md");
const WIDTH: usize = 640;
const HEIGHT: usize = 480;
const OCTAVES: u32 = 4;
const POINTS: usize = 500;
/// Gaussian scales per octave (G0..G3), each with a Sobel image.
const SCALES: usize = 4;
const PAIRS_PER_SECOND: usize = 30;

/// How the device packs its packets.
#[derive(Clone, Copy)]
struct Packing {
    points_per_batch: usize,
    row_segment: usize,
    fec: bool,
}

/// OUTPUT_MODE's reset values, no parity.
const CLEAN: Packing = Packing {
    points_per_batch: 16,
    row_segment: 1280,
    fec: false,
};

/// `LinkProtection::noisy` of the host.
const NOISY: Packing = Packing {
    points_per_batch: 8,
    row_segment: 64,
    fec: true,
};

fn frame_len(repr: PacketRepr<'_>, packing: Packing) -> usize {
    let plain = max_encoded_len(repr.buffer_len());
    if packing.fec {
        fec::protected_len(plain - 1) + 1
    } else {
        plain
    }
}

/// FrameStart, the point batches and FrameEnd: sent in every mode.
fn points_only(packing: Packing) -> usize {
    let start = frame_len(
        PacketRepr::FrameStart(FrameStartRepr {
            frame_id: 0,
            camera: Camera::Left,
            width: WIDTH as u16,
            height: HEIGHT as u16,
            octaves: OCTAVES as u8,
            timestamp_us: 0,
        }),
        packing,
    );
    let end = frame_len(
        PacketRepr::FrameEnd(FrameEndRepr {
            frame_id: 0,
            camera: Camera::Left,
            point_count: 0,
            sobel_count: 0,
            flags: Default::default(),
            dropped_points: 0,
            dropped_sobel: 0,
        }),
        packing,
    );
    let points = [Default::default(); POINTS];
    let batches: usize = points
        .chunks(packing.points_per_batch)
        .map(|batch| {
            frame_len(
                PacketRepr::PointBatch(PointBatchRepr {
                    frame_id: 0,
                    camera: Camera::Left,
                    points: Records::Values(batch),
                }),
                packing,
            )
        })
        .sum();
    start + batches + end
}

/// The `SobelRows` packets of every row of one scale of every octave.
fn sobel_rows_one_scale(packing: Packing) -> usize {
    let row = [SobelPixel::default(); WIDTH];
    (0..OCTAVES)
        .map(|octave| {
            let (width, height) = (WIDTH >> octave, HEIGHT >> octave);
            let per_row: usize = row[..width]
                .chunks(packing.row_segment)
                .map(|segment| {
                    frame_len(
                        PacketRepr::SobelRows(SobelRowsRepr {
                            frame_id: 0,
                            camera: Camera::Left,
                            octave: octave as u8,
                            scale: 0,
                            row: 0,
                            x: 0,
                            pixels: Records::Values(segment),
                        }),
                        packing,
                    )
                })
                .sum();
            per_row * height
        })
        .sum()
}

/// One `SobelPatch` per keypoint.
fn sobel_patches(packing: Packing) -> usize {
    let patch = [SobelPixel::default(); PATCH_PIXELS];
    POINTS
        * frame_len(
            PacketRepr::SobelPatch(SobelPatchRepr {
                frame_id: 0,
                camera: Camera::Left,
                point_index: 0,
                octave: 0,
                scale: 0,
                x: 0,
                y: 0,
                pixels: Records::Values(&patch),
            }),
            packing,
        )
}

fn table() -> String {
    let rows = [
        ("points only (no Sobel data)", points_only(CLEAN)),
        (
            "16x16 patches at 500 points",
            points_only(CLEAN) + sobel_patches(CLEAN),
        ),
        (
            "full Sobel rows, 1 scale x 4 octaves",
            points_only(CLEAN) + sobel_rows_one_scale(CLEAN),
        ),
        (
            "full Sobel rows, 4 scales x 4 octaves",
            points_only(CLEAN) + SCALES * sobel_rows_one_scale(CLEAN),
        ),
        (
            "noisy link: 16x16 patches at 500 points",
            points_only(NOISY) + sobel_patches(NOISY),
        ),
        (
            "noisy link: full Sobel rows, 1 scale x 4 octaves",
            points_only(NOISY) + sobel_rows_one_scale(NOISY),
        ),
    ];
    let mut text = String::from(
        "| mode | bytes per camera frame | Mbit/s for 30 stereo pairs/s |\n|---|---:|---:|\n",
    );
    for (mode, bytes) in rows {
        let mbit = (bytes * 2 * PAIRS_PER_SECOND * 8) as f64 / 1e6;
        text += &format!("| {mode} | {bytes} | {mbit:.1} |\n");
    }
    text
}

#[test]
fn spec_bandwidth_table_matches_the_layouts() {
    let table = table();
    assert!(
        SPEC.contains(&table),
        "the spec's bandwidth table is stale; it must read:\n{table}"
    );
}
