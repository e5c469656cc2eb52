//! A fake device on the far end of a stream: answers Hello and register packets like the
//! soft-core, and sends canned frames once the host sets `CONTROL.ENABLE`.

use std::io::{ErrorKind, Read, Write};

use stereocal_hdl::{regs, RegisterBank, RegisterBus};
use stereocal_wire::{
    Accumulator, Capabilities, FeedResult, HelloRepr, PacketRepr, RegisterValueRepr,
    MAX_ENCODED_LEN, PROTOCOL_VERSION,
};

use super::{FrameSpec, Wire};

/// Serves the host until it closes the stream; returns the packets it received.
pub fn serve(stream: &mut (impl Read + Write), frames: &[FrameSpec]) -> usize {
    let mut wire = Wire::new();
    let mut sent = 0;
    let mut received = 0;
    let mut acc = Accumulator::<{ MAX_ENCODED_LEN - 1 }>::new();
    let mut bank = RegisterBank::new();
    let mut buf = [0u8; 4096];
    loop {
        let n = match stream.read(&mut buf) {
            Ok(0) => return received,
            Ok(n) => n,
            Err(e)
                if matches!(
                    e.kind(),
                    ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
                ) =>
            {
                continue
            }
            Err(_) => return received,
        };
        let mut window = &buf[..n];
        loop {
            window = match acc.feed(window) {
                FeedResult::Consumed => break,
                FeedResult::OverFull(rest) => rest,
                FeedResult::DecodeError { remaining, .. } => remaining,
                FeedResult::Success {
                    packet, remaining, ..
                } => {
                    received += 1;
                    match packet {
                        PacketRepr::Hello(_) => {
                            wire.push(&PacketRepr::Hello(HelloRepr {
                                version: PROTOCOL_VERSION,
                                capabilities: Capabilities::POINTS | Capabilities::SOBEL_ROWS,
                            }));
                        }
                        PacketRepr::RegisterWrite(w) => {
                            bank.write(w.addr, w.value);
                            let enable = regs::control::ENABLE.extract(w.value) == 1;
                            if w.addr == regs::control::OFFSET && enable {
                                for f in frames {
                                    wire.frame(f);
                                }
                            }
                        }
                        PacketRepr::RegisterRead(r) => {
                            wire.push(&PacketRepr::RegisterValue(RegisterValueRepr {
                                addr: r.addr,
                                value: bank.read(r.addr),
                            }));
                        }
                        _ => {}
                    }
                    remaining
                }
            };
        }
        if stream.write_all(&wire.bytes[sent..]).is_err() {
            return received;
        }
        sent = wire.bytes.len();
    }
}
