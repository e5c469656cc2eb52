//! Damaged input: every failure is a typed error, nothing panics, and the receiver is back in
//! step at the next frame delimiter.

mod arbitrary;

use arbitrary::{packet, OwnedPacket};
use proptest::collection::vec;
use proptest::prelude::*;
use stereocal_wire::{
    crc32c, decode, encode, Accumulator, Error, FeedResult, Header, HelloRepr, PacketKind,
    PacketRepr, RegisterReadRepr, Source, CRC_LEN, MAX_ENCODED_LEN, PROTOCOL_VERSION,
};

fn encoded(seq: u16, packet: &PacketRepr<'_>) -> Vec<u8> {
    let mut buf = [0u8; MAX_ENCODED_LEN];
    encode(Source::Control, seq, packet, &mut buf)
        .expect("valid packets encode")
        .to_vec()
}

/// A frame around arbitrary packet bytes, with a correct CRC appended.
fn frame_around(packet_without_crc: &[u8]) -> Vec<u8> {
    let mut raw = packet_without_crc.to_vec();
    raw.extend_from_slice(&crc32c(packet_without_crc).to_le_bytes());
    let mut out = vec![0u8; cobs::max_encoding_length(raw.len()) + 1];
    let len = cobs::encode(&raw, &mut out);
    out.truncate(len);
    out.push(0);
    out
}

/// What the accumulator made of a stream.
#[derive(Debug, Default)]
struct Outcome {
    /// Decoded packets as (seq, repr); only `RegisterRead` reprs are kept, others become a
    /// placeholder `Hello` so the record outlives the accumulator's buffer.
    packets: Vec<(u16, PacketRepr<'static>)>,
    errors: Vec<Error>,
    overfull: usize,
}

/// Feeds `stream` in one go (the tests put `RegisterRead` markers around the damage).
fn run<const N: usize>(stream: &[u8]) -> Outcome {
    feed_all(Accumulator::<N>::new(), stream)
}

/// Feeds `stream` to `acc` in one go.
fn feed_all<const N: usize>(mut acc: Accumulator<N>, stream: &[u8]) -> Outcome {
    let mut outcome = Outcome::default();
    let mut window = stream;
    loop {
        window = match acc.feed(window) {
            FeedResult::Consumed => break,
            FeedResult::OverFull(rest) => {
                outcome.overfull += 1;
                rest
            }
            FeedResult::DecodeError {
                error, remaining, ..
            } => {
                outcome.errors.push(error);
                remaining
            }
            FeedResult::Success {
                header,
                packet,
                remaining,
            } => {
                let kept = match packet {
                    PacketRepr::RegisterRead(r) => PacketRepr::RegisterRead(r),
                    _ => PacketRepr::Hello(HelloRepr {
                        version: 0,
                        capabilities: stereocal_wire::Capabilities(0),
                    }),
                };
                outcome.packets.push((header.seq, kept));
                remaining
            }
        };
    }
    outcome
}

fn marker(addr: u16) -> PacketRepr<'static> {
    PacketRepr::RegisterRead(RegisterReadRepr { addr })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// Flipped bits inside one frame (never its delimiter): that frame is reported as an error
    /// (or, where a flip made a `0x00`, as several), its neighbours decode.
    #[test]
    fn bit_flips_are_caught_and_neighbours_survive(
        packet in packet(),
        flips in vec((any::<prop::sample::Index>(), 0u8..8), 1..8),
    ) {
        let mut damaged = encoded(1, &packet.repr());
        let body_len = damaged.len() - 1;
        for (at, bit) in &flips {
            damaged[at.index(body_len)] ^= 1 << bit;
        }
        prop_assume!(damaged != encoded(1, &packet.repr()));
        let stream = [encoded(0, &marker(0xa)), damaged, encoded(2, &marker(0xb))].concat();
        let outcome = run::<MAX_ENCODED_LEN>(&stream);
        prop_assert_eq!(&outcome.packets, &vec![(0, marker(0xa)), (2, marker(0xb))]);
        prop_assert!(!outcome.errors.is_empty());
    }

    /// A frame cut short runs into the next frame, which is lost with it; the one after decodes.
    #[test]
    fn truncation_costs_at_most_the_next_frame(packet in packet(), cut in any::<prop::sample::Index>()) {
        let whole = encoded(1, &packet.repr());
        let mut cut_frame = whole[..cut.index(whole.len() - 1)].to_vec();
        let direct = decode(&mut cut_frame);
        prop_assert!(direct.is_err(), "a truncated frame decoded: {:?}", direct);
        let stream = [
            encoded(0, &marker(0xa)),
            whole[..cut.index(whole.len() - 1)].to_vec(),
            encoded(2, &marker(0xb)),
            encoded(3, &marker(0xc)),
        ]
        .concat();
        let outcome = run::<MAX_ENCODED_LEN>(&stream);
        prop_assert_eq!(outcome.packets.first(), Some(&(0, marker(0xa))));
        prop_assert_eq!(outcome.packets.last(), Some(&(3, marker(0xc))));
    }

    /// Garbage between frames: the frame before decodes, the frame after the next delimiter
    /// decodes, nothing in between decodes into a wrong packet.
    #[test]
    fn garbage_between_frames_resyncs(garbage in vec(any::<u8>(), 0..3000)) {
        let stream = [
            encoded(0, &marker(0xa)),
            garbage.clone(),
            encoded(2, &marker(0xb)),
            encoded(3, &marker(0xc)),
        ]
        .concat();
        let outcome = run::<MAX_ENCODED_LEN>(&stream);
        prop_assert_eq!(outcome.packets.first(), Some(&(0, marker(0xa))));
        prop_assert_eq!(outcome.packets.last(), Some(&(3, marker(0xc))));
        for middle in &outcome.packets[1..outcome.packets.len() - 1] {
            prop_assert_eq!(middle, &(2, marker(0xb)));
        }
        if garbage.last().is_none_or(|&b| b == 0) {
            prop_assert_eq!(outcome.packets.len(), 3);
        }
    }

    /// Arbitrary bytes never panic the accumulator or `decode`, whatever the buffer size.
    #[test]
    fn arbitrary_bytes_never_panic(bytes in vec(any::<u8>(), 0..4000)) {
        run::<MAX_ENCODED_LEN>(&bytes);
        run::<16>(&bytes);
        let mut copy = bytes.clone();
        let _ = decode(&mut copy);
    }

    /// Arbitrary packet bytes with a valid CRC reach the field checks: a typed error or a
    /// packet, never a panic.
    #[test]
    fn arbitrary_packets_with_valid_crc_never_panic(
        kind in prop_oneof![Just(0x01u8), Just(0x02), Just(0x03), Just(0x04), Just(0x10), Just(0x11),
                            Just(0x12), Just(0x13), Just(0x14), Just(0x20), Just(0x21), any::<u8>()],
        len_field in any::<u16>(),
        payload in vec(any::<u8>(), 0..3000),
    ) {
        let mut raw = vec![PROTOCOL_VERSION, kind, 0, 0, 0];
        raw.extend_from_slice(&len_field.to_le_bytes());
        raw.extend_from_slice(&payload);
        let _ = decode(&mut frame_around(&raw));
    }
}

#[test]
fn each_failure_has_its_error() {
    let good = [
        PROTOCOL_VERSION,
        0x03,
        0x01,
        0x07,
        0x00,
        0x02,
        0x00,
        0x34,
        0x12,
    ];
    let mut frame = frame_around(&good);
    let (header, repr) = decode(&mut frame).unwrap();
    assert_eq!(
        (header.source, header.seq, repr),
        (Source::Left, 7, marker(0x1234))
    );

    for version in [0, 1, 2, 4] {
        let mut bad_version = good;
        bad_version[0] = version;
        assert_eq!(
            decode(&mut frame_around(&bad_version)).unwrap_err(),
            Error::DecodeUnknownVersion
        );
    }

    let mut bad_kind = good;
    bad_kind[1] = 0x7f;
    assert_eq!(
        decode(&mut frame_around(&bad_kind)).unwrap_err(),
        Error::DecodeUnknownKind
    );

    let mut long_field = good;
    long_field[5] = 3;
    assert_eq!(
        decode(&mut frame_around(&long_field)).unwrap_err(),
        Error::DecodeUnexpectedEnd
    );

    let mut short_field = good;
    short_field[5] = 1;
    assert_eq!(
        decode(&mut frame_around(&short_field)).unwrap_err(),
        Error::DecodeBadLength
    );

    let mut extra_payload = good.to_vec();
    extra_payload[5] = 3;
    extra_payload.push(0x55);
    assert_eq!(
        decode(&mut frame_around(&extra_payload)).unwrap_err(),
        Error::DecodeBadLength
    );

    let mut bad_crc = frame_around(&good);
    let crc_byte = bad_crc.len() - 1 - CRC_LEN;
    bad_crc[crc_byte] ^= 0x01;
    assert_eq!(decode(&mut bad_crc).unwrap_err(), Error::DecodeBadCrc);

    assert_eq!(
        decode(&mut frame_around(&good[..6])).unwrap_err(),
        Error::DecodeUnexpectedEnd
    );
    assert_eq!(decode(&mut []).unwrap_err(), Error::DecodeUnexpectedEnd);
    assert_eq!(decode(&mut [0]).unwrap_err(), Error::DecodeUnexpectedEnd);
    // A code byte pointing past the end of the frame.
    assert_eq!(
        decode(&mut [0x05, 0x01, 0x00]).unwrap_err(),
        Error::DecodeBadCobs
    );
    // A delimiter inside the frame.
    assert_eq!(
        decode(&mut [0x02, 0x01, 0x00, 0x02, 0x01]).unwrap_err(),
        Error::DecodeBadCobs
    );
}

/// An intact packet whose kind or payload the receiver cannot read still says who sent it
/// and its number, so the receiver's numbering of that source goes on without a gap; a
/// damaged packet says nothing.
#[test]
fn an_intact_header_comes_with_the_error() {
    let unknown_kind = [PROTOCOL_VERSION, 0x7f, 0x02, 0x09, 0x00, 0x00, 0x00];
    let bad_payload = [PROTOCOL_VERSION, 0x03, 0x01, 0x0a, 0x00, 0x01, 0x00, 0x34];
    let mut damaged = frame_around(&unknown_kind);
    damaged[3] ^= 0x01;
    let stream = [
        frame_around(&unknown_kind),
        frame_around(&bad_payload),
        damaged,
    ]
    .concat();
    let mut acc = Accumulator::<MAX_ENCODED_LEN>::new();
    let mut window = &stream[..];
    let mut seen = Vec::new();
    while let FeedResult::DecodeError {
        error,
        header,
        remaining,
    } = acc.feed(window)
    {
        seen.push((error, header));
        window = remaining;
    }
    let header = |kind, source, seq, payload_len| Header {
        version: PROTOCOL_VERSION,
        kind,
        source,
        seq,
        payload_len,
    };
    assert_eq!(
        seen,
        [
            (
                Error::DecodeUnknownKind,
                Some(header(PacketKind::Unknown(0x7f), Source::Right, 9, 0))
            ),
            (
                Error::DecodeUnexpectedEnd,
                Some(header(PacketKind::RegisterRead, Source::Left, 10, 1))
            ),
            (Error::DecodeBadCrc, None),
        ]
    );
}

#[test]
fn overlong_frame_is_reported_once_and_skipped() {
    let long = OwnedPacket::Log(vec![0x55; 200]);
    let stream = [encoded(0, &long.repr()), encoded(1, &marker(0xb))].concat();
    let outcome = run::<64>(&stream);
    assert_eq!(outcome.overfull, 1);
    assert!(outcome.errors.is_empty());
    assert_eq!(outcome.packets, vec![(1, marker(0xb))]);

    // The same when the overlong frame arrives in pieces.
    let mut acc = Accumulator::<64>::new();
    let mut results = Vec::new();
    for chunk in stream.chunks(7) {
        let mut window = chunk;
        loop {
            window = match acc.feed(window) {
                FeedResult::Consumed => break,
                FeedResult::OverFull(rest) => {
                    results.push("overfull");
                    rest
                }
                FeedResult::DecodeError { remaining, .. } => {
                    results.push("error");
                    remaining
                }
                FeedResult::Success { remaining, .. } => {
                    results.push("packet");
                    remaining
                }
            };
        }
    }
    assert_eq!(results, ["overfull", "packet"]);
}

#[test]
fn lone_delimiters_are_idle_and_flush_a_partial_frame() {
    let frame = encoded(5, &marker(0xb));
    let stream = [&[0u8, 0, 0][..], &frame[..3], &[0], &frame, &[0, 0]].concat();
    let outcome = run::<MAX_ENCODED_LEN>(&stream);
    assert_eq!(outcome.packets, vec![(5, marker(0xb))]);
    assert_eq!(outcome.errors.len(), 1);
}

/// `packet` encoded, and protected by the forward error correction when `protected`; with its
/// delimiter.
#[cfg(feature = "fec-repair")]
fn link_frame(seq: u16, packet: &PacketRepr<'_>, protected: bool) -> Vec<u8> {
    let plain = encoded(seq, packet);
    if !protected {
        return plain;
    }
    let body = plain.len() - 1;
    let mut frame = plain;
    frame.resize(stereocal_wire::fec::protected_len(body) + 1, 0);
    let total = stereocal_wire::fec::protect(&mut frame, body).expect("protects");
    frame.truncate(total);
    frame.push(0);
    frame
}

/// What the accumulator makes of `stream`, its frames protected when `protected`.
#[cfg(feature = "fec-repair")]
fn run_guarded(stream: &[u8], protected: bool) -> Outcome {
    let mut acc = Accumulator::<{ stereocal_wire::MAX_PROTECTED_LEN }>::new();
    acc.set_fec(protected);
    feed_all(acc, stream)
}

#[cfg(feature = "fec-repair")]
proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// A flip that unmakes the delimiter between two frames joins them: the first packet is
    /// lost, the second decodes, with or without the forward error correction, whatever the
    /// packets and the byte the delimiter became, as long as the two fit the receiver's buffer
    /// together (a longer run of bytes is skipped as over-long).
    #[test]
    fn a_lost_delimiter_costs_only_the_frame_before_it(
        first in packet(),
        second in packet(),
        flipped in 1u8..=255,
        protected in any::<bool>(),
    ) {
        let mut joined = link_frame(1, &first.repr(), protected);
        *joined.last_mut().unwrap() = flipped;
        let second = link_frame(2, &second.repr(), protected);
        prop_assume!(joined.len() + second.len() - 1 <= stereocal_wire::MAX_PROTECTED_LEN);
        let stream = [
            link_frame(0, &marker(0xa), protected),
            joined,
            second,
            link_frame(3, &marker(0xc), protected),
        ]
        .concat();
        let outcome = run_guarded(&stream, protected);
        let seqs: Vec<u16> = outcome.packets.iter().map(|p| p.0).collect();
        prop_assert_eq!(seqs, vec![0, 2, 3], "errors {:?}", outcome.errors);
        prop_assert_eq!(outcome.errors.len(), 0, "{:?}", outcome.errors);
    }

    /// A damaged byte that the code repairs, even in the header's length, leaves the frame
    /// whole: it is not taken for two joined frames.
    #[test]
    fn a_repaired_header_is_not_a_joined_frame(
        packet in packet(),
        at in 0usize..8,
        flip in 1u8..=255,
    ) {
        let mut damaged = link_frame(1, &packet.repr(), true);
        let at = at.min(damaged.len() - 2);
        damaged[at] ^= flip;
        prop_assume!(damaged[at] != 0);
        let stream = [damaged, link_frame(2, &marker(0xb), true)].concat();
        let outcome = run_guarded(&stream, true);
        let seqs: Vec<u16> = outcome.packets.iter().map(|p| p.0).collect();
        prop_assert_eq!(seqs, vec![1, 2]);
    }
}
