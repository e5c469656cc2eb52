//! Where the driver's packets go: a byte sink, and the writer that numbers and frames packets.
//!
//! The driver never owns the link. On the soft-core the sink is the UART; in the host's
//! in-process link it is a `Vec<u8>` or a channel. One [`PacketWriter`] per link keeps one
//! sequence counter, so the packets of both cameras (and the firmware's log packets) share a
//! single numbering and the host sees every gap.

use stereocal_wire::{encode, PacketRepr, MAX_FRAME_LEN};

/// Takes complete wire frames (COBS bytes and the `0x00` delimiter), in order.
///
/// Writing cannot fail: a link that can lose bytes loses them (the host sees the sequence gap
/// and the CRC failure); a link that can block blocks.
pub trait ByteSink {
    /// Sends `bytes`, which always form one or more whole frames.
    fn write(&mut self, bytes: &[u8]);
}

impl<S: ByteSink + ?Sized> ByteSink for &mut S {
    fn write(&mut self, bytes: &[u8]) {
        (**self).write(bytes);
    }
}

/// Encodes packets with consecutive sequence numbers into a [`ByteSink`].
pub struct PacketWriter<S: ByteSink> {
    sink: S,
    next_seq: u16,
    frame: [u8; MAX_FRAME_LEN],
}

impl<S: ByteSink> PacketWriter<S> {
    /// A writer whose first packet gets sequence number 0.
    pub const fn new(sink: S) -> Self {
        Self {
            sink,
            next_seq: 0,
            frame: [0; MAX_FRAME_LEN],
        }
    }

    /// Encodes `packet` with the next sequence number and writes the frame to the sink.
    ///
    /// The sequence number is used up only when the packet was encoded, so a refused packet
    /// leaves no gap.
    pub fn send(&mut self, packet: &PacketRepr<'_>) -> Result<(), stereocal_wire::Error> {
        let frame = encode(self.next_seq, packet, &mut self.frame)?;
        self.sink.write(frame);
        self.next_seq = self.next_seq.wrapping_add(1);
        Ok(())
    }

    /// Makes `seq` the next packet's sequence number: a stretch of a link's numbering can be
    /// written apart from the rest (the host's in-process link runs the left camera on one
    /// core while the right one runs on the other) and the link's writer then skips past it.
    pub fn set_next_seq(&mut self, seq: u16) {
        self.next_seq = seq;
    }

    /// The sequence number the next packet will carry.
    pub fn next_seq(&self) -> u16 {
        self.next_seq
    }

    /// The sink, e.g. to read back what a test collected.
    pub fn sink(&self) -> &S {
        &self.sink
    }

    /// The sink, mutably (e.g. to clear a test buffer between frames).
    pub fn sink_mut(&mut self) -> &mut S {
        &mut self.sink
    }

    /// Gives the sink back.
    pub fn into_sink(self) -> S {
        self.sink
    }
}
