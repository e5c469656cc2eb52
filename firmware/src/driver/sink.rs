//! Where the driver's packets go: a byte sink, and the writer that frames packets into it.
//!
//! The driver never owns the link. On the soft-core the sink is the UART; in the host's
//! in-process link it is a `Vec<u8>`. The [`PacketWriter`] of a link numbers the device's
//! control packets (answers, errors, logs); each camera channel numbers its own frames'
//! packets ([`Numbering`]) and writes them through the same writer, so the host sees a gap in
//! any one source.

use stereocal_wire::{encode, fec, PacketRepr, Source, MAX_PROTECTED_LEN};

use crate::driver::numbering::Numbering;

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

/// Encodes packets into a [`ByteSink`], numbering the control source's itself, and protects
/// each link frame by forward error correction when the host asked for it in `Hello`.
pub struct PacketWriter<S: ByteSink> {
    sink: S,
    control: Numbering,
    /// Room for the largest link frame with its parity.
    frame: [u8; MAX_PROTECTED_LEN],
    fec: bool,
}

impl<S: ByteSink> PacketWriter<S> {
    /// A writer whose first control packet gets sequence number 0.
    pub const fn new(sink: S) -> Self {
        Self {
            sink,
            control: Numbering::new(Source::Control),
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

    /// Encodes `packet` as the control source's next packet and writes the frame to the sink.
    pub fn send(&mut self, packet: &PacketRepr<'_>) -> Result<(), stereocal_wire::Error> {
        let Self {
            sink,
            control,
            frame,
            fec,
        } = self;
        write(sink, frame, *fec, control, packet)
    }

    /// Encodes `packet` as the next packet of `numbering`'s source (a camera channel's) and
    /// writes the frame to the sink.
    pub fn send_from(
        &mut self,
        numbering: &mut Numbering,
        packet: &PacketRepr<'_>,
    ) -> Result<(), stereocal_wire::Error> {
        write(&mut self.sink, &mut self.frame, self.fec, numbering, packet)
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

/// Encodes `packet` with `numbering`'s next number, protects it when `fec` is set, and writes
/// it to `sink`. The number is used up only when the packet was encoded, so a refused packet
/// leaves no gap.
fn write<S: ByteSink>(
    sink: &mut S,
    frame: &mut [u8; MAX_PROTECTED_LEN],
    fec: bool,
    numbering: &mut Numbering,
    packet: &PacketRepr<'_>,
) -> Result<(), stereocal_wire::Error> {
    let len = encode(numbering.source(), numbering.next_seq(), packet, frame)?.len();
    let len = if fec {
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
