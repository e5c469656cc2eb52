//! Link and frame counters, for the run summary and the bandwidth report.

use super::damage::DamageCounts;

/// Everything the driver counted since it was created.
///
/// The bandwidth of one frame pair is the sum of the two frames'
/// [`ReceivedFrame::wire_bytes`](super::ReceivedFrame::wire_bytes); `bytes_received` also
/// counts log packets, register answers and noise.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinkStats {
    /// Bytes the link delivered.
    pub bytes_received: u64,
    /// Bytes the driver sent.
    pub bytes_sent: u64,
    /// Packets that decoded.
    pub packets: u64,
    /// Frames on the link that did not decode (bad COBS, CRC, version, length, kind, fields).
    pub undecodable: u64,
    /// Intact packets of a kind this host does not know (counted and skipped, no damage).
    pub unknown_kinds: u64,
    /// Frames on the link longer than any packet (skipped).
    pub over_long: u64,
    /// Jumps in the sequence numbers.
    pub sequence_gaps: u64,
    /// Packets missing according to the sequence numbers.
    pub packets_lost: u64,
    /// Decoded packets that belong to no frame and are no answer the driver waits for.
    pub stray_packets: u64,
    /// Frame packets dropped because their number was at or just behind their source's last
    /// (repeated or overtaken on the link).
    pub late_packets: u64,
    /// Camera frames assembled and handed out (salvaged ones included).
    pub frames_delivered: u64,
    /// Delivered camera frames that had lost packets (see `ReceivedFrame::salvage`).
    pub frames_salvaged: u64,
    /// Camera frames dropped (sum of `damage`).
    pub frames_damaged: u64,
    /// Dropped frames by reason.
    pub damage: DamageCounts,
    /// Wire bytes of the delivered frames (`FrameStart` through `FrameEnd`).
    pub delivered_wire_bytes: u64,
    /// `Log` packets received.
    pub log_frames: u64,
    /// `Log` packets discarded because nobody took the log queue.
    pub logs_discarded: u64,
    /// `ErrorReport` packets received.
    pub device_errors: u64,
    /// Blocks of link frames that forward error correction repaired (0 without it).
    pub fec_blocks_repaired: u64,
}

impl LinkStats {
    /// Mean wire bytes of a delivered frame, 0 when none was delivered.
    pub fn mean_frame_bytes(&self) -> f64 {
        if self.frames_delivered == 0 {
            0.0
        } else {
            self.delivered_wire_bytes as f64 / self.frames_delivered as f64
        }
    }
}
