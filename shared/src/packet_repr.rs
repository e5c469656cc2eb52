//! Any packet, as one enum: what `encode` takes and `decode` gives back.

use crate::packet::encoders::{self, EncodersRepr};
use crate::packet::error_report::{self, ErrorReportRepr};
use crate::packet::frame_end::{self, FrameEndRepr};
use crate::packet::frame_start::{self, FrameStartRepr};
use crate::packet::hello::{self, HelloRepr};
use crate::packet::kind::PacketKind;
use crate::packet::log::{self, LogRepr};
use crate::packet::point_batch::{self, PointBatchRepr};
use crate::packet::register_read::{self, RegisterReadRepr};
use crate::packet::register_value::{self, RegisterValueRepr};
use crate::packet::register_write::{self, RegisterWriteRepr};
use crate::packet::sobel_patch::{self, SobelPatchRepr};
use crate::packet::sobel_rows::{self, SobelRowsRepr};
use crate::Error;

/// The payload of any packet kind. Variable-length kinds borrow their records (from the
/// received frame when decoding, from the caller's slices when encoding).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PacketRepr<'a> {
    /// `0x01`
    Hello(HelloRepr),
    /// `0x02`
    RegisterWrite(RegisterWriteRepr),
    /// `0x03`
    RegisterRead(RegisterReadRepr),
    /// `0x04`
    RegisterValue(RegisterValueRepr),
    /// `0x10`
    FrameStart(FrameStartRepr),
    /// `0x11`
    PointBatch(PointBatchRepr<'a>),
    /// `0x12`
    SobelRows(SobelRowsRepr<'a>),
    /// `0x13`
    SobelPatch(SobelPatchRepr<'a>),
    /// `0x14`
    FrameEnd(FrameEndRepr),
    /// `0x15`
    Encoders(EncodersRepr),
    /// `0x20`
    Log(LogRepr<'a>),
    /// `0x21` (the spec's `Error` kind)
    ErrorReport(ErrorReportRepr),
}

impl<'a> PacketRepr<'a> {
    /// The kind byte this payload is sent with.
    pub fn kind(&self) -> PacketKind {
        match self {
            PacketRepr::Hello(_) => PacketKind::Hello,
            PacketRepr::RegisterWrite(_) => PacketKind::RegisterWrite,
            PacketRepr::RegisterRead(_) => PacketKind::RegisterRead,
            PacketRepr::RegisterValue(_) => PacketKind::RegisterValue,
            PacketRepr::FrameStart(_) => PacketKind::FrameStart,
            PacketRepr::PointBatch(_) => PacketKind::PointBatch,
            PacketRepr::SobelRows(_) => PacketKind::SobelRows,
            PacketRepr::SobelPatch(_) => PacketKind::SobelPatch,
            PacketRepr::FrameEnd(_) => PacketKind::FrameEnd,
            PacketRepr::Encoders(_) => PacketKind::Encoders,
            PacketRepr::Log(_) => PacketKind::Log,
            PacketRepr::ErrorReport(_) => PacketKind::ErrorReport,
        }
    }

    /// Payload length in bytes (without header and CRC).
    pub fn buffer_len(&self) -> usize {
        match self {
            PacketRepr::Hello(repr) => repr.buffer_len(),
            PacketRepr::RegisterWrite(repr) => repr.buffer_len(),
            PacketRepr::RegisterRead(repr) => repr.buffer_len(),
            PacketRepr::RegisterValue(repr) => repr.buffer_len(),
            PacketRepr::FrameStart(repr) => repr.buffer_len(),
            PacketRepr::PointBatch(repr) => repr.buffer_len(),
            PacketRepr::SobelRows(repr) => repr.buffer_len(),
            PacketRepr::SobelPatch(repr) => repr.buffer_len(),
            PacketRepr::FrameEnd(repr) => repr.buffer_len(),
            PacketRepr::Encoders(repr) => repr.buffer_len(),
            PacketRepr::Log(repr) => repr.buffer_len(),
            PacketRepr::ErrorReport(repr) => repr.buffer_len(),
        }
    }

    /// Parses the payload of a packet of `kind`.
    pub fn parse(kind: PacketKind, payload: &'a [u8]) -> Result<PacketRepr<'a>, Error> {
        Ok(match kind {
            PacketKind::Hello => {
                PacketRepr::Hello(HelloRepr::parse(&hello::Packet::new_unchecked(payload))?)
            }
            PacketKind::RegisterWrite => PacketRepr::RegisterWrite(RegisterWriteRepr::parse(
                &register_write::Packet::new_unchecked(payload),
            )?),
            PacketKind::RegisterRead => PacketRepr::RegisterRead(RegisterReadRepr::parse(
                &register_read::Packet::new_unchecked(payload),
            )?),
            PacketKind::RegisterValue => PacketRepr::RegisterValue(RegisterValueRepr::parse(
                &register_value::Packet::new_unchecked(payload),
            )?),
            PacketKind::FrameStart => PacketRepr::FrameStart(FrameStartRepr::parse(
                &frame_start::Packet::new_unchecked(payload),
            )?),
            PacketKind::PointBatch => PacketRepr::PointBatch(PointBatchRepr::parse(
                &point_batch::Packet::new_unchecked(payload),
            )?),
            PacketKind::SobelRows => PacketRepr::SobelRows(SobelRowsRepr::parse(
                &sobel_rows::Packet::new_unchecked(payload),
            )?),
            PacketKind::SobelPatch => PacketRepr::SobelPatch(SobelPatchRepr::parse(
                &sobel_patch::Packet::new_unchecked(payload),
            )?),
            PacketKind::FrameEnd => PacketRepr::FrameEnd(FrameEndRepr::parse(
                &frame_end::Packet::new_unchecked(payload),
            )?),
            PacketKind::Encoders => PacketRepr::Encoders(EncodersRepr::parse(
                &encoders::Packet::new_unchecked(payload),
            )?),
            PacketKind::Log => {
                PacketRepr::Log(LogRepr::parse(&log::Packet::new_unchecked(payload))?)
            }
            PacketKind::ErrorReport => PacketRepr::ErrorReport(ErrorReportRepr::parse(
                &error_report::Packet::new_unchecked(payload),
            )?),
            PacketKind::Unknown(_) => return Err(Error::DecodeUnknownKind),
        })
    }

    /// Writes the payload into `payload`, which must be at least [`Self::buffer_len`] bytes.
    pub fn emit(&self, payload: &mut [u8]) -> Result<(), Error> {
        match self {
            PacketRepr::Hello(repr) => repr.emit(&mut hello::Packet::new_unchecked(payload)),
            PacketRepr::RegisterWrite(repr) => {
                repr.emit(&mut register_write::Packet::new_unchecked(payload))
            }
            PacketRepr::RegisterRead(repr) => {
                repr.emit(&mut register_read::Packet::new_unchecked(payload))
            }
            PacketRepr::RegisterValue(repr) => {
                repr.emit(&mut register_value::Packet::new_unchecked(payload))
            }
            PacketRepr::FrameStart(repr) => {
                repr.emit(&mut frame_start::Packet::new_unchecked(payload))
            }
            PacketRepr::PointBatch(repr) => {
                repr.emit(&mut point_batch::Packet::new_unchecked(payload))
            }
            PacketRepr::SobelRows(repr) => {
                repr.emit(&mut sobel_rows::Packet::new_unchecked(payload))
            }
            PacketRepr::SobelPatch(repr) => {
                repr.emit(&mut sobel_patch::Packet::new_unchecked(payload))
            }
            PacketRepr::FrameEnd(repr) => repr.emit(&mut frame_end::Packet::new_unchecked(payload)),
            PacketRepr::Encoders(repr) => repr.emit(&mut encoders::Packet::new_unchecked(payload)),
            PacketRepr::Log(repr) => repr.emit(&mut log::Packet::new_unchecked(payload)),
            PacketRepr::ErrorReport(repr) => {
                repr.emit(&mut error_report::Packet::new_unchecked(payload))
            }
        }
    }
}
