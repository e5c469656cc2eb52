//! Where the driver's packets go: a byte sink, and the writer that frames packets into it.
//!
//! The driver never owns the link. On the soft-core the sink is the UART; in the host's
//! in-process link it is a `Vec<u8>`. The [`PacketWriter`] of a link numbers the device's
//! control packets (answers, errors, logs); each camera channel numbers its own frames'
//! packets ([`Numbering`]) and writes them through the same writer, so the host sees a gap in
//! any one source.

use stereocal_wire::{encode, PacketRepr, Source, MAX_ENCODED_LEN};

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

/// Encodes packets into a [`ByteSink`], numbering the control source's itself.
pub struct PacketWriter<S: ByteSink> {
    sink: S,
    control: Numbering,
    frame: [u8; MAX_ENCODED_LEN],
}

impl<S: ByteSink> PacketWriter<S> {
    /// A writer whose first control packet gets sequence number 0.
    pub const fn new(sink: S) -> Self {
        Self {
            sink,
            control: Numbering::new(Source::Control),
            frame: [0; MAX_ENCODED_LEN],
        }
    }

    /// Encodes `packet` as the control source's next packet and writes the frame to the sink.
    pub fn send(&mut self, packet: &PacketRepr<'_>) -> Result<(), stereocal_wire::Error> {
        let Self {
            sink,
            control,
            frame,
        } = self;
        write(sink, frame, control, packet)
    }

    /// Encodes `packet` as the next packet of `numbering`'s source (a camera channel's) and
    /// writes the frame to the sink.
    pub fn send_from(
        &mut self,
        numbering: &mut Numbering,
        packet: &PacketRepr<'_>,
    ) -> Result<(), stereocal_wire::Error> {
        write(&mut self.sink, &mut self.frame, numbering, packet)
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

/// Encodes `packet` with `numbering`'s next number and writes it to `sink`. The number is used
/// up only when the packet was encoded, so a refused packet leaves no gap.
fn write<S: ByteSink>(
    sink: &mut S,
    frame: &mut [u8; MAX_ENCODED_LEN],
    numbering: &mut Numbering,
    packet: &PacketRepr<'_>,
) -> Result<(), stereocal_wire::Error> {
    let bytes = encode(numbering.source(), numbering.next_seq(), packet, frame)?;
    sink.write(bytes);
    numbering.advance();
    Ok(())
}
