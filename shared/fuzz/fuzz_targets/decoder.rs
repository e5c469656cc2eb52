//! Arbitrary bytes into the receiving side: the streaming accumulator (at two buffer sizes and
//! a data-dependent chunking) and `decode` on the whole input. Nothing may panic, every
//! packet that decodes must survive encode → decode unchanged, and after the input, whatever
//! state it left the accumulator in, one `0x00` and a valid frame must give exactly that frame
//! (resynchronisation at the next delimiter).
//!
//! The crate skips the CRC check under `cfg(fuzzing)`, so mutated frames reach the field checks.
#![no_main]

use libfuzzer_sys::fuzz_target;
use stereocal_wire::{
    decode, encode, Accumulator, FeedResult, PacketRepr, RegisterReadRepr, Source, DELIMITER,
    MAX_ENCODED_LEN,
};

const MARKER_SEQ: u16 = 0xBEEF;
const MARKER: PacketRepr<'static> = PacketRepr::RegisterRead(RegisterReadRepr { addr: 0x1234 });

fn feed_all<const N: usize>(acc: &mut Accumulator<N>, mut window: &[u8]) {
    loop {
        window = match acc.feed(window) {
            FeedResult::Consumed => return,
            FeedResult::OverFull(rest) => rest,
            FeedResult::DecodeError { remaining, .. } => remaining,
            FeedResult::Success {
                header,
                packet,
                remaining,
            } => {
                let mut buf = [0u8; MAX_ENCODED_LEN];
                let frame = encode(header.source, header.seq, &packet, &mut buf)
                    .expect("a decoded packet re-encodes");
                let mut frame = frame.to_vec();
                let (again_header, again) =
                    decode(&mut frame).expect("a re-encoded packet decodes");
                assert_eq!(again_header, header);
                assert_eq!(again, packet);
                remaining
            }
        };
    }
}

/// Ends whatever the fuzz input left behind with one delimiter, then requires the marker frame
/// (short enough for the 32-byte accumulator) to decode as itself with nothing else reported.
fn resyncs<const N: usize>(acc: &mut Accumulator<N>, marker_frame: &[u8]) {
    feed_all(acc, &[DELIMITER]);
    match acc.feed(marker_frame) {
        FeedResult::Success {
            header,
            packet,
            remaining,
        } => {
            assert_eq!(header.seq, MARKER_SEQ);
            assert_eq!(packet, MARKER);
            assert!(remaining.is_empty());
        }
        other => panic!("no resync at the next delimiter: {other:?}"),
    }
}

fuzz_target!(|data: &[u8]| {
    let mut marker_buf = [0u8; MAX_ENCODED_LEN];
    let marker_frame =
        encode(Source::Control, MARKER_SEQ, &MARKER, &mut marker_buf).expect("the marker encodes");

    let split = data.first().map_or(0, |&b| usize::from(b)).min(data.len());
    let (head, tail) = data.split_at(split);

    let mut full = Accumulator::<MAX_ENCODED_LEN>::new();
    feed_all(&mut full, head);
    feed_all(&mut full, tail);
    resyncs(&mut full, marker_frame);

    let mut small = Accumulator::<32>::new();
    feed_all(&mut small, head);
    feed_all(&mut small, tail);
    resyncs(&mut small, marker_frame);

    let _ = decode(&mut data.to_vec());
});
