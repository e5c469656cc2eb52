//! A streaming receiver: bytes in, decoded packets out, at any chunking of the input.

use heapless::Vec;

use crate::cobs_in_place::first_zero;
use crate::framing::{decode_zero_free, Rejected, DELIMITER};
use crate::packet::header::Header;
use crate::packet_repr::PacketRepr;
use crate::Error;

// `first_zero` finds frame ends because the delimiter is the byte COBS removes.
const _: () = assert!(DELIMITER == 0);

/// Collects the bytes of one COBS frame in a buffer of `N` bytes and decodes it when its
/// `0x00` arrives.
///
/// With `N` = [`MAX_ENCODED_LEN`](crate::MAX_ENCODED_LEN) (the alias
/// [`FrameAccumulator`](crate::FrameAccumulator)) every packet kind fits (`MAX_ENCODED_LEN - 1`
/// would do: the delimiter is not stored); a smaller `N` suits a receiver that only expects
/// short packets, such as the firmware's command input. A frame longer than
/// `N` is reported once as [`FeedResult::OverFull`] and skipped up to its delimiter, so the
/// next frame decodes normally. Empty frames (`0x00 0x00`) are ignored: a sender may send a
/// lone `0x00` to flush a receiver's partial frame. With the feature `fec-repair` (the host's
/// receiver) it also recovers the second of two frames that a lost delimiter joined, when
/// both fit in `N` (the wire spec, section 2, "Resynchronisation"): the first is lost, as
/// before, but no longer the second.
#[derive(Debug, Clone)]
pub struct Accumulator<const N: usize> {
    /// The COBS bytes of the frame being received.
    buf: Vec<u8, N>,
    /// `buf` holds a frame that was handed out (decoded in place, borrowed by the last
    /// [`FeedResult`]); the next call empties it first.
    delivered: bool,
    /// Skipping the rest of an over-long frame.
    discarding: bool,
    /// Frames are protected by [`fec`](crate::fec): each is repaired before it decodes.
    #[cfg(feature = "fec-repair")]
    fec: bool,
    /// Blocks [`fec::repair`](crate::fec::repair) repaired, all frames.
    #[cfg(feature = "fec-repair")]
    fec_blocks_repaired: u64,
    /// The second of two link frames that a lost delimiter joined, copied out of `buf`
    /// before `buf` decodes in place, and decoded when the joined frame fails.
    #[cfg(feature = "fec-repair")]
    second: Vec<u8, N>,
}

/// What [`Accumulator::feed`] found. `'de` borrows the accumulator, `'a` the input.
#[derive(Debug)]
pub enum FeedResult<'de, 'a> {
    /// All input was consumed without completing a frame.
    Consumed,
    /// A frame was longer than the buffer and is dropped; feed the remaining input again.
    OverFull(&'a [u8]),
    /// A complete frame failed to decode; feed the remaining input again.
    DecodeError {
        /// What was wrong with the frame.
        error: Error,
        /// The packet's header, when the packet was intact up to its payload (its kind is
        /// unknown, or its payload breaks the kind's layout): the packet used up a number of
        /// its source, which a receiver checking the numbering allows for.
        header: Option<Header>,
        /// Input after the bad frame's delimiter.
        remaining: &'a [u8],
    },
    /// A frame decoded; feed the remaining input again.
    Success {
        /// The packet's header.
        header: Header,
        /// The packet's payload, borrowing the accumulator's buffer.
        packet: PacketRepr<'de>,
        /// Input after the frame's delimiter.
        remaining: &'a [u8],
    },
}

impl<const N: usize> Accumulator<N> {
    /// An empty accumulator.
    pub const fn new() -> Self {
        Accumulator {
            buf: Vec::new(),
            delivered: false,
            discarding: false,
            #[cfg(feature = "fec-repair")]
            fec: false,
            #[cfg(feature = "fec-repair")]
            fec_blocks_repaired: 0,
            #[cfg(feature = "fec-repair")]
            second: Vec::new(),
        }
    }

    /// Whether the frames that complete from now on are protected by forward error
    /// correction (feature `fec-repair`) (`N` must then hold [`MAX_PROTECTED_LEN`](crate::MAX_PROTECTED_LEN) bytes
    /// for every kind to fit).
    #[cfg(feature = "fec-repair")]
    pub fn set_fec(&mut self, on: bool) {
        self.fec = on;
    }

    /// Whether frames are taken as protected by forward error correction.
    #[cfg(feature = "fec-repair")]
    pub fn fec(&self) -> bool {
        self.fec
    }

    /// Blocks forward error correction has repaired so far.
    #[cfg(feature = "fec-repair")]
    pub fn fec_blocks_repaired(&self) -> u64 {
        self.fec_blocks_repaired
    }

    /// Drops any partial frame (e.g. after reopening the link).
    pub fn reset(&mut self) {
        self.buf.clear();
        self.delivered = false;
        self.discarding = false;
    }

    /// Takes input up to and including the first frame delimiter that completes a frame, and
    /// reports what happened; call again with the remaining input until [`FeedResult::Consumed`].
    /// Never panics, whatever the input.
    pub fn feed<'de, 'a>(&'de mut self, input: &'a [u8]) -> FeedResult<'de, 'a> {
        if self.delivered {
            self.buf.clear();
            self.delivered = false;
        }
        let mut input = input;
        loop {
            // A word-at-a-time scan: a full-Sobel stream is megabytes per frame pair, and a
            // byte-wise split was a visible part of the host's decoding.
            let end = first_zero(input);
            let (chunk, delimited, rest) = match (input.get(..end), input.get(end + 1..)) {
                (Some(chunk), Some(rest)) => (chunk, true, rest),
                _ => (input, false, &[][..]),
            };
            if self.discarding {
                if !delimited {
                    return FeedResult::Consumed;
                }
                self.discarding = false;
                input = rest;
                continue;
            }
            if self.buf.extend_from_slice(chunk).is_err() {
                // Nothing was copied: the chunk does not fit in what is left of the buffer.
                self.buf.clear();
                self.discarding = !delimited;
                return FeedResult::OverFull(rest);
            }
            if !delimited {
                return FeedResult::Consumed;
            }
            if self.buf.is_empty() {
                input = rest;
                continue;
            }
            self.delivered = true;
            #[cfg(feature = "fec-repair")]
            {
                self.second.clear();
                if let Some(at) = crate::joined::second_frame_at(&self.buf, self.fec) {
                    // Both are at most `N` long, so the copy fits.
                    let _ = self
                        .second
                        .extend_from_slice(self.buf.get(at..).unwrap_or(&[]));
                }
                let repaired = &mut self.fec_blocks_repaired;
                let result = decode_link_frame(&mut self.buf, self.fec, repaired, rest);
                if matches!(result, FeedResult::DecodeError { .. }) && !self.second.is_empty() {
                    return decode_link_frame(&mut self.second, self.fec, repaired, rest);
                }
                return result;
            }
            #[cfg(not(feature = "fec-repair"))]
            return decode_body(&mut self.buf, rest);
        }
    }
}

/// Repairs one link frame's bytes in place when `protected` (counting the blocks repaired in
/// `repaired`), then decodes them.
#[cfg(feature = "fec-repair")]
fn decode_link_frame<'de, 'a, const N: usize>(
    frame: &'de mut Vec<u8, N>,
    protected: bool,
    repaired: &mut u64,
    rest: &'a [u8],
) -> FeedResult<'de, 'a> {
    if protected {
        match crate::fec::repair(frame) {
            Ok(done) => {
                frame.truncate(done.body_len);
                *repaired += u64::from(done.blocks_repaired);
            }
            Err(error) => {
                return FeedResult::DecodeError {
                    error,
                    header: None,
                    remaining: rest,
                }
            }
        }
    }
    decode_body(frame, rest)
}

/// Decodes the COBS bytes of one link frame in place. Every chunk was cut before a zero, so
/// they hold none.
fn decode_body<'de, 'a>(body: &'de mut [u8], rest: &'a [u8]) -> FeedResult<'de, 'a> {
    match decode_zero_free(body) {
        Ok((header, packet)) => FeedResult::Success {
            header,
            packet,
            remaining: rest,
        },
        Err(Rejected { error, header }) => FeedResult::DecodeError {
            error,
            header,
            remaining: rest,
        },
    }
}

impl<const N: usize> Default for Accumulator<N> {
    fn default() -> Self {
        Self::new()
    }
}
