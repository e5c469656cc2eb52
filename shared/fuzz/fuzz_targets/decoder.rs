//! Arbitrary bytes into the receiving side: the streaming accumulator (at two buffer sizes and
//! a data-dependent chunking) and `decode` on the whole input. Nothing may panic, and every
//! packet that decodes must survive encode → decode unchanged.
//!
//! The crate skips the CRC check under `cfg(fuzzing)`, so mutated frames reach the field checks.
#![no_main]

use libfuzzer_sys::fuzz_target;
use stereocal_wire::{decode, encode, Accumulator, FeedResult, MAX_FRAME_LEN};

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
                let mut buf = [0u8; MAX_FRAME_LEN];
                let frame =
                    encode(header.seq, &packet, &mut buf).expect("a decoded packet re-encodes");
                let mut frame = frame.to_vec();
                let (again_header, again) =
                    decode(&mut frame).expect("a re-encoded packet decodes");
                assert_eq!(again_header.seq, header.seq);
                assert_eq!(again, packet);
                remaining
            }
        };
    }
}

fuzz_target!(|data: &[u8]| {
    let split = data.first().map_or(0, |&b| usize::from(b)).min(data.len());
    let (head, tail) = data.split_at(split);

    let mut full = Accumulator::<MAX_FRAME_LEN>::new();
    feed_all(&mut full, head);
    feed_all(&mut full, tail);

    let mut small = Accumulator::<32>::new();
    feed_all(&mut small, head);
    feed_all(&mut small, tail);

    let _ = decode(&mut data.to_vec());
});
