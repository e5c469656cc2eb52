//! Two link frames joined by a lost delimiter: where the second one starts.
//!
//! A bit flip that turns a frame's closing `0x00` into another byte joins that frame to the
//! next one, and the joined bytes fail to decode as one frame. Without more, the receiver
//! loses both packets, though only the first was damaged. The first packet's header says how
//! long that packet is, and walking its COBS code bytes finds where its encoding ends: the byte
//! after that is the damaged delimiter, and the second frame, behind it, decodes on its own.
//! The check costs a header's worth of COBS decoding per frame; the walk runs only for a
//! frame longer than its header allows.

use crate::cobs_in_place::FULL_CODE;
use crate::fec;
use crate::packet::header::{Packet, CRC_LEN, HEADER_LEN};

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
    if body.is_some_and(|body| body <= cobs::max_encoding_length(packet_len)) {
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
    let decoded = groups(frame).flat_map(|g| g.data.iter().chain(g.zero_after.then_some(&0)));
    let mut filled = 0;
    for (slot, &byte) in header.iter_mut().zip(decoded) {
        *slot = byte;
        filled += 1;
    }
    let payload = Packet::new_unchecked(&header[..]).payload_len();
    (filled == HEADER_LEN).then_some(HEADER_LEN + usize::from(payload) + CRC_LEN)
}

/// The length of the COBS encoding at the start of `frame` that decodes to `packet_len`
/// bytes, or `None` when the code bytes say otherwise.
fn encoded_len(frame: &[u8], packet_len: usize) -> Option<usize> {
    let mut decoded = 0;
    for group in groups(frame) {
        decoded += group.data.len();
        if decoded == packet_len {
            return Some(group.end);
        }
        decoded += usize::from(group.zero_after);
        if decoded > packet_len {
            return None;
        }
    }
    None
}

/// One COBS group of a frame: its data bytes, where it ends, and whether a decoded zero
/// follows it (its code is not [`FULL_CODE`] and another group comes after it).
struct Group<'a> {
    data: &'a [u8],
    end: usize,
    zero_after: bool,
}

/// The COBS groups at the start of `frame`, up to its end or to a code byte that cannot be
/// one (a zero); the last one cut short where the frame ends.
fn groups(frame: &[u8]) -> impl Iterator<Item = Group<'_>> {
    let mut at = 0;
    core::iter::from_fn(move || {
        let code = *frame.get(at).filter(|&&code| code != 0)?;
        let end = at + usize::from(code);
        let data = frame.get(at + 1..end.min(frame.len()))?;
        at = end;
        Some(Group {
            data,
            end,
            zero_after: code != FULL_CODE && end < frame.len(),
        })
    })
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
