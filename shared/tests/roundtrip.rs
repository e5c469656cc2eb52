//! Every kind survives encode → bytes → decode unchanged, through `decode` and through the
//! accumulator at any chunking; the in-place COBS encoder agrees with the `cobs` crate's.

mod arbitrary;

use arbitrary::{packet, OwnedPacket};
use proptest::collection::vec;
use proptest::prelude::*;
use stereocal_wire::{
    decode, encode, max_encoded_len, Accumulator, FeedResult, PacketRepr, Source, CRC_LEN,
    HEADER_LEN, MAX_ENCODED_LEN, PROTOCOL_VERSION,
};

fn encoded(source: Source, seq: u16, packet: &OwnedPacket) -> Vec<u8> {
    let mut buf = [0u8; MAX_ENCODED_LEN];
    encode(source, seq, &packet.repr(), &mut buf)
        .expect("valid packets encode")
        .to_vec()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn decode_inverts_encode(source in any::<u8>(), seq in any::<u16>(), packet in packet()) {
        let repr = packet.repr();
        let source = Source::from(source);
        let mut frame = encoded(source, seq, &packet);
        prop_assert!(frame.len() <= max_encoded_len(repr.buffer_len()));
        prop_assert_eq!(frame.last(), Some(&0));
        prop_assert!(!frame[..frame.len() - 1].contains(&0));

        let (header, decoded) = decode(&mut frame).expect("own frames decode");
        prop_assert_eq!(header.version, PROTOCOL_VERSION);
        prop_assert_eq!(header.source, source);
        prop_assert_eq!(header.seq, seq);
        prop_assert_eq!(header.kind, repr.kind());
        prop_assert_eq!(usize::from(header.payload_len), repr.buffer_len());
        prop_assert_eq!(decoded, repr);
    }

    #[test]
    fn in_place_cobs_matches_the_cobs_crate(seq in any::<u16>(), packet in packet()) {
        let frame = encoded(Source::Left, seq, &packet);
        let body = &frame[..frame.len() - 1];
        let mut raw = vec![0u8; body.len()];
        let raw_len = cobs::decode(body, &mut raw).expect("valid COBS").frame_size();
        prop_assert_eq!(raw_len, HEADER_LEN + packet.repr().buffer_len() + CRC_LEN);
        let mut reference = vec![0u8; cobs::max_encoding_length(raw_len)];
        let reference_len = cobs::encode(&raw[..raw_len], &mut reference);
        prop_assert_eq!(body, &reference[..reference_len]);
    }

    #[test]
    fn accumulator_reassembles_any_chunking(
        packets in vec(packet(), 1..6),
        chunk_sizes in vec(1usize..700, 1..64),
    ) {
        let stream: Vec<u8> =
            packets.iter().enumerate().flat_map(|(seq, p)| encoded(Source::Right, seq as u16, p)).collect();
        let mut acc = Accumulator::<MAX_ENCODED_LEN>::new();
        let mut received = 0usize;
        let mut offset = 0;
        let mut sizes = chunk_sizes.iter().cycle();
        while offset < stream.len() {
            let end = (offset + sizes.next().unwrap()).min(stream.len());
            let mut window = &stream[offset..end];
            offset = end;
            loop {
                window = match acc.feed(window) {
                    FeedResult::Consumed => break,
                    FeedResult::Success { header, packet, remaining } => {
                        prop_assert_eq!(usize::from(header.seq), received);
                        prop_assert_eq!(packet, packets[received].repr());
                        received += 1;
                        remaining
                    }
                    other => return Err(TestCaseError::fail(format!("{other:?}"))),
                };
            }
        }
        prop_assert_eq!(received, packets.len());
    }
}

#[test]
fn short_output_buffer_is_an_error() {
    let repr = PacketRepr::RegisterRead(stereocal_wire::RegisterReadRepr { addr: 1 });
    let needed = max_encoded_len(repr.buffer_len());
    let mut buf = vec![0u8; needed - 1];
    assert_eq!(
        encode(Source::Control, 0, &repr, &mut buf),
        Err(stereocal_wire::Error::EncodeBufferTooSmall)
    );
    let mut buf = vec![0u8; needed];
    assert!(encode(Source::Control, 0, &repr, &mut buf).is_ok());
}

#[test]
fn max_frame_len_covers_the_largest_packet() {
    // A full-width row whose pixels have no zero byte: COBS worst case (one code byte per 254).
    let pixels = [stereocal_wire::SobelPixel {
        magnitude: 0xff,
        orientation: 0x3f,
    }; 1280];
    let repr = PacketRepr::SobelRows(stereocal_wire::SobelRowsRepr {
        frame_id: u32::MAX,
        camera: stereocal_wire::Camera::Unknown(0xff),
        octave: 0xff,
        scale: 0xff,
        row: u16::MAX,
        x: 0,
        pixels: stereocal_wire::Records::Values(&pixels),
    });
    assert_eq!(repr.buffer_len(), stereocal_wire::MAX_PAYLOAD_LEN);
    let mut buf = [0u8; MAX_ENCODED_LEN];
    let frame = encode(Source::Unknown(0xff), 0xffff, &repr, &mut buf).unwrap();
    assert!(frame.len() <= MAX_ENCODED_LEN);
    let mut frame = frame.to_vec();
    assert_eq!(decode(&mut frame).unwrap().1, repr);
}

/// Runs of non-zero bytes around the 254-byte COBS block length, where the in-place encoder
/// has its only special case (a full block and whether another code byte follows).
#[test]
fn long_nonzero_runs_encode_like_the_cobs_crate() {
    let nonzero = [0xffu8; stereocal_wire::MAX_LOG_LEN];
    let bright = [stereocal_wire::SobelPixel {
        magnitude: 0xff,
        orientation: 0x3f,
    }; 400];
    for len in 0..=nonzero.len() {
        let log = PacketRepr::Log(stereocal_wire::LogRepr {
            frame: &nonzero[..len],
        });
        let rows = PacketRepr::SobelRows(stereocal_wire::SobelRowsRepr {
            frame_id: 0xffff_ffff,
            camera: stereocal_wire::Camera::Unknown(0xff),
            octave: 0xff,
            scale: 0xff,
            row: 0xffff,
            x: 0,
            pixels: stereocal_wire::Records::Values(&bright[..len + 100]),
        });
        for repr in [log, rows] {
            let mut buf = [0u8; MAX_ENCODED_LEN];
            let mut frame = encode(Source::Unknown(0xff), 0xffff, &repr, &mut buf)
                .unwrap()
                .to_vec();
            let body = &frame[..frame.len() - 1];
            let mut raw = vec![0u8; body.len()];
            let raw_len = cobs::decode(body, &mut raw).unwrap().frame_size();
            let mut reference = vec![0u8; cobs::max_encoding_length(raw_len)];
            let reference_len = cobs::encode(&raw[..raw_len], &mut reference);
            assert_eq!(body, &reference[..reference_len], "{repr:?}");
            assert_eq!(decode(&mut frame).unwrap().1, repr);
        }
    }
}
