//! Proptest strategies: one owned value per packet kind, lent out as a `PacketRepr`.

use proptest::collection::vec;
use proptest::prelude::*;
use stereocal_wire::{
    Camera, Capabilities, EncodersRepr, ErrorCode, ErrorReportRepr, FrameEndFlags, FrameEndRepr,
    FrameStartRepr, HelloRepr, LogRepr, PacketRepr, Point, PointBatchRepr, Records,
    RegisterReadRepr, RegisterValueRepr, RegisterWriteRepr, SobelPatchRepr, SobelPixel,
    SobelRowsRepr, MAX_LOG_LEN, MAX_POINTS, MAX_SOBEL_ROW_WIDTH, PATCH_PIXELS,
};

/// A packet that owns its records.
#[derive(Debug, Clone)]
pub enum OwnedPacket {
    Fixed(PacketRepr<'static>),
    PointBatch {
        frame_id: u32,
        camera: Camera,
        points: Vec<Point>,
    },
    SobelRows {
        frame_id: u32,
        camera: Camera,
        octave: u8,
        scale: u8,
        row: u16,
        x: u16,
        pixels: Vec<SobelPixel>,
    },
    SobelPatch {
        frame_id: u32,
        camera: Camera,
        point_index: u16,
        octave: u8,
        scale: u8,
        x: u16,
        y: u16,
        pixels: Vec<SobelPixel>,
    },
    Log(Vec<u8>),
}

impl OwnedPacket {
    pub fn repr(&self) -> PacketRepr<'_> {
        match self {
            OwnedPacket::Fixed(repr) => *repr,
            OwnedPacket::PointBatch {
                frame_id,
                camera,
                points,
            } => PacketRepr::PointBatch(PointBatchRepr {
                frame_id: *frame_id,
                camera: *camera,
                points: Records::Values(points),
            }),
            OwnedPacket::SobelRows {
                frame_id,
                camera,
                octave,
                scale,
                row,
                x,
                pixels,
            } => PacketRepr::SobelRows(SobelRowsRepr {
                frame_id: *frame_id,
                camera: *camera,
                octave: *octave,
                scale: *scale,
                row: *row,
                x: *x,
                pixels: Records::Values(pixels),
            }),
            OwnedPacket::SobelPatch {
                frame_id,
                camera,
                point_index,
                octave,
                scale,
                x,
                y,
                pixels,
            } => PacketRepr::SobelPatch(SobelPatchRepr {
                frame_id: *frame_id,
                camera: *camera,
                point_index: *point_index,
                octave: *octave,
                scale: *scale,
                x: *x,
                y: *y,
                pixels: Records::Values(pixels),
            }),
            OwnedPacket::Log(frame) => PacketRepr::Log(LogRepr { frame }),
        }
    }
}

/// Any camera byte; `Unknown` only for values that are not Left/Right, so it round-trips.
pub fn camera() -> impl Strategy<Value = Camera> {
    any::<u8>().prop_map(Camera::from)
}

pub fn point() -> impl Strategy<Value = Point> {
    (any::<(u16, u16, u8, u8)>(), any::<(i16, i16, i16, i16)>()).prop_map(
        |((x, y, octave, scale), (dx, dy, ds, dog))| Point {
            x,
            y,
            octave,
            scale,
            dx,
            dy,
            ds,
            dog,
        },
    )
}

pub fn sobel_pixel() -> impl Strategy<Value = SobelPixel> {
    (any::<u8>(), 0u8..64).prop_map(|(magnitude, orientation)| SobelPixel {
        magnitude,
        orientation,
    })
}

fn fixed() -> impl Strategy<Value = PacketRepr<'static>> {
    prop_oneof![
        (any::<u8>(), any::<u32>()).prop_map(|(version, bits)| PacketRepr::Hello(HelloRepr {
            version,
            capabilities: Capabilities(bits),
        })),
        (any::<u16>(), any::<u32>())
            .prop_map(|(addr, value)| PacketRepr::RegisterWrite(RegisterWriteRepr { addr, value })),
        any::<u16>().prop_map(|addr| PacketRepr::RegisterRead(RegisterReadRepr { addr })),
        (any::<u16>(), any::<u32>())
            .prop_map(|(addr, value)| PacketRepr::RegisterValue(RegisterValueRepr { addr, value })),
        (any::<u32>(), camera(), any::<(u16, u16, u8, u64)>()).prop_map(
            |(frame_id, camera, (width, height, octaves, timestamp_us))| {
                PacketRepr::FrameStart(FrameStartRepr {
                    frame_id,
                    camera,
                    width,
                    height,
                    octaves,
                    timestamp_us,
                })
            }
        ),
        (any::<u32>(), camera(), any::<(u32, u32, u8, u32, u32)>()).prop_map(
            |(
                frame_id,
                camera,
                (point_count, sobel_count, flags, dropped_points, dropped_sobel),
            )| {
                PacketRepr::FrameEnd(FrameEndRepr {
                    frame_id,
                    camera,
                    point_count,
                    sobel_count,
                    flags: FrameEndFlags(flags),
                    dropped_points,
                    dropped_sobel,
                })
            }
        ),
        any::<(u32, i32, i32)>().prop_map(|(frame_id, left_yaw_udeg, right_yaw_udeg)| {
            PacketRepr::Encoders(EncodersRepr {
                frame_id,
                left_yaw_udeg,
                right_yaw_udeg,
            })
        }),
        (any::<u16>(), any::<u32>()).prop_map(|(code, detail)| PacketRepr::ErrorReport(
            ErrorReportRepr {
                code: ErrorCode::from(code),
                detail,
            }
        )),
    ]
}

/// Any valid packet of any kind, records up to each kind's maximum.
pub fn packet() -> impl Strategy<Value = OwnedPacket> {
    prop_oneof![
        fixed().prop_map(OwnedPacket::Fixed),
        (any::<u32>(), camera(), vec(point(), 0..=MAX_POINTS)).prop_map(
            |(frame_id, camera, points)| OwnedPacket::PointBatch {
                frame_id,
                camera,
                points
            }
        ),
        (
            any::<u32>(),
            camera(),
            any::<(u8, u8, u16)>(),
            vec(sobel_pixel(), 0..=MAX_SOBEL_ROW_WIDTH),
            0..=MAX_SOBEL_ROW_WIDTH
        )
            .prop_map(|(frame_id, camera, (octave, scale, row), pixels, x)| {
                // A segment ends within the widest row.
                let x = x.min(MAX_SOBEL_ROW_WIDTH - pixels.len()) as u16;
                OwnedPacket::SobelRows {
                    frame_id,
                    camera,
                    octave,
                    scale,
                    row,
                    x,
                    pixels,
                }
            }),
        (
            any::<u32>(),
            camera(),
            any::<(u16, u8, u8, u16, u16)>(),
            vec(sobel_pixel(), PATCH_PIXELS)
        )
            .prop_map(
                |(frame_id, camera, (point_index, octave, scale, x, y), pixels)| {
                    OwnedPacket::SobelPatch {
                        frame_id,
                        camera,
                        point_index,
                        octave,
                        scale,
                        x,
                        y,
                        pixels,
                    }
                }
            ),
        vec(any::<u8>(), 0..=MAX_LOG_LEN).prop_map(OwnedPacket::Log),
    ]
}
