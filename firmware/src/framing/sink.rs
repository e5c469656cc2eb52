//! Where packets go: a byte sink, the framer that turns packets into link frames, and the
//! soft-core's writer.
//!
//! Neither the driver nor the fabric owns the link. On the soft-core the sink is the UART; in
//! the host's in-process link it is a `Vec<u8>`. The soft-core's [`PacketWriter`] numbers the
//! device's control packets (answers, errors, logs); the fabric's stream engine numbers its
//! camera channel's packets ([`Numbering`]) and frames them with a [`Framer`] of its own, so
//! the host sees a gap in any one source.

use stereocal_wire::{encode, fec, PacketRepr, Source, MAX_PROTECTED_LEN};

use crate::framing::Numbering;

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

/// Turns packets into link frames: encodes a packet with its source's next number, protects
/// the frame by forward error correction when asked, and writes it whole to a sink.
///
/// The soft-core's writer and each stream engine have one, since each frames its own packets
/// (on a head, in software and in the fabric's framer respectively).
pub struct Framer {
    /// Room for the largest link frame with its parity.
    frame: [u8; MAX_PROTECTED_LEN],
    fec: bool,
}

impl Framer {
    /// A framer without forward error correction.
    pub const fn new() -> Self {
        Self {
            frame: [0; MAX_PROTECTED_LEN],
            fec: false,
        }
    }

    /// Whether the link frames written from now on carry forward error correction
    /// ([`stereocal_wire::fec`]).
    pub fn set_fec(&mut self, on: bool) {
        self.fec = on;
    }

    /// Whether link frames carry forward error correction.
    pub fn fec(&self) -> bool {
        self.fec
    }

    /// Encodes `packet` with `numbering`'s next number, protects it when FEC is on, and
    /// writes it to `sink`. The number is used up only when the packet was encoded, so a
    /// refused packet leaves no gap.
    pub fn send<S: ByteSink + ?Sized>(
        &mut self,
        sink: &mut S,
        numbering: &mut Numbering,
        packet: &PacketRepr<'_>,
    ) -> Result<(), stereocal_wire::Error> {
        let frame = &mut self.frame;
        let len = encode(numbering.source(), numbering.next_seq(), packet, frame)?.len();
        let len = if self.fec {
            // The body is the frame without its delimiter; the parity goes where that was.
            let protected = fec::protect(frame, len - 1)?;
            let delimiter = frame
                .get_mut(protected)
                .ok_or(stereocal_wire::Error::EncodeBufferTooSmall)?;
            *delimiter = stereocal_wire::DELIMITER;
            protected + 1
        } else {
            len
        };
        let bytes = frame
            .get(..len)
            .ok_or(stereocal_wire::Error::EncodeBufferTooSmall)?;
        sink.write(bytes);
        numbering.advance();
        Ok(())
    }
}

impl Default for Framer {
    fn default() -> Self {
        Self::new()
    }
}

/// The soft-core's end of a link: encodes its packets into a [`ByteSink`], numbering the
/// control source's itself.
pub struct PacketWriter<S: ByteSink> {
    sink: S,
    control: Numbering,
    framer: Framer,
}

impl<S: ByteSink> PacketWriter<S> {
    /// A writer whose first control packet gets sequence number 0.
    pub const fn new(sink: S) -> Self {
        Self {
            sink,
            control: Numbering::new(Source::Control),
            framer: Framer::new(),
        }
    }

    /// Whether the link frames written from now on carry forward error correction
    /// ([`stereocal_wire::fec`]).
    pub fn set_fec(&mut self, on: bool) {
        self.framer.set_fec(on);
    }

    /// Whether link frames carry forward error correction.
    pub fn fec(&self) -> bool {
        self.framer.fec()
    }

    /// Encodes `packet` as the control source's next packet and writes the frame to the sink.
    pub fn send(&mut self, packet: &PacketRepr<'_>) -> Result<(), stereocal_wire::Error> {
        self.framer.send(&mut self.sink, &mut self.control, packet)
    }

    /// The control source's numbering.
    pub fn control(&self) -> &Numbering {
        &self.control
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
