//! Arbitrary bytes into the receiving side: the streaming accumulator (at two buffer sizes and
//! a data-dependent chunking, and with forward error correction on) and `decode` and
//! `fec::repair` on the whole input. Nothing may panic, every
//! packet that decodes must survive encode → decode unchanged, and after the input, whatever
//! state it left the accumulator in, one `0x00` and a valid frame must give exactly that frame
//! (resynchronisation at the next delimiter).
//!
//! The crate skips the CRC check under `cfg(fuzzing)`, so mutated frames reach the field checks.
#![no_main]

use libfuzzer_sys::fuzz_target;
use stereocal_wire::{
    decode, encode, fec, Accumulator, FeedResult, PacketRepr, RegisterReadRepr, Source,
    DELIMITER, MAX_ENCODED_LEN, MAX_PROTECTED_LEN,
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

    // The same input on a link under forward error correction, and the marker protected.
    let mut protected_buf = [0u8; MAX_PROTECTED_LEN];
    let len = encode(Source::Control, MARKER_SEQ, &MARKER, &mut protected_buf)
        .expect("the marker encodes")
        .len();
    let total = fec::protect(&mut protected_buf, len - 1).expect("the marker protects");
    protected_buf[total] = DELIMITER;
    let mut fec_on = Accumulator::<MAX_PROTECTED_LEN>::new();
    fec_on.set_fec(true);
    feed_all(&mut fec_on, head);
    feed_all(&mut fec_on, tail);
    resyncs(&mut fec_on, &protected_buf[..=total]);

    // A repaired frame's body protects to a frame that repairs to it again.
    let mut frame = data.to_vec();
    if let Ok(repaired) = fec::repair(&mut frame) {
        let body = frame[..repaired.body_len].to_vec();
        let mut again = body.clone();
        again.resize(fec::protected_len(body.len()), 0);
        if fec::protect(&mut again, body.len()).is_ok() {
            let twice = fec::repair(&mut again).expect("a protected body repairs");
            assert_eq!(twice.blocks_repaired, 0);
            assert_eq!(&again[..twice.body_len], &body[..]);
        }
    }

    let _ = decode(&mut data.to_vec());
});
