//! Framing: a packet (header, payload, CRC-32C) COBS-encoded and terminated by `0x00`.
//!
//! COBS removes every `0x00` from the packet bytes, so `0x00` marks frame ends only and a
//! receiver that lost sync (a dropped byte, line noise, a reset peer) is back in step at the
//! next `0x00`. The overhead is one byte per 254 bytes plus one, and the delimiter.

use cobs::{EncoderState, PushResult};

use crate::packet::header::{self, Header, CRC_LEN, HEADER_LEN};
use crate::packet_repr::PacketRepr;
use crate::{Error, MAX_PAYLOAD_LEN, PROTOCOL_VERSION, SUPPORTED_VERSIONS};

/// The frame delimiter.
pub const DELIMITER: u8 = 0x00;

/// Longest frame (COBS bytes plus the delimiter) a packet with `payload_len` payload bytes
/// can take; `encode` needs an output buffer at least this long.
pub const fn max_frame_len(payload_len: usize) -> usize {
    cobs::max_encoding_length(HEADER_LEN + payload_len + CRC_LEN) + 1
}

/// Encodes `repr` with sequence number `seq` into `out` as one complete frame, delimiter
/// included, and returns the frame (a prefix of `out`).
///
/// `out` must hold [`max_frame_len`]`(repr.buffer_len())` bytes (at most
/// [`MAX_FRAME_LEN`](crate::MAX_FRAME_LEN)), even when the frame turns out shorter: the packet
/// is first written at the end of `out` and then COBS-encoded in place towards the front,
/// so no second buffer is needed on the soft-core.
pub fn encode<'o>(seq: u16, repr: &PacketRepr<'_>, out: &'o mut [u8]) -> Result<&'o [u8], Error> {
    let payload_len = repr.buffer_len();
    if payload_len > MAX_PAYLOAD_LEN {
        return Err(Error::EncodeTooManyRecords);
    }
    if out.len() < max_frame_len(payload_len) {
        return Err(Error::EncodeBufferTooSmall);
    }
    let packet_len = HEADER_LEN + payload_len + CRC_LEN;
    let offset = cobs::max_encoding_overhead(packet_len);
    let mut packet = header::Packet::new_unchecked(
        out.get_mut(offset..offset + packet_len)
            .ok_or(Error::EncodeBufferTooSmall)?,
    );
    let header = Header {
        version: PROTOCOL_VERSION,
        kind: repr.kind(),
        seq,
        // `payload_len <= MAX_PAYLOAD_LEN`, which fits a u16 (asserted in lib.rs).
        payload_len: payload_len as u16,
    };
    header.emit(&mut packet)?;
    repr.emit(packet.payload_mut())?;
    packet.fill_crc();
    // `out` holds `max_frame_len` bytes (checked above), so neither `None` below happens.
    let frame_len =
        cobs_encode_in_place(out, offset, packet_len).ok_or(Error::EncodeBufferTooSmall)?;
    *out.get_mut(frame_len).ok_or(Error::EncodeBufferTooSmall)? = DELIMITER;
    out.get(..=frame_len).ok_or(Error::EncodeBufferTooSmall)
}

/// COBS-encodes `buf[src..src + len]` into `buf[..]` and returns the encoded length, or
/// `None` (before finishing) should `buf` be too short, which [`encode`] rules out.
///
/// The `cobs` crate's encoder state machine does the transform; this loop only moves bytes.
/// It is safe in place when `src >= cobs::max_encoding_overhead(len)`: before input byte `i`
/// is written, the output holds at most `i` bytes plus one code byte per started block, at
/// most `1 + i / 254 <= src` extra bytes, so no unread input byte is overwritten.
fn cobs_encode_in_place(buf: &mut [u8], src: usize, len: usize) -> Option<usize> {
    let mut state = EncoderState::default();
    // buf[0] is the first code byte, written once its block closes.
    let mut dest = 1;
    // After a full 254-byte block the next code byte's slot is only reserved if more bytes
    // follow (COBS drops a final empty block after a full one).
    let mut block_just_filled = false;
    for i in src..src + len {
        let byte = *buf.get(i)?;
        if block_just_filled {
            dest += 1;
            block_just_filled = false;
        }
        match state.push(byte) {
            PushResult::AddSingle(value) => {
                *buf.get_mut(dest)? = value;
                dest += 1;
            }
            PushResult::ModifyFromStartAndSkip((code_at, code)) => {
                *buf.get_mut(code_at)? = code;
                dest += 1;
            }
            PushResult::ModifyFromStartAndPushAndSkip((code_at, code, value)) => {
                *buf.get_mut(code_at)? = code;
                *buf.get_mut(dest)? = value;
                dest += 1;
                block_just_filled = true;
            }
        }
    }
    if !block_just_filled {
        let (code_at, code) = state.finalize();
        *buf.get_mut(code_at)? = code;
    }
    Some(dest)
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
    let packet_len = cobs_decode_in_place(encoded).ok_or(Error::DecodeBadCobs)?;
    let encoded: &[u8] = encoded;
    parse_packet(encoded.get(..packet_len).ok_or(Error::DecodeBadCobs)?)
}

/// COBS-decodes `buf` (no `0x00` in it) in place and returns the decoded length, or `None`
/// when a code byte points past the end. The same transform and the same rejections as
/// `cobs::decode_in_place`, written with checked accesses so the firmware links no panic.
fn cobs_decode_in_place(buf: &mut [u8]) -> Option<usize> {
    let end = buf.len();
    let mut src = 0;
    let mut dest = 0;
    while let Some(&code) = buf.get(src) {
        let code = usize::from(code);
        if src + code > end && code != 1 {
            return None;
        }
        src += 1;
        for _ in 1..code {
            // `dest < src` throughout, so the write never overtakes the read.
            let byte = *buf.get(src)?;
            *buf.get_mut(dest)? = byte;
            src += 1;
            dest += 1;
        }
        if code != 0xff && src < end {
            *buf.get_mut(dest)? = 0;
            dest += 1;
        }
    }
    Some(dest)
}

/// Checks and parses the bytes of a whole packet (after COBS decoding).
fn parse_packet(bytes: &[u8]) -> Result<(Header, PacketRepr<'_>), Error> {
    if bytes.len() < HEADER_LEN + CRC_LEN {
        return Err(Error::DecodeUnexpectedEnd);
    }
    let packet = header::Packet::new_unchecked(bytes);
    if !cfg!(fuzzing) && !packet.verify_crc() {
        return Err(Error::DecodeBadCrc);
    }
    if !SUPPORTED_VERSIONS.contains(&packet.version()) {
        return Err(Error::DecodeUnknownVersion);
    }
    let header = Header::parse(&packet)?;
    let payload = bytes
        .get(HEADER_LEN..bytes.len() - CRC_LEN)
        .ok_or(Error::DecodeUnexpectedEnd)?;
    let repr = PacketRepr::parse(header.kind, payload)?;
    Ok((header, repr))
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    proptest! {
        /// The checked in-place decoder agrees with the `cobs` crate on any zero-free input.
        #[test]
        fn cobs_decode_matches_the_cobs_crate(bytes in proptest::collection::vec(1u8..=255, 1..600)) {
            let mut ours = bytes.clone();
            let mut theirs = bytes;
            let expected = cobs::decode_in_place(&mut theirs).ok();
            let got = super::cobs_decode_in_place(&mut ours);
            prop_assert_eq!(got, expected);
            if let Some(len) = got {
                prop_assert_eq!(&ours[..len], &theirs[..len]);
            }
        }
    }
}
