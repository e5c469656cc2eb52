//! Giving an encoded frame a new sequence number without decoding it.
//!
//! The in-process link runs the right camera's channel while the left one runs, so the right
//! camera's packets are numbered before it is known how many the left camera sends. They are
//! renumbered afterwards, about 1.3 MB per pair at KITTI's size. Decoding and re-encoding
//! every frame (COBS, CRC, COBS again) cost the device thread about a tenth of its time.
//!
//! A renumbering changes only the two sequence bytes at packet offset 2 and the four CRC bytes
//! at the end. COBS is local: as long as none of these six bytes turns from non-zero to zero
//! or back, the COBS code bytes stay where they are and the new bytes take the old bytes'
//! places. The new CRC follows from the old one without reading the payload, because a CRC is
//! linear: two messages that differ only in their first four bytes differ in their CRCs by
//! those four bytes' CRCs' difference carried through the rest of the message as through zero
//! bytes. A frame that does not meet the conditions is left untouched, and the caller decodes
//! and re-encodes it as before.

use stereocal_wire::{CRC_LEN, DELIMITER};

/// Packet offset of the sequence number (after version and kind).
const SEQ_AT: usize = 2;
/// Packet bytes up to the end of the sequence number: the prefix the renumbering changes.
const PREFIX: usize = SEQ_AT + 2;
/// The COBS code byte that announces a full block (no zero follows it).
const FULL_BLOCK: u8 = 0xFF;

/// Rewrites `frame` (COBS bytes and the trailing delimiter, as the packet writer wrote it) to
/// carry sequence number `seq`, with its CRC to match. Returns `false`, leaving `frame`
/// unchanged, when that cannot be done in place: a sequence or CRC byte would become or
/// was zero, the bytes are no well-formed frame, or the packet is shorter than a header.
pub fn renumber_in_place(frame: &mut [u8], seq: u16) -> bool {
    let Some((&mut DELIMITER, encoded)) = frame.split_last_mut() else {
        return false;
    };
    let Some((packet_len, last_block)) = cobs_layout(encoded) else {
        return false;
    };
    // The prefix is whole in the first block, and the CRC whole in the last one.
    if usize::from(encoded[0]) <= PREFIX || last_block < CRC_LEN || packet_len < PREFIX + CRC_LEN {
        return false;
    }
    let seq_bytes = seq.to_le_bytes();
    if seq_bytes.contains(&0) {
        return false;
    }
    let crc_at = encoded.len() - CRC_LEN;
    let mut old_prefix = [0u8; PREFIX];
    old_prefix.copy_from_slice(&encoded[1..=PREFIX]);
    let mut new_prefix = old_prefix;
    new_prefix[SEQ_AT..].copy_from_slice(&seq_bytes);
    let mut old_crc = [0u8; CRC_LEN];
    old_crc.copy_from_slice(&encoded[crc_at..]);
    let carried = packet_len - CRC_LEN - PREFIX;
    let delta = through_zeros(
        crc32c::crc32c(&old_prefix) ^ crc32c::crc32c(&new_prefix),
        carried,
    );
    let new_crc = (u32::from_le_bytes(old_crc) ^ delta).to_le_bytes();
    if new_crc.contains(&0) {
        return false;
    }
    encoded[1 + SEQ_AT..=PREFIX].copy_from_slice(&seq_bytes);
    encoded[crc_at..].copy_from_slice(&new_crc);
    true
}

/// Walks the COBS code bytes of `encoded` (zero-free): the decoded packet's length and the
/// number of data bytes in its last block, or `None` when a code points past the end.
fn cobs_layout(encoded: &[u8]) -> Option<(usize, usize)> {
    let mut at = 0;
    let mut decoded = 0;
    loop {
        let code = usize::from(*encoded.get(at)?);
        if code == 0 {
            return None;
        }
        let next = at + code;
        if next == encoded.len() {
            return Some((decoded + code - 1, code - 1));
        }
        if next > encoded.len() {
            return None;
        }
        // A block ends in a zero of the packet unless it is full.
        decoded += code - 1 + usize::from(encoded[at] != FULL_BLOCK);
        at = next;
    }
}

/// Bytes of zeros the CRC difference is carried through at most per step (a frame's
/// length). A `static`, so every use reads the one array: a `const` sliced at a run-time
/// length may be built afresh as a temporary at each use.
static ZEROS: [u8; stereocal_wire::MAX_FRAME_LEN] = [0; stereocal_wire::MAX_FRAME_LEN];

/// The CRC register difference `x` after `len` more equal bytes: zeros carry the register
/// linearly, and `crc32c_append` starts from and returns the complement of the register.
fn through_zeros(x: u32, len: usize) -> u32 {
    let mut carried = x;
    let mut left = len;
    while left > 0 {
        let step = left.min(ZEROS.len());
        carried = !crc32c::crc32c_append(!carried, &ZEROS[..step]);
        left -= step;
    }
    carried
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use stereocal_wire::{decode, encode, max_frame_len, PacketRepr, SobelRowsRepr};

    /// A Sobel-rows frame with sequence number `seq` and the given pixel bytes.
    fn frame(seq: u16, pixels: &[u8]) -> Vec<u8> {
        let repr = PacketRepr::SobelRows(SobelRowsRepr {
            frame_id: 7,
            camera: stereocal_wire::Camera::Right,
            octave: 0,
            scale: 1,
            row: 3,
            pixels: stereocal_wire::Records::Wire(pixels),
        });
        let mut out = vec![0u8; max_frame_len(repr.buffer_len())];
        encode(seq, &repr, &mut out).unwrap().to_vec()
    }

    proptest! {
        /// Renumbered in place or not at all: when it says it did, the bytes are those of
        /// encoding the packet with the new number; when not, the frame is untouched.
        #[test]
        fn in_place_equals_re_encoding(
            old in any::<u16>(),
            new in any::<u16>(),
            pixels in proptest::collection::vec((any::<u8>(), 0u8..64), 0..700),
        ) {
            let bytes: Vec<u8> = pixels.iter().flat_map(|&(m, o)| [m, o]).collect();
            let original = frame(old, &bytes);
            let mut renumbered = original.clone();
            if renumber_in_place(&mut renumbered, new) {
                prop_assert_eq!(&renumbered, &frame(new, &bytes));
                let (header, _) = decode(&mut renumbered).unwrap();
                prop_assert_eq!(header.seq, new);
            } else {
                prop_assert_eq!(&renumbered, &original);
            }
        }
    }

    #[test]
    fn most_frames_renumber_in_place_and_zero_bytes_do_not() {
        let pixels: Vec<u8> = (0..1264u32)
            .flat_map(|i| [(i % 251) as u8, (i % 64) as u8])
            .collect();
        let renumbered = (1..=1000u16)
            .filter(|&seq| renumber_in_place(&mut frame(seq, &pixels), seq.wrapping_add(300)))
            .count();
        // A sequence number with a zero byte (256 of 1000 here have a zero high byte) or a
        // new CRC with a zero byte (about 1 in 64) falls back.
        assert!(renumbered > 700, "{renumbered}");
        let mut original = frame(0x0101, &pixels);
        assert!(!renumber_in_place(&mut original, 0x0100));
        assert_eq!(original, frame(0x0101, &pixels));
    }

    #[test]
    fn malformed_frames_are_left_alone() {
        for bad in [
            &[][..],
            &[0],
            &[5, 1, 1, 1, 1, 0],
            &[9, 1, 2, 3, 4, 5, 6, 7, 8],
            &[0, 1, 0],
        ] {
            let mut bytes = bad.to_vec();
            assert!(!renumber_in_place(&mut bytes, 0x0202));
            assert_eq!(bytes, bad);
        }
    }
}
