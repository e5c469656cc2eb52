//! Framing: a packet (header, payload, CRC-32C) COBS-encoded and terminated by `0x00`, a
//! *link frame*. (A bare "frame" in this project is a camera frame; the link's unit is always
//! called a link frame or an encoded packet.)
//!
//! COBS removes every `0x00` from the packet bytes, so `0x00` marks link-frame ends only and a
//! receiver that lost sync (a dropped byte, line noise, a reset peer) is back in step at the
//! next `0x00`. The overhead is one byte per 254 bytes plus one, and the delimiter.

use crate::cobs_in_place;
use crate::packet::header::{self, Header, CRC_LEN, HEADER_LEN};
use crate::packet::source::Source;
use crate::packet_repr::PacketRepr;
use crate::{Error, MAX_PAYLOAD_LEN, PROTOCOL_VERSION, SUPPORTED_VERSIONS};

/// The frame delimiter.
pub const DELIMITER: u8 = 0x00;

/// Longest frame (COBS bytes plus the delimiter) a packet with `payload_len` payload bytes
/// can take; `encode` needs an output buffer at least this long.
pub const fn max_encoded_len(payload_len: usize) -> usize {
    cobs::max_encoding_length(HEADER_LEN + payload_len + CRC_LEN) + 1
}

/// Encodes `repr` as packet `seq` of `source` into `out` as one complete frame, delimiter
/// included, and returns the frame (a prefix of `out`).
///
/// `out` must hold [`max_encoded_len`]`(repr.buffer_len())` bytes (at most
/// [`MAX_ENCODED_LEN`](crate::MAX_ENCODED_LEN)), even when the frame turns out shorter: the packet
/// is first written one byte in, behind the slot of the first COBS code byte, and then
/// COBS-encoded in place, so no second buffer is needed on the soft-core. Mostly that only
/// rewrites its zeros; a packet with full COBS blocks (254 non-zero bytes) first moves one
/// byte towards the end per such block, into the room the length check kept.
pub fn encode<'o>(
    source: Source,
    seq: u16,
    repr: &PacketRepr<'_>,
    out: &'o mut [u8],
) -> Result<&'o [u8], Error> {
    let payload_len = repr.buffer_len();
    if payload_len > MAX_PAYLOAD_LEN {
        return Err(Error::EncodeTooManyRecords);
    }
    if out.len() < max_encoded_len(payload_len) {
        return Err(Error::EncodeBufferTooSmall);
    }
    let packet_len = HEADER_LEN + payload_len + CRC_LEN;
    let offset = 1;
    let mut packet = header::Packet::new_unchecked(
        out.get_mut(offset..offset + packet_len)
            .ok_or(Error::EncodeBufferTooSmall)?,
    );
    let header = Header {
        version: PROTOCOL_VERSION,
        kind: repr.kind(),
        source,
        seq,
        // `payload_len <= MAX_PAYLOAD_LEN`, which fits a u16 (asserted in lib.rs).
        payload_len: payload_len as u16,
    };
    header.emit(&mut packet)?;
    repr.emit(packet.payload_mut())?;
    packet.fill_crc();
    // `out` holds `max_encoded_len` bytes (checked above), so neither `None` below happens.
    let frame_len = cobs_in_place::encode_in_place(out, offset, packet_len)
        .ok_or(Error::EncodeBufferTooSmall)?;
    *out.get_mut(frame_len).ok_or(Error::EncodeBufferTooSmall)? = DELIMITER;
    out.get(..=frame_len).ok_or(Error::EncodeBufferTooSmall)
}

/// Decodes one frame in place and parses it.
///
/// `frame` holds the COBS bytes of one frame, with or without its trailing `0x00`. The checks
/// run in this order, each with its own error: COBS, minimum length, CRC (skipped when the
/// crate is built for fuzzing), version, length fields, kind, payload fields.
pub fn decode(frame: &mut [u8]) -> Result<(Header, PacketRepr<'_>), Error> {
    let encoded_len = match frame.last() {
        Some(&DELIMITER) => frame.len() - 1,
        _ => frame.len(),
    };
    let encoded = frame
        .get_mut(..encoded_len)
        .ok_or(Error::DecodeUnexpectedEnd)?;
    if encoded.is_empty() {
        return Err(Error::DecodeUnexpectedEnd);
    }
    if encoded.contains(&DELIMITER) {
        return Err(Error::DecodeBadCobs);
    }
    decode_zero_free(encoded).map_err(|rejected| rejected.error)
}

/// Why a frame did not decode, with its header when the packet was intact up to its payload
/// (a kind this crate does not know, a payload that breaks its kind's layout): the packet
/// still used up a number of its source.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Rejected {
    pub error: Error,
    pub header: Option<Header>,
}

impl From<Error> for Rejected {
    fn from(error: Error) -> Self {
        Rejected {
            error,
            header: None,
        }
    }
}

/// [`decode`] of COBS bytes known to hold no `0x00` (the [`Accumulator`](crate::Accumulator)
/// cuts its frames at the zeros, so it need not scan them again).
pub(crate) fn decode_zero_free(encoded: &mut [u8]) -> Result<(Header, PacketRepr<'_>), Rejected> {
    let packet = cobs_in_place::decode_in_place(encoded).ok_or(Error::DecodeBadCobs)?;
    let encoded: &[u8] = encoded;
    parse_packet(encoded.get(packet).ok_or(Error::DecodeBadCobs)?)
}

/// Checks and parses the bytes of a whole packet (after COBS decoding).
fn parse_packet(bytes: &[u8]) -> Result<(Header, PacketRepr<'_>), Rejected> {
    if bytes.len() < HEADER_LEN + CRC_LEN {
        return Err(Error::DecodeUnexpectedEnd.into());
    }
    let packet = header::Packet::new_unchecked(bytes);
    if !cfg!(fuzzing) && !packet.verify_crc() {
        return Err(Error::DecodeBadCrc.into());
    }
    if !SUPPORTED_VERSIONS.contains(&packet.version()) {
        return Err(Error::DecodeUnknownVersion.into());
    }
    let header = Header::parse(&packet)?;
    let payload = bytes
        .get(HEADER_LEN..bytes.len() - CRC_LEN)
        .ok_or(Error::DecodeUnexpectedEnd)?;
    let repr = PacketRepr::parse(header.kind, payload).map_err(|error| Rejected {
        error,
        header: Some(header),
    })?;
    Ok((header, repr))
}
