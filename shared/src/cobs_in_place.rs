//! COBS encoding and decoding inside one buffer, by zero masks of whole chunks and by code
//! bytes instead of a byte at a time.
//!
//! The output is byte for byte that of the `cobs` crate (the proptests below compare them),
//! but the `cobs` crate's state machine spends a match and a bounds check on every byte, and
//! the host frames every byte of a full-Sobel stream (2.6 MB per 1264x376 pair, in blocks of
//! about 11 bytes: per-block work is what counts). Here the common case moves no data at all:
//! while no block is full (254 non-zero bytes), COBS only replaces each `0x00` by the distance
//! to the next one and puts one code byte in front, so with the packet one byte behind the
//! code slot the encoder writes one code per zero it finds and the decoder writes one zero per
//! code it follows. Only full blocks shift data, by one byte each, and only from the first
//! full block on does either side fall back to moving bytes.
//!
//! Every access is checked (`get`, iterators, cells), so the firmware links no
//! panicking path through here (tests/tests/firmware_panic_free.rs).

use core::cell::Cell;
use core::ops::Range;

/// Most non-zero bytes one COBS block carries (its code byte is then `0xFF`).
const FULL_BLOCK: usize = 254;

/// The code byte of a full block.
pub(crate) const FULL_CODE: u8 = FULL_BLOCK as u8 + 1;

/// COBS-encodes `buf[src..src + len]` into `buf[..]` and returns the encoded length, or
/// `None` when `src` is 0 or `buf` is too short (shorter than the encoding), which
/// [`crate::encode`] rules out.
///
/// The packet is moved to index 1 (where [`crate::encode`] already puts it), behind the slot
/// of the first code byte. Each `0x00` then becomes the code of the block after it, the
/// distance to the next `0x00` (or to the end), and the slot in front the distance to the
/// first: a forward scan that writes each code when it finds the zero that ends the block.
/// The scan takes [`CHUNK`] bytes at a time, builds their zero mask without a branch
/// ([`zero_mask`]) and writes the codes of its zeros lowest first ([`Blocks::close_chunk`]),
/// so few branches depend on the data. A scan a word at a time, with a branch on each word's
/// zeros and a loop over them, took twice as long on Sobel rows, mostly in mispredicted
/// branches: two thirds of their words hold no zero, the others one to eight. The bytes are
/// read and written through cells, so one pass can write the codes behind it. A block longer
/// than [`FULL_BLOCK`] needs inserted code bytes, which [`Blocks::insert_full`] makes room
/// for.
pub(crate) fn encode_in_place(buf: &mut [u8], src: usize, len: usize) -> Option<usize> {
    if src == 0 {
        return None;
    }
    let cells = Cell::from_mut(buf).as_slice_of_cells();
    move_bytes(cells, src, 1, len)?;
    let mut blocks = Blocks {
        slot: 0,
        head: 0,
        gap: 0,
        end: len.checked_add(1)?,
    };
    let mut from = 1;
    'scan: loop {
        let mut chunks = cells.get(from..blocks.end)?.chunks_exact(CHUNK);
        let mut base = from;
        for chunk in &mut chunks {
            if let Some(moved_to) = blocks.close_chunk(cells, base, zero_mask(chunk))? {
                from = moved_to;
                continue 'scan;
            }
            base += CHUNK;
        }
        let zeros = tail_zero_mask(chunks.remainder());
        if let Some(moved_to) = blocks.close_chunk(cells, base, zeros)? {
            from = moved_to;
            continue 'scan;
        }
        break;
    }
    // A full last block (code 0xFF) ends the frame: COBS drops the empty block after it.
    let end = blocks.end;
    if end - blocks.slot > usize::from(FULL_CODE) {
        blocks.insert_full(cells, end, usize::from(FULL_CODE))?;
    }
    let end = blocks.end;
    cells.get(blocks.slot)?.set((end - blocks.slot) as u8);
    // The room left over from the first full block on: the bytes after the last one move down.
    move_bytes(
        cells,
        blocks.head,
        blocks.head - blocks.gap,
        end - blocks.head,
    )?;
    Some(end - blocks.gap)
}

/// The state of [`encode_in_place`]. Positions are where the bytes are now; the encoding of a
/// byte at `p` goes to `p - gap`.
///
/// Until the first full block `gap` is 0 and nothing moves. There, the rest of the packet
/// moves `E` bytes towards the end, `E` the most code bytes its full blocks can insert (one
/// per [`FULL_BLOCK`] bytes, and no more than `buf` has room for), and the scan starts again in
/// the moved bytes. Each inserted code closes the gap by one: the stretch since the last one
/// (codes written in place) moves down to where it belongs, once, and its last byte, now read,
/// becomes the slot of the code after the full block. The stretch after the last full block
/// moves down by what is left of the gap at the end. (Counting `E` exactly took a scan of the
/// rest of the packet, which cost more than the one move it saves.)
struct Blocks {
    /// Where the current block's code byte goes (its final place is `slot - gap`).
    slot: usize,
    /// Start of the stretch not yet moved to its final place (its first byte is a code).
    head: usize,
    /// Room still open for inserted code bytes.
    gap: usize,
    /// End of the packet.
    end: usize,
}

impl Blocks {
    /// Ends a block at each zero of the chunk at `base` (`zeros` its [`zero_mask`]).
    /// `Some(Some(p))` when the first full block moved the rest of the packet: the scan goes on
    /// at `p`, just after the zero that made room for it.
    ///
    /// Only the chunk's first zero can be more than [`FULL_BLOCK`] bytes from the slot (the
    /// others are less than [`CHUNK`] bytes from the zero before them), and only when the slot
    /// is that far from the chunk's last byte, which a well-predicted branch rules out first.
    /// The first [`UNROLLED`] zeros are taken without a branch: once the mask is empty, a step
    /// writes a meaningless code into the slot and keeps it, which is harmless, as the slot's
    /// code is written again when its block ends. Only the zeros after those loop.
    #[inline(always)]
    fn close_chunk(
        &mut self,
        cells: &[Cell<u8>],
        base: usize,
        zeros: usize,
    ) -> Option<Option<usize>> {
        if zeros == usize::MAX && base - self.slot <= FULL_BLOCK {
            // A flat chunk: its first zero ends the block before, each of the others an
            // empty block, so the chunk becomes `01 01 .. 01` and its last byte the slot.
            cells.get(self.slot)?.set((base - self.slot) as u8);
            for cell in cells.get(base..base + CHUNK - 1)? {
                cell.set(1);
            }
            self.slot = base + CHUNK - 1;
            return Some(None);
        }
        if base + (CHUNK - 1) - self.slot > FULL_BLOCK && zeros != 0 {
            let first = base + zeros.trailing_zeros() as usize;
            if first - self.slot > FULL_BLOCK {
                if let Some(moved_to) = self.insert_full_at(cells, first)? {
                    return Some(Some(moved_to));
                }
            }
        }
        let mut slot = self.slot;
        let mut zeros = zeros;
        for () in [(); UNROLLED] {
            let zero = base + zeros.trailing_zeros() as usize;
            cells.get(slot)?.set((zero - slot) as u8);
            slot = if zeros != 0 { zero } else { slot };
            zeros &= zeros.wrapping_sub(1);
        }
        while zeros != 0 {
            let zero = base + zeros.trailing_zeros() as usize;
            zeros &= zeros - 1;
            cells.get(slot)?.set((zero - slot) as u8);
            slot = zero;
        }
        self.slot = slot;
        Some(None)
    }

    /// [`close_chunk`](Self::close_chunk) at a `zero` too far from the slot: inserts the full
    /// blocks and, when that moved the packet, ends the block at the moved zero and returns
    /// where the scan goes on.
    #[cold]
    fn insert_full_at(&mut self, cells: &[Cell<u8>], zero: usize) -> Option<Option<usize>> {
        let moved = self.insert_full(cells, zero, FULL_BLOCK)?;
        if moved == 0 {
            return Some(None);
        }
        let zero = zero + moved;
        cells.get(self.slot)?.set((zero - self.slot) as u8);
        self.slot = zero;
        Some(Some(zero + 1))
    }

    /// Inserts full blocks until `at` (a zero or the end of the packet) is at most `most`
    /// bytes from the slot; the first ever (or the first once the gap is used up) moves the
    /// rest of the packet to make room for them, and the move is returned.
    fn insert_full(&mut self, cells: &[Cell<u8>], at: usize, most: usize) -> Option<usize> {
        let mut moved = 0;
        if self.gap == 0 {
            let rest = self.slot + 1;
            moved = ((self.end - rest) / FULL_BLOCK).min(cells.len() - self.end);
            move_bytes(cells, rest, rest + moved, self.end - rest)?;
            self.gap = moved;
            self.end += moved;
            // The slot's old byte was moved, so the slot can stand in the freed room at the
            // head of the stretch that moves down at the first insertion.
            self.slot += moved;
            self.head = self.slot;
        }
        let at = at + moved;
        while at - self.slot > most {
            cells.get(self.slot)?.set(FULL_CODE);
            let block_end = self.slot + 1 + FULL_BLOCK;
            move_bytes(
                cells,
                self.head,
                self.head - self.gap,
                block_end - self.head,
            )?;
            // No room left: `buf` is shorter than the encoding.
            self.gap = self.gap.checked_sub(1)?;
            self.slot = block_end - 1;
            self.head = self.slot;
        }
        Some(moved)
    }
}

/// The little-endian word in `cells` (`WORD` of them), one load once optimised.
#[inline(always)]
fn load(cells: &[Cell<u8>]) -> usize {
    let mut bytes = [0; WORD];
    for (byte, cell) in bytes.iter_mut().zip(cells) {
        *byte = cell.get();
    }
    usize::from_le_bytes(bytes)
}

/// Bytes in a machine word, the step of the scans below.
const WORD: usize = core::mem::size_of::<usize>();
/// `0x01` in every byte of a word.
const ONES: usize = usize::MAX / 0xff;
/// `0x80` in every byte of a word.
const HIGHS: usize = ONES << 7;
/// `0x7F` in every byte of a word.
const LOWS: usize = !HIGHS;

/// `0x80` in each byte of `word` that is not `0x00`, `0x00` in the others, exactly: adding
/// `0x7F` to the low seven bits of a byte sets its top bit unless they are all clear, and
/// cannot carry into the next byte; OR-ing the byte's own top bit in leaves it clear only for
/// `0x00`. (The shorter `(w - 0x01..01) & !w` borrows across bytes and can flag a `0x01`
/// above a zero, fine for [`first_zero`] but not for finding every zero.)
fn nonzero_bytes(word: usize) -> usize {
    (((word & LOWS) + LOWS) | word) & HIGHS
}

/// Bytes [`encode_in_place`] scans at a time: one bit each fills a `usize` (64 on the host,
/// 32 on the soft-core, eight words either way).
const CHUNK: usize = usize::BITS as usize;

/// Zeros of a chunk [`Blocks::close_chunk`] takes without a branch. A mispredicted branch
/// costs a host CPU more than a few steps that do nothing: three in four chunks of Sobel rows
/// hold at most eight zeros (a chunk of zeros takes its own path), and 6 to 8 steps were
/// fastest there, 12 or more slower. The soft-core pays per instruction, not per
/// misprediction, so it only loops.
const UNROLLED: usize = if cfg!(target_os = "none") { 0 } else { 8 };

/// `1 << 7j` for each byte `j` of a word: times a [`nonzero_bytes`] mask, whose flag for
/// byte `i` is bit `8i + 7`, it puts that flag at bit `7 * WORD + i` (when `i + j` is
/// `WORD - 1`), in the top `WORD` bits. The other products land either above the word or
/// below bit `8 * WORD - 8`, at distinct bits (no carries), so the top bits are exact.
const GATHER: usize = {
    let mut gather = 0;
    let mut byte = 0;
    while byte < WORD {
        gather |= 1 << (7 * byte);
        byte += 1;
    }
    gather
};

/// Bit `i` set when byte `i` of `chunk` ([`CHUNK`] bytes) is `0x00`, with no branch on the
/// data: each word's [`nonzero_bytes`] flags, gathered into the top `WORD` bits by one
/// multiply ([`GATHER`]), shift in from the top, and the mask of non-zero bytes is inverted
/// once at the end. (Shifting each word's flags into place by its index instead let the
/// compiler vectorise half the multiplies into slower SSE2 emulations of 64-bit products.)
#[inline(always)]
fn zero_mask(chunk: &[Cell<u8>]) -> usize {
    let mut nonzero = 0;
    for word in chunk.chunks_exact(WORD) {
        let flags = nonzero_bytes(load(word)).wrapping_mul(GATHER) & !(usize::MAX >> WORD);
        nonzero = (nonzero >> WORD) | flags;
    }
    !nonzero
}

/// [`zero_mask`] of a partial chunk, padded with non-zero bytes.
fn tail_zero_mask(tail: &[Cell<u8>]) -> usize {
    let mut chunk = [0xff; CHUNK];
    for (to, from) in chunk.iter_mut().zip(tail) {
        *to = from.get();
    }
    zero_mask(Cell::from_mut(&mut chunk[..]).as_slice_of_cells())
}

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

/// COBS-decodes `buf` (no `0x00` in it) in place and returns where the decoded bytes are, or
/// `None` when a code byte is `0x00` or points past the end: the transform and the rejections
/// of `cobs::decode_in_place`.
///
/// The decoded bytes start at index 1, where the first block's data already is. Each code
/// byte after the first stands where the zero that ended the block before it belongs, so the
/// walk along the codes only turns each one into `0x00`, one load and one store per block,
/// and a flat stretch of `0x01` codes (empty blocks) a word at a time. A full block has no zero
/// after it: its successor's code is dropped instead, and the bytes after it belong one
/// further down. They are decoded in place all the same and moved down once per stretch, when
/// the next dropped code (or the end) closes it, so nothing before the first full block moves.
pub(crate) fn decode_in_place(buf: &mut [u8]) -> Option<Range<usize>> {
    let end = buf.len();
    let cells = Cell::from_mut(buf).as_slice_of_cells();
    let mut code_at = 0;
    let mut code = cells.first()?.get();
    // Codes dropped so far, and the start of the decoded bytes not yet moved down by as many.
    let mut dropped = 0;
    let mut unmoved = 1;
    loop {
        let mut next = code_at + usize::from(code);
        if code == 0 || next >= end {
            if code == 0 || next > end {
                return None;
            }
            move_bytes(cells, unmoved, unmoved - dropped, end - unmoved)?;
            return Some(1..end - dropped);
        }
        if code == 1 {
            // Whole words of `0x01` codes before the last code: empty blocks, all zeros.
            while next + WORD < end {
                let word = cells.get(next..next + WORD)?;
                if load(word) != ONES {
                    break;
                }
                for cell in word {
                    cell.set(0);
                }
                next += WORD;
            }
        }
        let place = cells.get(next)?;
        let full = code == FULL_CODE;
        code = place.get();
        if full {
            move_bytes(cells, unmoved, unmoved - dropped, next - unmoved)?;
            dropped += 1;
            unmoved = next + 1;
        } else {
            place.set(0);
        }
        code_at = next;
    }
}

/// Moves `cells[from..from + len]` to `cells[to..to + len]`, overlapping or not, like
/// `copy_within`, but as a loop over cells: `copy_within` and `rotate_left` each left a
/// bounds-check panic in the firmware's release ELF (not inlined there, so no guard here could
/// discharge it), and cells let one loop read and write the same bytes without indexing.
/// Copying in the direction of the move reads every byte before it is overwritten.
fn move_bytes(cells: &[Cell<u8>], from: usize, to: usize, len: usize) -> Option<()> {
    if from == to {
        return Some(());
    }
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

    /// Byte strings shaped around the encoder's chunks and full blocks: zero-free runs of
    /// about one or two chunks, or one, two or three full blocks, all-zero stretches, and
    /// single zeros, so zeros and run ends fall on every side of chunk boundaries.
    fn chunk_bytes() -> impl Strategy<Value = Vec<u8>> {
        let run = prop_oneof![
            (0usize..=2 * CHUNK + 2).prop_map(|len| vec![0x37; len]),
            prop_oneof![252usize..=256, 506usize..=510, 760usize..=764]
                .prop_map(|len| vec![0xc1; len]),
            (0usize..=2 * CHUNK + 2).prop_map(|len| vec![0; len]),
            Just(vec![0]),
        ];
        proptest::collection::vec(run, 0..10).prop_map(|runs| runs.concat())
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
        fn encode_matches_the_cobs_crate_around_chunks(
            bytes in chunk_bytes(),
            src in 1usize..4,
        ) {
            prop_assert_eq!(encode(&bytes, src, 0), reference(&bytes));
        }

        #[test]
        fn a_buffer_shorter_than_the_encoding_is_refused(
            bytes in prop_oneof![hard_bytes(), chunk_bytes()],
            short in 1usize..4,
        ) {
            // Shorter, but still holding the packet behind the first code.
            let encoded_len = reference(&bytes).len();
            let short = short.min(encoded_len - (1 + bytes.len()));
            if short > 0 {
                let mut buf = vec![0xeeu8; encoded_len - short];
                buf[1..1 + bytes.len()].copy_from_slice(&bytes);
                prop_assert_eq!(encode_in_place(&mut buf, 1, bytes.len()), None);
            }
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

    /// The `cobs` crate's encoding of `bytes`.
    fn reference(bytes: &[u8]) -> Vec<u8> {
        let mut encoded = vec![0u8; cobs::max_encoding_length(bytes.len())];
        let len = cobs::encode(bytes, &mut encoded);
        encoded.truncate(len);
        encoded
    }

    #[test]
    fn long_runs_match_the_cobs_crate_at_every_alignment() {
        let leads: [fn(usize) -> Vec<u8>; 3] = [
            |lead| vec![0x11; lead],
            |lead| vec![0; lead],
            |lead| (0..lead).map(|i| u8::from(i % 3 != 0)).collect(),
        ];
        let tails: [&[u8]; 5] = [&[], &[0], &[0, 0x22], &[0; 70], &[0x22; 10]];
        for lead in leads {
            for lead_len in 0..=2 * CHUNK + 1 {
                for run in [1, 253, 254, 255, 508, 509, 762, 763] {
                    for tail in tails {
                        let mut bytes = lead(lead_len);
                        bytes.push(0);
                        bytes.extend(core::iter::repeat_n(0x5a, run));
                        bytes.extend_from_slice(tail);
                        assert_eq!(
                            encode(&bytes, 1, 0),
                            reference(&bytes),
                            "lead {lead_len}, run {run}, tail {tail:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_too_short_buffer_is_refused() {
        let mut buf = [1u8; 4];
        assert_eq!(encode_in_place(&mut buf, 0, 3), None);
        assert_eq!(encode_in_place(&mut buf, 2, 3), None);
    }
}
