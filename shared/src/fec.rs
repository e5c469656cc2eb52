//! Forward error correction of link frames: optional, asked for by the host in `Hello`
//! ([`Capabilities::FEC`](crate::Capabilities::FEC)), device to host only.
//!
//! The CRC turns a damaged link frame into a lost one. On a link whose bit errors are frequent
//! enough that many frames carry one, a Reed-Solomon code repairs them instead. A link frame's
//! COBS bytes (its *body*, which holds no zero) are cut into blocks of [`BLOCK_DATA`] bytes, and
//! RS(255, 239) over GF(2⁸) gives each block [`ECC_LEN`] parity bytes (the last block is a
//! shortened code), which repair up to `ECC_LEN / 2` damaged bytes anywhere in the block and
//! its parity. Parity bytes may be zero, which would end the link frame, so they go on the wire
//! packed seven bits to a byte with the top bit set. A protected link frame is
//! `body ++ packed parity ++ 0x00`; the body's length follows from the frame's
//! ([`body_len`]).
//!
//! The code covers the COBS bytes rather than the packet: a flipped COBS code byte moves every
//! zero after it, which no byte code could repair after COBS decoding. What it cannot repair
//! is a flip that makes a zero or unmakes the delimiter (it splits or joins link frames), a
//! dropped byte, and more than 8 damaged bytes in one block: those frames fail as without FEC.
//!
//! Overhead: 16 parity bytes per 239 body bytes, times 8/7 for the packing, 7.7 %. The
//! receiver re-encodes every block and compares the parity, which costs what encoding does;
//! only a block whose parity differs goes to the decoder.
//!
//! The sender's side is the code's linear-feedback shift register, written here (a dozen
//! lines over constant tables) because it runs on the soft-core, whose release ELF must link
//! no panicking path, and is what a hardware framer in the fabric implements; the test
//! `parity_equals_the_reed_solomon_crate` proves its parity identical to the `reed-solomon`
//! crate's encoder. The receiver's side, the decoder (syndromes, Berlekamp-Massey, Forney),
//! is that crate's, behind the `fec-repair` feature the host enables.

use crate::Error;

/// Parity bytes per block.
pub const ECC_LEN: usize = 16;
/// Body bytes per block (the last block may be shorter).
pub const BLOCK_DATA: usize = 255 - ECC_LEN;

/// Parity bytes of a `body_len`-byte body.
pub const fn parity_len(body_len: usize) -> usize {
    body_len.div_ceil(BLOCK_DATA) * ECC_LEN
}

/// Wire bytes of `n` parity bytes packed seven bits per byte.
pub const fn packed_len(n: usize) -> usize {
    (8 * n).div_ceil(7)
}

/// A protected link frame's length, delimiter excluded, for a `body_len`-byte body.
pub const fn protected_len(body_len: usize) -> usize {
    body_len + packed_len(parity_len(body_len))
}

/// Most parity bytes any link frame has (the body of [`MAX_ENCODED_LEN`](crate::MAX_ENCODED_LEN)).
#[cfg(feature = "fec-repair")]
const MAX_PARITY: usize = parity_len(crate::MAX_ENCODED_LEN);

/// GF(2⁸) with the primitive polynomial `0x11d` (x⁸ + x⁴ + x³ + x² + 1) and generator 2, the
/// field of the `reed-solomon` crate: `EXP[i] = 2^i` over two periods, so that the sum of
/// two logarithms indexes it directly, and `LOG[EXP[i]] = i` (`LOG[0]` is unused).
struct Field {
    exp: [u8; 512],
    log: [u8; 256],
}

const FIELD: Field = {
    let (mut exp, mut log) = ([0u8; 512], [0u8; 256]);
    let mut x: u16 = 1;
    let mut i = 0;
    while i < 255 {
        exp[i] = x as u8;
        exp[i + 255] = x as u8;
        log[x as usize] = i as u8;
        x <<= 1;
        if x & 0x100 != 0 {
            x ^= 0x11d;
        }
        i += 1;
    }
    Field { exp, log }
};

/// The code's generator polynomial `(x - 2^0) (x - 2^1) … (x - 2^15)` times each byte value
/// `f`: entry `f` holds `f · g_k` for the generator's coefficients below its leading 1,
/// highest degree in the top byte, so that the shift register is one `u128` and a step is a
/// shift, a lookup and an XOR (as a table-driven CRC steps).
const GENERATOR_TIMES: [u128; 256] = {
    // Coefficients, highest degree first: start from 1 and multiply by (x + 2^i) in turn.
    let mut g = [0u8; ECC_LEN + 1];
    g[0] = 1;
    let mut degree = 0;
    while degree < ECC_LEN {
        let root_log = degree;
        // g · (x + root): every coefficient moves one degree up, plus root times itself.
        let mut next = [0u8; ECC_LEN + 1];
        let mut k = 0;
        while k <= degree {
            next[k] ^= g[k];
            if g[k] != 0 {
                next[k + 1] ^= FIELD.exp[FIELD.log[g[k] as usize] as usize + root_log];
            }
            k += 1;
        }
        g = next;
        degree += 1;
    }
    let mut table = [0u128; 256];
    let mut f = 1;
    while f < 256 {
        let mut row = 0u128;
        let mut k = 0;
        while k < ECC_LEN {
            let c = g[k + 1];
            let product = if c == 0 {
                0
            } else {
                FIELD.exp[FIELD.log[f] as usize + FIELD.log[c as usize] as usize]
            };
            row |= (product as u128) << (8 * (ECC_LEN - 1 - k));
            k += 1;
        }
        table[f] = row;
        f += 1;
    }
    table
};

/// The [`ECC_LEN`] parity bytes of one block: the remainder of `block · x^16` divided by the
/// generator, by the shift register a hardware encoder has.
fn parity_of(block: &[u8]) -> [u8; ECC_LEN] {
    let mut register = 0u128;
    for &byte in block {
        let feedback = byte ^ (register >> (8 * (ECC_LEN - 1))) as u8;
        register = (register << 8) ^ GENERATOR_TIMES[usize::from(feedback)];
    }
    register.to_be_bytes()
}

/// Protects the body `frame[..body_len]`: writes its packed parity behind it and returns the
/// protected length ([`protected_len`]); the caller adds the delimiter.
pub fn protect(frame: &mut [u8], body_len: usize) -> Result<usize, Error> {
    let total = protected_len(body_len);
    if body_len == 0 {
        return Err(Error::EncodeBufferTooSmall);
    }
    let (body, tail) = frame
        .split_at_mut_checked(body_len)
        .ok_or(Error::EncodeBufferTooSmall)?;
    let packed = tail
        .get_mut(..total - body_len)
        .ok_or(Error::EncodeBufferTooSmall)?;
    let mut packer = Packer::new(packed);
    for block in body.chunks(BLOCK_DATA) {
        for byte in parity_of(block) {
            packer.push(byte);
        }
    }
    packer.finish();
    Ok(total)
}

/// The body length of a protected link frame `frame_len` bytes long (delimiter excluded);
/// `None` when no body length gives it.
pub fn body_len(frame_len: usize) -> Option<usize> {
    // `protected_len` grows with the body, so one block count at most fits.
    (1..=frame_len / BLOCK_DATA + 1).find_map(|blocks| {
        let body = frame_len.checked_sub(packed_len(blocks * ECC_LEN))?;
        (body > 0 && body.div_ceil(BLOCK_DATA) == blocks).then_some(body)
    })
}

/// What [`repair`] did to a link frame.
#[cfg(feature = "fec-repair")]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Repaired {
    /// Length of the body, now at the start of the frame.
    pub body_len: usize,
    /// Blocks that had damage and were repaired.
    pub blocks_repaired: u32,
}

/// Repairs a protected link frame (delimiter excluded) in place: afterwards its first
/// `body_len` bytes are the body as sent. `DecodeBadFec` when the length fits no body or a
/// block has more damage than the code repairs.
#[cfg(feature = "fec-repair")]
pub fn repair(frame: &mut [u8]) -> Result<Repaired, Error> {
    let body_len = body_len(frame.len()).ok_or(Error::DecodeBadFec)?;
    let parity_len = parity_len(body_len);
    let mut parity = [0u8; MAX_PARITY];
    let parity = parity.get_mut(..parity_len).ok_or(Error::DecodeBadFec)?;
    unpack(&frame[body_len..], parity);
    let decoder = reed_solomon::Decoder::new(ECC_LEN);
    let mut blocks_repaired = 0;
    let mut codeword = [0u8; BLOCK_DATA + ECC_LEN];
    let blocks = frame[..body_len].chunks_mut(BLOCK_DATA);
    for (block, ecc) in blocks.zip(parity.chunks(ECC_LEN)) {
        // An intact block re-encodes to its parity (zero syndromes): the shift register
        // checks that at the encoder's speed, and only a damaged block goes to the decoder.
        if parity_of(block)[..] == *ecc {
            continue;
        }
        let n = block.len();
        codeword[..n].copy_from_slice(block);
        codeword[n..n + ECC_LEN].copy_from_slice(ecc);
        let fixed = decoder
            .correct(&codeword[..n + ECC_LEN], None)
            .map_err(|_| Error::DecodeBadFec)?;
        block.copy_from_slice(fixed.data());
        blocks_repaired += 1;
    }
    Ok(Repaired {
        body_len,
        blocks_repaired,
    })
}

/// Packs bytes into seven-bit groups, each written with the top bit set (never zero).
struct Packer<'a> {
    out: &'a mut [u8],
    at: usize,
    bits: u32,
    held: u32,
}

impl<'a> Packer<'a> {
    fn new(out: &'a mut [u8]) -> Self {
        Self {
            out,
            at: 0,
            bits: 0,
            held: 0,
        }
    }

    fn emit(&mut self, seven: u32) {
        if let Some(slot) = self.out.get_mut(self.at) {
            *slot = 0x80 | (seven & 0x7F) as u8;
        }
        self.at += 1;
    }

    fn push(&mut self, byte: u8) {
        self.bits = (self.bits << 8) | u32::from(byte);
        self.held += 8;
        while self.held >= 7 {
            self.held -= 7;
            self.emit(self.bits >> self.held);
        }
        self.bits &= (1 << self.held) - 1;
    }

    /// Writes the last bits, left-aligned in their group.
    fn finish(mut self) {
        if self.held > 0 {
            self.emit(self.bits << (7 - self.held));
        }
    }
}

/// Unpacks [`Packer`]'s groups into `out` (top bits ignored: a flip there costs nothing).
#[cfg(feature = "fec-repair")]
fn unpack(packed: &[u8], out: &mut [u8]) {
    let (mut bits, mut held, mut at) = (0u32, 0u32, 0);
    for &group in packed {
        bits = (bits << 7) | u32::from(group & 0x7F);
        held += 7;
        if held >= 8 {
            held -= 8;
            if let Some(slot) = out.get_mut(at) {
                *slot = (bits >> held) as u8;
            }
            at += 1;
            bits &= (1 << held) - 1;
        }
    }
}

#[cfg(all(test, feature = "fec-repair"))]
mod tests {
    extern crate std;
    use std::{vec, vec::Vec};

    use super::*;

    /// A zero-free body of `n` bytes.
    fn body(n: usize) -> Vec<u8> {
        (0..n).map(|i| (i * 37 % 255 + 1) as u8).collect()
    }

    fn protected(n: usize) -> Vec<u8> {
        let mut frame = body(n);
        frame.resize(protected_len(n), 0);
        assert_eq!(protect(&mut frame, n), Ok(protected_len(n)));
        frame
    }

    #[test]
    fn a_protected_frame_holds_no_zero_and_gives_back_its_body() {
        for n in [
            1,
            2,
            7,
            238,
            239,
            240,
            478,
            1000,
            crate::MAX_ENCODED_LEN - 1,
        ] {
            let mut frame = protected(n);
            assert!(!frame.contains(&0), "body {n}");
            assert_eq!(body_len(frame.len()), Some(n));
            let repaired = repair(&mut frame).unwrap();
            assert_eq!(repaired.body_len, n);
            assert_eq!(repaired.blocks_repaired, 0);
            assert_eq!(&frame[..n], &body(n)[..]);
        }
    }

    #[test]
    fn eight_damaged_bytes_per_block_are_repaired_and_nine_are_an_error() {
        let n = 3 * BLOCK_DATA + 17;
        let clean = protected(n);
        let mut frame = clean.clone();
        // Eight bytes in each full block's body, and one parity bit of the short last block
        // (parity byte 49 of 64, in packed byte 56).
        for block in 0..3 {
            for k in 0..8 {
                frame[block * BLOCK_DATA + 29 * k] ^= 0x5A;
            }
        }
        frame[n + 56] ^= 0x01;
        let repaired = repair(&mut frame).unwrap();
        assert_eq!(repaired.blocks_repaired, 4);
        assert_eq!(&frame[..n], &clean[..n]);
        let mut frame = clean.clone();
        for k in 0..9 {
            frame[BLOCK_DATA + 20 * k] ^= 0xFF;
        }
        assert_eq!(repair(&mut frame), Err(Error::DecodeBadFec));
    }

    #[test]
    fn lengths_no_body_gives_are_an_error() {
        assert_eq!(body_len(0), None);
        assert_eq!(repair(&mut []), Err(Error::DecodeBadFec));
        // One body byte makes 1 + 19 bytes; 19 bytes is no protected frame.
        assert_eq!(protected_len(1), 20);
        assert_eq!(body_len(19), None);
        assert_eq!(repair(&mut [1; 19]), Err(Error::DecodeBadFec));
    }

    #[test]
    fn parity_equals_the_reed_solomon_crate() {
        let encoder = reed_solomon::Encoder::new(ECC_LEN);
        let mut seed = 0x1234_5678u32;
        for len in [1, 2, 16, 100, 238, 239] {
            for _ in 0..20 {
                let block: Vec<u8> = (0..len)
                    .map(|_| {
                        seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                        (seed >> 24) as u8
                    })
                    .collect();
                assert_eq!(
                    &parity_of(&block)[..],
                    encoder.encode(&block).ecc(),
                    "{len}"
                );
            }
        }
        assert_eq!(parity_of(&[0; 239]), [0; ECC_LEN]);
    }

    #[test]
    fn packing_round_trips_every_byte_value() {
        let bytes: Vec<u8> = (0..=255).collect();
        let mut packed = vec![0; packed_len(bytes.len())];
        let mut packer = Packer::new(&mut packed);
        bytes.iter().for_each(|&b| packer.push(b));
        packer.finish();
        assert!(packed.iter().all(|&b| b & 0x80 != 0));
        let mut out = vec![0; bytes.len()];
        unpack(&packed, &mut out);
        assert_eq!(out, bytes);
    }
}
