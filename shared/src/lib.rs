//! The wire format between the stereocal soft-core firmware and the host.
//!
//! `no_std`, no allocation, no `std` feature: the firmware and the host use this crate as-is.
//! The specification, with byte diagrams and test vectors, is `docs/wire-format.md`.
//!
//! # Sending (firmware)
//! Build a [`PacketRepr`] and [`encode`] it into a buffer you own; the result is one complete
//! link frame (the encoded packet, delimiter included), ready for the UART:
//! ```
//! use stereocal_wire::{encode, Camera, FrameStartRepr, PacketRepr, Source, MAX_ENCODED_LEN};
//!
//! let mut buf = [0u8; MAX_ENCODED_LEN];
//! let repr = PacketRepr::FrameStart(FrameStartRepr {
//!     frame_id: 1,
//!     camera: Camera::Left,
//!     width: 640,
//!     height: 480,
//!     octaves: 4,
//!     timestamp_us: 0,
//! });
//! // The left camera's channel numbers its own packets; this is its first.
//! let frame: &[u8] = encode(Source::channel(Camera::Left), 0, &repr, &mut buf)?;
//! assert_eq!(frame.last(), Some(&0x00));
//! # Ok::<(), stereocal_wire::Error>(())
//! ```
//! Point and Sobel packets borrow their records from your slices through
//! [`Records::Values`]; [`MAX_POINTS`], [`MAX_SOBEL_ROW_WIDTH`] and [`PATCH_PIXELS`] bound them.
//!
//! # Receiving (host)
//! Feed whatever bytes the link delivers to an [`Accumulator`] and loop on the remaining input:
//! ```
//! use stereocal_wire::{FeedResult, FrameAccumulator};
//!
//! # let link_bytes = [0u8; 3];
//! let mut acc = FrameAccumulator::new();
//! let mut window: &[u8] = &link_bytes;
//! while !window.is_empty() {
//!     window = match acc.feed(window) {
//!         FeedResult::Consumed => break,
//!         FeedResult::OverFull(rest) => rest,
//!         FeedResult::DecodeError { error, remaining, .. } => {
//!             // count `error`; the next frame decodes normally
//!             remaining
//!         }
//!         FeedResult::Success { header, packet, remaining } => {
//!             // `packet` borrows the accumulator until the next `feed`
//!             let _ = (header.source, header.seq, packet.kind());
//!             remaining
//!         }
//!     };
//! }
//! ```
//! A whole frame already in memory decodes with [`decode`].
//!
//! # Typed views
//! [`packet`] has a module per kind with a `Packet<T: AsRef<[u8]>>` view over the payload
//! bytes and the `Repr` types re-exported here; see its documentation for the no-panic contract.
#![no_std]
#![deny(missing_docs)]

#[macro_use]
pub mod packet;

mod accumulator;
mod checksum;
mod cobs_in_place;
mod error;
pub mod fec;
mod framing;
mod geometry;
#[cfg(feature = "fec-repair")]
mod joined;
mod le;
mod packet_repr;
mod records;

pub use accumulator::{Accumulator, FeedResult};
pub use checksum::crc32c;
pub use error::Error;
pub use framing::{decode, encode, max_encoded_len, DELIMITER};
pub use geometry::octave_dims;
pub use packet::camera::Camera;
pub use packet::encoders::EncodersRepr;
pub use packet::error_report::{ErrorCode, ErrorReportRepr};
pub use packet::frame_end::{FrameEndFlags, FrameEndRepr};
pub use packet::frame_failure::{FrameFailure, MAX_FAILURE_VALUE};
pub use packet::frame_start::FrameStartRepr;
pub use packet::header::{Header, CRC_LEN, HEADER_LEN};
pub use packet::hello::{Capabilities, HelloRepr};
pub use packet::kind::PacketKind;
pub use packet::log::LogRepr;
pub use packet::point_batch::{Point, PointBatchRepr, MAX_POINTS, OFFSET_FRAC_BITS};
pub use packet::register_read::RegisterReadRepr;
pub use packet::register_value::RegisterValueRepr;
pub use packet::register_write::RegisterWriteRepr;
pub use packet::sobel_patch::{SobelPatchRepr, PATCH_PIXELS, PATCH_SIZE};
pub use packet::sobel_pixel::{SobelPixel, ORIENTATION_BITS};
pub use packet::sobel_rows::{SobelRowsRepr, MAX_WIDTH as MAX_SOBEL_ROW_WIDTH};
pub use packet::source::Source;
pub use packet_repr::PacketRepr;
pub use records::{Record, RecordIter, Records};

/// The protocol version this crate writes: 3, whose `SobelRows` names its first column (a row
/// may go out in segments).
pub const PROTOCOL_VERSION: u8 = 3;
/// The protocol versions [`decode`] accepts; any other is [`Error::DecodeUnknownVersion`].
/// Version 1's header has no source byte, and version 2's `SobelRows` no first column, so
/// their fields sit elsewhere: they are not read.
pub const SUPPORTED_VERSIONS: &[u8] = &[PROTOCOL_VERSION];

/// Payload length of `Hello`.
pub const MAX_HELLO_LEN: usize = packet::hello::LEN;
/// Payload length of `RegisterWrite`.
pub const MAX_REGISTER_WRITE_LEN: usize = packet::register_write::LEN;
/// Payload length of `RegisterRead`.
pub const MAX_REGISTER_READ_LEN: usize = packet::register_read::LEN;
/// Payload length of `RegisterValue`.
pub const MAX_REGISTER_VALUE_LEN: usize = packet::register_value::LEN;
/// Payload length of `FrameStart`.
pub const MAX_FRAME_START_LEN: usize = packet::frame_start::LEN;
/// Largest payload of `PointBatch` ([`MAX_POINTS`] points).
pub const MAX_POINT_BATCH_LEN: usize = packet::point_batch::MAX_LEN;
/// Largest payload of `SobelRows` (a [`MAX_SOBEL_ROW_WIDTH`]-pixel row).
pub const MAX_SOBEL_ROWS_LEN: usize = packet::sobel_rows::MAX_LEN;
/// Payload length of `SobelPatch`.
pub const MAX_SOBEL_PATCH_LEN: usize = packet::sobel_patch::LEN;
/// Payload length of `FrameEnd`.
pub const MAX_FRAME_END_LEN: usize = packet::frame_end::LEN;
/// Payload length of `Encoders`.
pub const MAX_ENCODERS_LEN: usize = packet::encoders::LEN;
/// Largest payload of `Log`.
pub const MAX_LOG_LEN: usize = packet::log::MAX_LEN;
/// Payload length of `ErrorReport`.
pub const MAX_ERROR_REPORT_LEN: usize = packet::error_report::LEN;

/// Largest payload of any kind.
pub const MAX_PAYLOAD_LEN: usize = {
    let lens = [
        MAX_HELLO_LEN,
        MAX_REGISTER_WRITE_LEN,
        MAX_REGISTER_READ_LEN,
        MAX_REGISTER_VALUE_LEN,
        MAX_FRAME_START_LEN,
        MAX_POINT_BATCH_LEN,
        MAX_SOBEL_ROWS_LEN,
        MAX_SOBEL_PATCH_LEN,
        MAX_FRAME_END_LEN,
        MAX_ENCODERS_LEN,
        MAX_LOG_LEN,
        MAX_ERROR_REPORT_LEN,
    ];
    let mut max = 0;
    let mut i = 0;
    while i < lens.len() {
        if lens[i] > max {
            max = lens[i];
        }
        i += 1;
    }
    max
};
/// Largest packet (header, payload, CRC) before COBS.
pub const MAX_PACKET_LEN: usize = HEADER_LEN + MAX_PAYLOAD_LEN + CRC_LEN;
/// Largest link frame (an encoded packet: COBS bytes and delimiter); sizes every transmit buffer and
/// every [`Accumulator`] that must receive all kinds.
pub const MAX_ENCODED_LEN: usize = max_encoded_len(MAX_PAYLOAD_LEN);

/// Largest link frame under forward error correction ([`fec`]), delimiter included.
pub const MAX_PROTECTED_LEN: usize = fec::protected_len(MAX_ENCODED_LEN - 1) + 1;

/// An accumulator that receives every packet kind.
pub type FrameAccumulator = Accumulator<MAX_ENCODED_LEN>;

// The header's payload length field is a u16.
const _: () = assert!(MAX_PAYLOAD_LEN <= u16::MAX as usize);
