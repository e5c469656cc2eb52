//! A link that damages the device's bytes in transit, deterministically by seed: what a
//! noisy UART (bit flips, lost bytes) and a misbehaving bridge between it and the host
//! (truncated, duplicated, reordered packets, stalls) would do to them.
//!
//! [`FaultLink`] wraps any [`Link`] (and passes a [`FrameInput`] through when the wrapped link has one), so the
//! driver above it runs unchanged: every fault reaches the host exactly where a real one
//! would, in the byte stream, and the wire format's COBS framing, CRC-32C and sequence
//! numbers are what has to catch it. Only the device-to-host direction is damaged: requests
//! reach the device intact, so a run always gets past `Hello` and configuration and the
//! faults fall on camera frames.
//!
//! Packet-level faults need packet boundaries: the wrapper cuts the incoming bytes at the
//! wire delimiter (`0x00`) before damaging them, and holds back a trailing partial packet
//! until the rest of it arrives.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use stereocal_wire::DELIMITER;

use super::{FrameInput, Link, LinkError};

/// Bytes asked of the wrapped link per receive.
const PULL_CHUNK: usize = 64 * 1024;

/// What to damage and how often. Rates are probabilities per bit, per byte or per packet;
/// 0 turns a fault off.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaultConfig {
    /// Seeds every random choice: the same seed over the same bytes gives the same damage.
    pub seed: u64,
    /// Probability that a bit is inverted.
    pub bit_flip_rate: f64,
    /// Probability that a byte is lost.
    pub byte_drop_rate: f64,
    /// Probability that a packet loses a random-length tail (its delimiter stays, so the
    /// next packet is not merged into it).
    pub truncate_rate: f64,
    /// Probability that a packet arrives twice in a row.
    pub duplicate_rate: f64,
    /// Probability that a packet is swapped with the one after it.
    pub reorder_rate: f64,
    /// Probability that the link goes quiet for [`FaultConfig::stall`] before a packet.
    pub stall_rate: f64,
    /// Length of a stall; meant to be shorter than the driver's timeout, and cut at the
    /// receive deadline in any case, so a stall delays bytes but never loses them.
    pub stall: Duration,
}

/// A rate that is no probability.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("fault rate {name} = {rate} is not a probability in [0, 1]")]
pub struct BadRate {
    /// Which rate.
    pub name: &'static str,
    /// Its value.
    pub rate: f64,
}

impl FaultConfig {
    /// No faults at all (a wrapper that passes every byte through).
    pub fn none(seed: u64) -> Self {
        Self {
            seed,
            bit_flip_rate: 0.0,
            byte_drop_rate: 0.0,
            truncate_rate: 0.0,
            duplicate_rate: 0.0,
            reorder_rate: 0.0,
            stall_rate: 0.0,
            stall: Duration::ZERO,
        }
    }

    /// Checks that every rate is a probability (the random draws would panic otherwise).
    pub fn validate(&self) -> Result<(), BadRate> {
        let rates = [
            ("bit_flip_rate", self.bit_flip_rate),
            ("byte_drop_rate", self.byte_drop_rate),
            ("truncate_rate", self.truncate_rate),
            ("duplicate_rate", self.duplicate_rate),
            ("reorder_rate", self.reorder_rate),
            ("stall_rate", self.stall_rate),
        ];
        match rates.iter().find(|(_, r)| !(0.0..=1.0).contains(r)) {
            Some(&(name, rate)) => Err(BadRate { name, rate }),
            None => Ok(()),
        }
    }
}

/// What the wrapper did so far.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FaultCounts {
    /// Packets (delimited runs of bytes) that went through while faults were on.
    pub packets: u64,
    /// Bits inverted.
    pub bits_flipped: u64,
    /// Bytes removed.
    pub bytes_dropped: u64,
    /// Packets that lost a tail.
    pub packets_truncated: u64,
    /// Packets sent twice.
    pub packets_duplicated: u64,
    /// Packets held back to go out after their successor.
    pub packets_reordered: u64,
    /// Stalls inserted before a packet.
    pub stalls: u64,
    /// Most bytes the wrapper held at once (incoming, held back and outgoing): the bound on
    /// its memory, one delivery of the wrapped link plus one packet.
    pub peak_buffered: usize,
}

/// One packet on its way to the host.
#[derive(Debug)]
struct Outgoing {
    bytes: Vec<u8>,
    /// Bytes already handed out.
    read: usize,
    /// Wait this long before its first byte.
    stall: Duration,
}

/// A [`Link`] whose received bytes are damaged per a [`FaultConfig`] while faults are on.
pub struct FaultLink<L: Link> {
    inner: L,
    config: FaultConfig,
    rng: ChaCha8Rng,
    active: bool,
    /// Bits left to pass intact before the next flip (geometric gaps, so a rate of 1e-7
    /// costs no random draw per bit).
    bits_to_flip: u64,
    /// Bytes left to pass before the next drop.
    bytes_to_drop: u64,
    pull: Vec<u8>,
    /// Received bytes not yet cut into packets (a partial packet).
    incoming: Vec<u8>,
    /// A packet waiting to be sent after its successor (reordering).
    held: Option<Vec<u8>>,
    outgoing: VecDeque<Outgoing>,
    counts: FaultCounts,
}

impl<L: Link> FaultLink<L> {
    /// Wraps `inner`; faults start off (see [`FaultLink::set_active`]).
    pub fn new(inner: L, config: FaultConfig) -> Result<Self, BadRate> {
        config.validate()?;
        let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
        let bits_to_flip = gap(&mut rng, config.bit_flip_rate);
        let bytes_to_drop = gap(&mut rng, config.byte_drop_rate);
        Ok(Self {
            inner,
            config,
            rng,
            active: false,
            bits_to_flip,
            bytes_to_drop,
            pull: vec![0; PULL_CHUNK],
            incoming: Vec::new(),
            held: None,
            outgoing: VecDeque::new(),
            counts: FaultCounts::default(),
        })
    }

    /// Turns faults on or off for bytes received from now on: a fault burst is the span
    /// between switching on and off, and recovery is measured from its end.
    pub fn set_active(&mut self, active: bool) {
        self.active = active;
    }

    /// What the wrapper did so far.
    pub fn counts(&self) -> FaultCounts {
        self.counts
    }

    /// Moves whatever the wrapped link has into packets, damaging them while active.
    /// Returns the wrapped link's error when it had nothing.
    fn pull(&mut self, deadline: Instant) -> Result<(), LinkError> {
        let n = self.inner.recv(&mut self.pull, deadline)?;
        self.incoming.extend_from_slice(&self.pull[..n]);
        let mut start = 0;
        while let Some(end) = self.incoming[start..].iter().position(|&b| b == DELIMITER) {
            let packet = self.incoming[start..=start + end].to_vec();
            start += end + 1;
            self.enqueue(packet);
        }
        self.incoming.drain(..start);
        self.note_buffered();
        Ok(())
    }

    /// Applies the packet-level faults to one delimited packet, then the byte-level ones.
    fn enqueue(&mut self, mut packet: Vec<u8>) {
        if !self.active {
            self.release_held();
            self.push(packet, Duration::ZERO);
            return;
        }
        self.counts.packets += 1;
        let c = self.config;
        if packet.len() > 1 && self.rng.random_bool(c.truncate_rate) {
            // Keep a prefix of the body, then the delimiter.
            let keep = self.rng.random_range(0..packet.len() - 1);
            packet.drain(keep..packet.len() - 1);
            self.counts.packets_truncated += 1;
        }
        let copies = if self.rng.random_bool(c.duplicate_rate) {
            self.counts.packets_duplicated += 1;
            2
        } else {
            1
        };
        for _ in 0..copies {
            let mut copy = packet.clone();
            self.damage_bytes(&mut copy);
            let stall = if self.rng.random_bool(c.stall_rate) {
                self.counts.stalls += 1;
                c.stall
            } else {
                Duration::ZERO
            };
            if let Some(earlier) = self.held.take() {
                // The held packet goes out after this one: the two swap places.
                self.push(copy, stall);
                self.push(earlier, Duration::ZERO);
            } else if self.rng.random_bool(c.reorder_rate) {
                self.counts.packets_reordered += 1;
                self.held = Some(copy);
            } else {
                self.push(copy, stall);
            }
        }
    }

    /// Drops bytes and flips bits of one packet copy.
    fn damage_bytes(&mut self, packet: &mut Vec<u8>) {
        if self.config.bit_flip_rate > 0.0 {
            let mut bit = 0u64;
            let bits = packet.len() as u64 * 8;
            loop {
                let skip = self.bits_to_flip;
                if bit + skip >= bits {
                    self.bits_to_flip -= bits - bit;
                    break;
                }
                bit += skip;
                packet[(bit / 8) as usize] ^= 1 << (bit % 8);
                self.counts.bits_flipped += 1;
                bit += 1;
                self.bits_to_flip = gap(&mut self.rng, self.config.bit_flip_rate);
            }
        }
        if self.config.byte_drop_rate > 0.0 {
            let mut i = 0usize;
            let mut kept = Vec::with_capacity(packet.len());
            loop {
                let skip = usize::try_from(self.bytes_to_drop).unwrap_or(usize::MAX);
                if skip >= packet.len() - i {
                    self.bytes_to_drop -= (packet.len() - i) as u64;
                    kept.extend_from_slice(&packet[i..]);
                    break;
                }
                kept.extend_from_slice(&packet[i..i + skip]);
                i += skip + 1;
                self.counts.bytes_dropped += 1;
                self.bytes_to_drop = gap(&mut self.rng, self.config.byte_drop_rate);
            }
            *packet = kept;
        }
    }

    /// Sends a packet held back for reordering: its successor never came, and holding it
    /// longer would turn reordering into loss.
    fn release_held(&mut self) {
        if let Some(held) = self.held.take() {
            self.push(held, Duration::ZERO);
        }
    }

    fn push(&mut self, bytes: Vec<u8>, stall: Duration) {
        if !bytes.is_empty() {
            self.outgoing.push_back(Outgoing {
                bytes,
                read: 0,
                stall,
            });
        }
    }

    fn note_buffered(&mut self) {
        let held = self.held.as_ref().map_or(0, Vec::len);
        let outgoing: usize = self.outgoing.iter().map(|o| o.bytes.len() - o.read).sum();
        let now = self.incoming.len() + held + outgoing;
        self.counts.peak_buffered = self.counts.peak_buffered.max(now);
    }
}

/// Draws how many trials pass before the next event of probability `rate` (geometric,
/// by inversion); never for a rate of 0.
fn gap(rng: &mut ChaCha8Rng, rate: f64) -> u64 {
    if rate <= 0.0 {
        return u64::MAX;
    }
    if rate >= 1.0 {
        return 0;
    }
    let u: f64 = rng.random::<f64>();
    // 1 - u is in (0, 1], so the logarithm is finite; ln_1p keeps a rate below f64's
    // epsilon from rounding 1 - rate to 1 (a zero divisor: every trial an event).
    let n = ((1.0 - u).ln() / (-rate).ln_1p()).floor();
    if n >= u64::MAX as f64 {
        u64::MAX
    } else {
        n as u64
    }
}

impl<L: Link> Link for FaultLink<L> {
    /// Host-to-device bytes pass intact (see the module documentation).
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.inner.send(bytes)
    }

    fn answer_timeout(&self) -> Duration {
        self.inner.answer_timeout()
    }

    fn recv(&mut self, buf: &mut [u8], deadline: Instant) -> Result<usize, LinkError> {
        loop {
            if let Some(front) = self.outgoing.front_mut() {
                if !front.stall.is_zero() {
                    let wait = front
                        .stall
                        .min(deadline.saturating_duration_since(Instant::now()));
                    std::thread::sleep(wait);
                    front.stall = Duration::ZERO;
                }
                let n = (front.bytes.len() - front.read).min(buf.len());
                buf[..n].copy_from_slice(&front.bytes[front.read..front.read + n]);
                front.read += n;
                if front.read == front.bytes.len() {
                    self.outgoing.pop_front();
                }
                return Ok(n);
            }
            match self.pull(deadline) {
                Ok(()) => {}
                // Nothing more is coming now (or ever): a held packet goes out alone.
                Err(_) if self.held.is_some() => self.release_held(),
                Err(e) => return Err(e),
            }
        }
    }
}

impl<D: Link + FrameInput> FrameInput for FaultLink<D> {
    fn submit_pair(
        &mut self,
        left: &[u8],
        right: &[u8],
        timestamp_us: u64,
    ) -> Result<(), LinkError> {
        self.inner.submit_pair(left, right, timestamp_us)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rate far below f64's epsilon still gives gaps of about 1/rate, not an event on
    /// every trial (1 - rate rounds to 1).
    #[test]
    fn a_tiny_rate_gives_long_gaps() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let gaps: Vec<u64> = (0..64).map(|_| gap(&mut rng, 1e-18)).collect();
        assert!(
            gaps.iter().filter(|&&g| g > 1u64 << 50).count() > 48,
            "{gaps:?}"
        );
        assert_eq!(gap(&mut rng, 0.0), u64::MAX);
        assert_eq!(gap(&mut rng, 1.0), 0);
    }
}
