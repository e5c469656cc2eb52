//! The bandwidth table of `docs/wire-format.md`, recomputed from the packet layouts.
//!
//! Frame sizes are the COBS worst case ([`max_encoded_len`]), so the table is an upper bound.
//! The scene: one 640x480 camera frame, 4 octaves (each half the size of the one before),
//! 500 keypoints.

use stereocal_wire::{
    max_encoded_len, Camera, FrameEndRepr, FrameStartRepr, PacketRepr, PointBatchRepr, Records,
    SobelPatchRepr, SobelPixel, SobelRowsRepr, MAX_POINTS, PATCH_PIXELS,
};

const SPEC: &str = include_str!("../docs/wire-format.md");
const WIDTH: usize = 640;
const HEIGHT: usize = 480;
const OCTAVES: u32 = 4;
const POINTS: usize = 500;
/// Gaussian scales per octave (G0..G3), each with a Sobel image.
const SCALES: usize = 4;
const PAIRS_PER_SECOND: usize = 30;

fn frame_len(repr: PacketRepr<'_>) -> usize {
    max_encoded_len(repr.buffer_len())
}

/// FrameStart, the point batches and FrameEnd: sent in every mode.
fn points_only() -> usize {
    let start = frame_len(PacketRepr::FrameStart(FrameStartRepr {
        frame_id: 0,
        camera: Camera::Left,
        width: WIDTH as u16,
        height: HEIGHT as u16,
        octaves: OCTAVES as u8,
        timestamp_us: 0,
    }));
    let end = frame_len(PacketRepr::FrameEnd(FrameEndRepr {
        frame_id: 0,
        camera: Camera::Left,
        point_count: 0,
        sobel_count: 0,
        flags: Default::default(),
        dropped_points: 0,
        dropped_sobel: 0,
    }));
    let points = [Default::default(); POINTS];
    let batches: usize = points
        .chunks(MAX_POINTS)
        .map(|batch| {
            frame_len(PacketRepr::PointBatch(PointBatchRepr {
                frame_id: 0,
                camera: Camera::Left,
                points: Records::Values(batch),
            }))
        })
        .sum();
    start + batches + end
}

/// One `SobelRows` packet per row of one scale of every octave.
fn sobel_rows_one_scale() -> usize {
    let row = [SobelPixel::default(); WIDTH];
    (0..OCTAVES)
        .map(|octave| {
            let (width, height) = (WIDTH >> octave, HEIGHT >> octave);
            let packet = frame_len(PacketRepr::SobelRows(SobelRowsRepr {
                frame_id: 0,
                camera: Camera::Left,
                octave: octave as u8,
                scale: 0,
                row: 0,
                pixels: Records::Values(&row[..width]),
            }));
            packet * height
        })
        .sum()
}

/// One `SobelPatch` per keypoint.
fn sobel_patches() -> usize {
    let patch = [SobelPixel::default(); PATCH_PIXELS];
    POINTS
        * frame_len(PacketRepr::SobelPatch(SobelPatchRepr {
            frame_id: 0,
            camera: Camera::Left,
            point_index: 0,
            octave: 0,
            scale: 0,
            x: 0,
            y: 0,
            pixels: Records::Values(&patch),
        }))
}

fn table() -> String {
    let rows = [
        ("points only (no Sobel data)", points_only()),
        (
            "16x16 patches at 500 points",
            points_only() + sobel_patches(),
        ),
        (
            "full Sobel rows, 1 scale x 4 octaves",
            points_only() + sobel_rows_one_scale(),
        ),
        (
            "full Sobel rows, 4 scales x 4 octaves",
            points_only() + SCALES * sobel_rows_one_scale(),
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
