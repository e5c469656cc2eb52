//! `Log` (`0x20`), device to host: one defmt log frame, passed through untouched.
//!
//! ```text
//!  0                    n
//! +-------- ... --------+
//! |  defmt frame bytes  |   n <= MAX_LEN
//! +-------- ... --------+
//! ```
//! The bytes are what the firmware's defmt global logger produced for one log call, without
//! defmt's own framing (the packet already delimits them); the host decodes them with the
//! firmware ELF's defmt table.

use crate::packet::check_room;
use crate::Error;

/// Largest defmt frame one `Log` packet carries.
pub const MAX_LEN: usize = 256;

packet_view! {
    /// A view over a `Log` payload.
}

impl<T: AsRef<[u8]>> Packet<T> {
    /// Checks that the buffer holds at most [`MAX_LEN`] bytes.
    pub fn check_len(&self) -> Result<(), Error> {
        if self.buffer.as_ref().len() > MAX_LEN {
            Err(Error::DecodeTooManyRecords)
        } else {
            Ok(())
        }
    }

    /// The defmt frame bytes.
    pub fn frame(&self) -> &[u8] {
        self.buffer.as_ref()
    }
}

/// A parsed `Log`, borrowing the packet bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LogRepr<'a> {
    /// The defmt frame bytes.
    pub frame: &'a [u8],
}

impl<'a> LogRepr<'a> {
    /// Reads a `Log` payload.
    pub fn parse<T: AsRef<[u8]> + ?Sized>(packet: &Packet<&'a T>) -> Result<LogRepr<'a>, Error> {
        packet.check_len()?;
        Ok(LogRepr {
            frame: packet.buffer.as_ref(),
        })
    }

    /// Payload length `emit` writes.
    pub const fn buffer_len(&self) -> usize {
        self.frame.len()
    }

    /// Writes the payload into `packet`.
    pub fn emit<T: AsRef<[u8]> + AsMut<[u8]>>(&self, packet: &mut Packet<T>) -> Result<(), Error> {
        if self.frame.len() > MAX_LEN {
            return Err(Error::EncodeTooManyRecords);
        }
        check_room(packet.buffer.as_ref().len(), self.buffer_len())?;
        for (out, byte) in packet.buffer.as_mut().iter_mut().zip(self.frame) {
            *out = *byte;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    static PACKET_BYTES: [u8; 4] = [
        0x01, 0x00, // defmt string index 1
        0x2a, 0x00, // its u16 argument, 42
    ];

    #[test]
    fn deconstruct() {
        let packet = Packet::new_checked(&PACKET_BYTES[..]).unwrap();
        assert_eq!(packet.frame(), &PACKET_BYTES[..]);
    }

    #[test]
    fn parse_and_emit() {
        let packet = Packet::new_unchecked(&PACKET_BYTES[..]);
        let repr = LogRepr::parse(&packet).unwrap();
        assert_eq!(repr.frame, &PACKET_BYTES[..]);
        let mut bytes = [0u8; 4];
        repr.emit(&mut Packet::new_unchecked(&mut bytes[..]))
            .unwrap();
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn impossible_length() {
        let long = [0u8; MAX_LEN + 1];
        assert_eq!(
            Packet::new_checked(&long[..]).unwrap_err(),
            Error::DecodeTooManyRecords
        );
        let mut out = [0u8; MAX_LEN + 1];
        assert_eq!(
            LogRepr { frame: &long }.emit(&mut Packet::new_unchecked(&mut out[..])),
            Err(Error::EncodeTooManyRecords)
        );
        let mut short = [0u8; 3];
        assert_eq!(
            LogRepr {
                frame: &PACKET_BYTES
            }
            .emit(&mut Packet::new_unchecked(&mut short[..])),
            Err(Error::EncodeBufferTooSmall)
        );
    }
}
