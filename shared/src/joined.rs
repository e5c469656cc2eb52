//! Two link frames joined by a lost delimiter: where the second one starts.
//!
//! A bit flip that turns a frame's closing `0x00` into another byte joins that frame to the
//! next one, and the joined bytes fail to decode as one frame. Without more, the receiver
//! loses both packets, though only the first was damaged. The first packet's header says how
//! long that packet is, and walking its COBS code bytes finds where its encoding ends: the byte
//! after that is the damaged delimiter, and the second frame, behind it, decodes on its own.
//! The check costs a header's worth of COBS decoding per frame; the walk runs only for a
//! frame longer than its header allows.

use crate::fec;
use crate::packet::header::{field, CRC_LEN, HEADER_LEN};

/// The COBS code that stands for 254 data bytes and no zero after them.
const FULL_CODE: u8 = 0xFF;

/// Where, in `frame` (the bytes between two delimiters, protected by [`fec`] when `protected`),
/// a second link frame starts when the first one's header says the first ends earlier.
/// `None` for a frame that is one link frame, as far as its header tells.
pub(crate) fn second_frame_at(frame: &[u8], protected: bool) -> Option<usize> {
    let packet_len = packet_len(frame)?;
    // The body the whole frame would have; a length no protected frame has is not one frame.
    let body = if protected {
        fec::body_len(frame.len())
    } else {
        Some(frame.len())
    };
    // COBS adds one code byte, and one more per 254 data bytes without a zero.
    if body.is_some_and(|body| body <= packet_len + 1 + packet_len / 254) {
        return None;
    }
    let first_body = encoded_len(frame, packet_len)?;
    let first = if protected {
        fec::protected_len(first_body)
    } else {
        first_body
    };
    // The first frame, then its damaged delimiter, then at least a code byte.
    (first + 2 <= frame.len()).then_some(first + 1)
}

/// The packet length (header, payload and CRC) the header of the COBS-encoded `frame` gives.
fn packet_len(frame: &[u8]) -> Option<usize> {
    let mut header = [0u8; HEADER_LEN];
    let mut filled = 0;
    walk(frame, |group| {
        for &byte in group {
            if let Some(slot) = header.get_mut(filled) {
                *slot = byte;
                filled += 1;
            }
        }
        filled >= HEADER_LEN
    });
    if filled < HEADER_LEN {
        return None;
    }
    let len = header.get(field::PAYLOAD_LEN)?;
    let payload = u16::from_le_bytes([*len.first()?, *len.get(1)?]);
    Some(HEADER_LEN + usize::from(payload) + CRC_LEN)
}

/// The length of the COBS encoding at the start of `frame` that decodes to `packet_len`
/// bytes, or `None` when the code bytes say otherwise.
fn encoded_len(frame: &[u8], packet_len: usize) -> Option<usize> {
    let mut at = 0;
    let mut decoded = 0;
    loop {
        let code = *frame.get(at)?;
        if code == 0 {
            return None;
        }
        decoded += usize::from(code) - 1;
        at += usize::from(code);
        if decoded == packet_len {
            return Some(at);
        }
        if code != FULL_CODE {
            // The zero the next code stands for.
            decoded += 1;
        }
        if decoded > packet_len {
            return None;
        }
    }
}

/// Hands the decoded bytes of `frame`'s COBS groups, with the zeros between them, to `take`
/// until it returns `true` or the bytes end.
fn walk(frame: &[u8], mut take: impl FnMut(&[u8]) -> bool) {
    let mut at = 0;
    while let Some(&code) = frame.get(at) {
        if code == 0 {
            return;
        }
        let end = at + usize::from(code);
        let Some(data) = frame.get(at + 1..end.min(frame.len())) else {
            return;
        };
        if take(data) || end >= frame.len() {
            return;
        }
        if code != FULL_CODE && take(&[0]) {
            return;
        }
        at = end;
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::vec::Vec;

    use super::*;
    use crate::{encode, PacketRepr, RegisterReadRepr, Source, MAX_ENCODED_LEN};

    /// A `RegisterRead` link frame without its delimiter, protected when `protected`.
    fn frame(seq: u16, protected: bool) -> Vec<u8> {
        let mut buf = [0u8; MAX_ENCODED_LEN];
        let repr = PacketRepr::RegisterRead(RegisterReadRepr { addr: 0 });
        let mut f = encode(Source::Control, seq, &repr, &mut buf)
            .unwrap()
            .to_vec();
        f.pop();
        if protected {
            let body = f.len();
            f.resize(fec::protected_len(body), 0);
            let total = fec::protect(&mut f, body).unwrap();
            f.truncate(total);
        }
        f
    }

    #[test]
    fn finds_the_second() {
        for protected in [false, true] {
            let a = frame(1, protected);
            let mut joined = a.clone();
            joined.push(0x7f);
            joined.extend_from_slice(&frame(2, protected));
            assert_eq!(
                second_frame_at(&joined, protected),
                Some(a.len() + 1),
                "{protected} {joined:?}"
            );
            assert_eq!(second_frame_at(&a, protected), None);
        }
    }
}
