//! COBS encoding and decoding inside one buffer, block by block instead of byte by byte.
//!
//! The output is byte for byte that of the `cobs` crate (the proptests below compare them),
//! but the `cobs` crate's state machine spends a match and a bounds check on every byte, and
//! the host frames every byte of a full-Sobel stream (2.6 MB per 1264x376 pair). Here the
//! common case moves no data at all: while no block is full (254 non-zero bytes), COBS only
//! replaces each `0x00` by the distance to the next one and puts one code byte in front, so
//! with the packet one byte behind the code slot the encoder is a backward pass over the bytes
//! and the decoder a walk along the codes (a flat stretch of `0x01` codes at a word a time).
//! Only full blocks shift data, by one byte each.
//!
//! Every access is checked (`get`/`get_mut`, iterators, cells), so the firmware links no
//! panicking path through here (tests/tests/firmware_panic_free.rs).

use core::cell::Cell;
use core::ops::Range;

/// Most non-zero bytes one COBS block carries (its code byte is then `0xFF`).
const FULL_BLOCK: usize = 254;

/// Chunk size of the search for long runs: a run of `FULL_BLOCK` or more non-zero bytes always
/// covers one whole chunk of `FULL_BLOCK / 2` (aligned to where the search starts), so only
/// chunks without a zero need a closer look.
const CHUNK: usize = FULL_BLOCK / 2;

/// COBS-encodes `buf[src..src + len]` into `buf[..]` and returns the encoded length, or
/// `None` when `src` is 0 or `buf` is too short (shorter than the encoding), which
/// [`crate::encode`] rules out.
///
/// The packet is first moved to `1 + E`, `E` the code bytes its full blocks insert: with
/// `src == 1` (as [`crate::encode`] places it) it stays put unless there are full blocks.
/// Every inserted code byte then closes the gap between output and input by one, so the
/// output never overtakes input not yet read, and after the last full block the data is where
/// it belongs. Between full blocks the encoding is one backward pass per stretch.
pub(crate) fn encode_in_place(buf: &mut [u8], src: usize, len: usize) -> Option<usize> {
    if src == 0 {
        return None;
    }
    let end = 1 + extra_codes(buf.get(src..src.checked_add(len)?)?) + len;
    let mut read = end - len;
    move_bytes(buf, src, read, len)?;
    // `slot` is the current block's code byte, `out` where the next data byte goes.
    let mut slot = 0;
    let mut out = 1;
    while let Some(run) = long_run(buf.get(read..end)?) {
        let (run_start, run_end) = (read + run.start, read + run.end);
        if run_start > read {
            // The stretch up to the zero before the run; that zero's place is the next slot.
            let stretch = run_start - 1 - read;
            move_bytes(buf, read, out, stretch)?;
            encode_stretch(buf.get_mut(slot..out + stretch)?);
            slot = out + stretch;
            out = slot + 1;
            read = run_start;
        }
        while run_end - read >= FULL_BLOCK {
            *buf.get_mut(slot)? = 0xff;
            move_bytes(buf, read, out, FULL_BLOCK)?;
            read += FULL_BLOCK;
            out += FULL_BLOCK;
            if read == end {
                // COBS drops the empty block after a final full one.
                return Some(out);
            }
            slot = out;
            out += 1;
        }
    }
    let tail = end - read;
    move_bytes(buf, read, out, tail)?;
    encode_stretch(buf.get_mut(slot..out + tail)?);
    Some(out + tail)
}

/// Code bytes the full blocks of `data` insert (a full block at the very end inserts none:
/// COBS drops the empty block after it). Walks the long runs as [`encode_in_place`] does.
fn extra_codes(data: &[u8]) -> usize {
    let mut read = 0;
    let mut extra = 0;
    while let Some(run) = data.get(read..).and_then(long_run) {
        let len = run.end - run.start;
        let full = len / FULL_BLOCK;
        let at_end = read + run.end == data.len() && len % FULL_BLOCK == 0;
        extra += full - usize::from(at_end);
        read += run.start + full * FULL_BLOCK;
    }
    extra
}

/// The first run of at least [`FULL_BLOCK`] non-zero bytes in `bytes` (bounded by zeros or
/// the ends of `bytes`), if any. The chunk test is `contains`, a word-at-a-time `memchr`, so
/// zero-rich and textured data are both scanned quickly.
fn long_run(bytes: &[u8]) -> Option<Range<usize>> {
    let mut chunk_start = 0;
    while let Some(chunk) = bytes.get(chunk_start..chunk_start + CHUNK) {
        if chunk.contains(&0) {
            chunk_start += CHUNK;
            continue;
        }
        // The chunk before held a zero (or this run would have been found there), so this
        // looks back less than one chunk.
        let before = bytes.get(..chunk_start).unwrap_or_default();
        let start = before
            .iter()
            .rposition(|&byte| byte == 0)
            .map_or(0, |zero| zero + 1);
        let end = chunk_start + first_zero(bytes.get(chunk_start..).unwrap_or_default());
        if end - start >= FULL_BLOCK {
            return Some(start..end);
        }
        // Continue at the chunk holding the zero that ended this short run.
        chunk_start += (end - chunk_start) / CHUNK * CHUNK;
    }
    None
}

/// Bytes in a machine word, the step of the scans below.
const WORD: usize = core::mem::size_of::<usize>();
/// `0x01` in every byte of a word.
const ONES: usize = usize::MAX / 0xff;
/// `0x80` in every byte of a word.
const HIGHS: usize = ONES << 7;

/// Index of the first `0x00` in `bytes`, or its length.
///
/// A machine word at a time: `(w - 0x01..01) & !w & 0x80..80` flags the zero bytes of `w` (a
/// borrow can flag a byte above a zero too, never one below the first, so the lowest flag is
/// exact).
pub(crate) fn first_zero(bytes: &[u8]) -> usize {
    let mut words = bytes.chunks_exact(WORD);
    let mut index = 0;
    for word in &mut words {
        let word = usize::from_le_bytes(word.try_into().unwrap_or_default());
        let zeros = word.wrapping_sub(ONES) & !word & HIGHS;
        if zeros != 0 {
            return index + (zeros.trailing_zeros() / 8) as usize;
        }
        index += WORD;
    }
    let tail = words.remainder();
    index
        + tail
            .iter()
            .position(|&byte| byte == 0)
            .unwrap_or(tail.len())
}

/// Number of `0x01` bytes at the start of `bytes`, a machine word at a time: XOR with
/// `0x01..01` clears exactly those, and the lowest set bit left marks the first other byte.
fn leading_ones(bytes: &[u8]) -> usize {
    let mut words = bytes.chunks_exact(WORD);
    let mut count = 0;
    for word in &mut words {
        let others = usize::from_le_bytes(word.try_into().unwrap_or_default()) ^ ONES;
        if others != 0 {
            return count + (others.trailing_zeros() / 8) as usize;
        }
        count += WORD;
    }
    let tail = words.remainder();
    count
        + tail
            .iter()
            .position(|&byte| byte != 1)
            .unwrap_or(tail.len())
}

/// Encodes a stretch without full blocks in place: `block[0]` is its code byte's slot and
/// `block[1..]` its data, ended by a zero just past `block` or by the packet's end. Walking
/// backwards, each `0x00` becomes the distance to the next zero (or to the end of `block`),
/// and `block[0]` the distance to the first; no byte moves. A word at a time where it can:
/// textured words (no zero) only add to the distance, flat words (all zero) become
/// `01 01 .. distance`; only the words that mix the two go byte by byte.
fn encode_stretch(block: &mut [u8]) {
    let Some((code, data)) = block.split_first_mut() else {
        return;
    };
    let mut distance: u8 = 1;
    let mut words = data.rchunks_exact_mut(WORD);
    for word in &mut words {
        let value = usize::from_le_bytes((&*word).try_into().unwrap_or_default());
        if value.wrapping_sub(ONES) & !value & HIGHS == 0 {
            // At most FULL_BLOCK: the stretch holds no zero-free run of FULL_BLOCK bytes.
            distance = distance.wrapping_add(WORD as u8);
        } else if value == 0 {
            let mut flat = [1u8; WORD];
            flat[WORD - 1] = distance;
            for (byte, value) in word.iter_mut().zip(flat) {
                *byte = value;
            }
            distance = 1;
        } else {
            distance = encode_bytes(word, distance);
        }
    }
    *code = encode_bytes(words.into_remainder(), distance);
}

/// [`encode_stretch`] byte by byte: turns the zeros of `bytes` into distances, given the
/// distance from its end to the next zero, and returns the distance from its start.
fn encode_bytes(bytes: &mut [u8], mut distance: u8) -> u8 {
    for byte in bytes.iter_mut().rev() {
        if *byte == 0 {
            *byte = distance;
            distance = 1;
        } else {
            distance = distance.wrapping_add(1);
        }
    }
    distance
}

/// COBS-decodes `buf` (no `0x00` in it) in place and returns where the decoded bytes are, or
/// `None` when a code byte points past the end: the transform and the rejections of
/// `cobs::decode_in_place`. The decoded bytes start at index 1, where the first block's data
/// already is, so a frame without full blocks decodes by turning each later code byte back
/// into `0x00`; after each full block the rest moves one byte towards the front.
pub(crate) fn decode_in_place(buf: &mut [u8]) -> Option<Range<usize>> {
    let end = buf.len();
    let mut code_at = 0;
    let mut code = *buf.first()?;
    let mut dest = 1;
    loop {
        if code == 1 {
            // A flat stretch: a row of `0x01` codes, each an empty block and so one zero. Done
            // as one fill, not one dependent load per byte.
            // (`buf[code_at]` itself may already hold the previous block's zero.)
            let codes = 1 + leading_ones(buf.get(code_at + 1..)?);
            let after = code_at + codes;
            if after == end {
                // The last code ends the frame and adds no zero.
                buf.get_mut(dest..dest + codes - 1)?.fill(0);
                return Some(1..dest + codes - 1);
            }
            code = *buf.get(after)?;
            buf.get_mut(dest..dest + codes)?.fill(0);
            dest += codes;
            code_at = after;
            continue;
        }
        let code_len = usize::from(code);
        if code_len == 0 {
            return None;
        }
        let block_end = code_at + code_len;
        if block_end > end {
            return None;
        }
        let data_len = code_len - 1;
        if dest != code_at + 1 && data_len != 0 {
            move_bytes(buf, code_at + 1, dest, data_len)?;
        }
        dest += data_len;
        if block_end == end {
            return Some(1..dest);
        }
        // Read the next code before the zero below may land on it.
        code = *buf.get(block_end)?;
        code_at = block_end;
        if code_len != FULL_BLOCK + 1 {
            *buf.get_mut(dest)? = 0;
            dest += 1;
        }
    }
}

/// Moves `buf[from..from + len]` to `buf[to..to + len]`, overlapping or not, like
/// `copy_within`, but as a loop over cells: `copy_within` and `rotate_left` each left a
/// bounds-check panic in the firmware's release ELF (not inlined there, so no guard here could
/// discharge it), and `Cell` lets one loop read and write the same bytes without indexing.
/// Copying in the direction of the move reads every byte before it is overwritten.
fn move_bytes(buf: &mut [u8], from: usize, to: usize, len: usize) -> Option<()> {
    if from == to {
        return Some(());
    }
    let cells = Cell::from_mut(buf).as_slice_of_cells();
    let source = cells.get(from..from.checked_add(len)?)?;
    let target = cells.get(to..to.checked_add(len)?)?;
    if to < from {
        for (to, from) in target.iter().zip(source) {
            to.set(from.get());
        }
    } else {
        for (to, from) in target.iter().zip(source).rev() {
            to.set(from.get());
        }
    }
    Some(())
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;
    use proptest::prelude::*;
    use std::vec;
    use std::vec::Vec;

    /// Byte strings COBS finds hard: empty, zero-heavy, and runs around the 254-byte block.
    fn hard_bytes() -> impl Strategy<Value = Vec<u8>> {
        let run = (
            prop_oneof![Just(0u8), 1u8..=255],
            0usize..300,
            any::<bool>(),
        )
            .prop_map(|(fill, len, zero_after)| {
                let mut run = vec![fill; len];
                if zero_after {
                    run.push(0);
                }
                run
            });
        prop_oneof![
            proptest::collection::vec(any::<u8>(), 0..1200),
            proptest::collection::vec(prop_oneof![3 => Just(0u8), 2 => 1u8..=255], 0..1200),
            proptest::collection::vec(run, 0..8).prop_map(|runs| runs.concat()),
            (252usize..=256, any::<bool>()).prop_map(|(len, zero)| {
                let mut run = vec![0x5a; len];
                if zero {
                    run.push(0);
                }
                run
            }),
        ]
    }

    /// Encodes with the packet one byte in (as `crate::encode` places it) or further, in a
    /// buffer just long enough for the longest encoding, or a little longer.
    fn encode(bytes: &[u8], src: usize, slack: usize) -> Vec<u8> {
        let room = cobs::max_encoding_length(bytes.len()).max(src + bytes.len());
        let mut buf = vec![0xeeu8; room + slack];
        buf[src..src + bytes.len()].copy_from_slice(bytes);
        let len = encode_in_place(&mut buf, src, bytes.len()).expect("room enough");
        buf.truncate(len);
        buf
    }

    proptest! {
        #[test]
        fn encode_matches_the_cobs_crate(
            bytes in hard_bytes(),
            src in prop_oneof![Just(1usize), 1usize..12],
            slack in 0usize..3,
        ) {
            let mut reference = vec![0u8; cobs::max_encoding_length(bytes.len())];
            let reference_len = cobs::encode(&bytes, &mut reference);
            prop_assert_eq!(encode(&bytes, src, slack), &reference[..reference_len]);
        }

        #[test]
        fn decode_matches_the_cobs_crate(bytes in hard_bytes()) {
            // Valid frames, from the reference encoder, and arbitrary zero-free bytes.
            let mut encoded = vec![0u8; cobs::max_encoding_length(bytes.len())];
            let encoded_len = cobs::encode(&bytes, &mut encoded);
            encoded.truncate(encoded_len);
            let noise: Vec<u8> = bytes.iter().map(|&b| b.max(1)).collect();
            for input in [encoded, noise].into_iter().filter(|input| !input.is_empty()) {
                let mut ours = input.clone();
                let mut theirs = input;
                let expected = cobs::decode_in_place(&mut theirs).ok();
                let got = decode_in_place(&mut ours);
                prop_assert_eq!(got.as_ref().map(|range| range.len()), expected);
                if let (Some(range), Some(len)) = (got, expected) {
                    prop_assert_eq!(&ours[range], &theirs[..len]);
                }
            }
        }

        #[test]
        fn round_trip(bytes in hard_bytes()) {
            let mut encoded = encode(&bytes, 1, 0);
            let range = decode_in_place(&mut encoded).expect("valid COBS");
            prop_assert_eq!(&encoded[range], &bytes[..]);
        }
    }

    #[test]
    fn a_too_short_buffer_is_refused() {
        let mut buf = [1u8; 4];
        assert_eq!(encode_in_place(&mut buf, 0, 3), None);
        assert_eq!(encode_in_place(&mut buf, 2, 3), None);
    }
}
