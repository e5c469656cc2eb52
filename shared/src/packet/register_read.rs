//! `RegisterRead` (`0x03`), host to device: ask for a fabric register's value (answered by `RegisterValue`).
//!
//! ```text
//!  0          2
//! +----------+
//! |   addr   |
//! |  u16 LE  |
//! +----------+
//! ```
//! `addr` is a byte address in the register map of `stereocal-hdl`.

use crate::le::{self, Field};
use crate::packet::{check_fixed_len, check_room};
use crate::Error;

mod field {
    use super::Field;
    pub const ADDR: Field = 0..2;
}

/// Payload length of a `RegisterRead`.
pub const LEN: usize = field::ADDR.end;

packet_view! {
    /// A view over a `RegisterRead` payload.
}

impl<T: AsRef<[u8]>> Packet<T> {
    /// Checks that the buffer is exactly [`LEN`] bytes.
    pub fn check_len(&self) -> Result<(), Error> {
        check_fixed_len(self.buffer.as_ref().len(), LEN)
    }

    /// Register address.
    pub fn addr(&self) -> u16 {
        le::read_u16(self.buffer.as_ref(), field::ADDR)
    }
}

impl<T: AsRef<[u8]> + AsMut<[u8]>> Packet<T> {
    /// Sets the register address.
    pub fn set_addr(&mut self, value: u16) {
        le::write_u16(self.buffer.as_mut(), field::ADDR, value);
    }
}

/// A parsed `RegisterRead`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RegisterReadRepr {
    /// Register address.
    pub addr: u16,
}

impl RegisterReadRepr {
    /// Reads a `RegisterRead` payload.
    pub fn parse<T: AsRef<[u8]> + ?Sized>(packet: &Packet<&T>) -> Result<RegisterReadRepr, Error> {
        packet.check_len()?;
        Ok(RegisterReadRepr {
            addr: packet.addr(),
        })
    }

    /// Payload length `emit` writes.
    pub const fn buffer_len(&self) -> usize {
        LEN
    }

    /// Writes the payload into `packet`.
    pub fn emit<T: AsRef<[u8]> + AsMut<[u8]>>(&self, packet: &mut Packet<T>) -> Result<(), Error> {
        check_room(packet.buffer.as_ref().len(), self.buffer_len())?;
        packet.set_addr(self.addr);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    static PACKET_BYTES: [u8; 2] = [
        0x34, 0x12, // addr 0x1234
    ];

    const REPR: RegisterReadRepr = RegisterReadRepr { addr: 0x1234 };

    #[test]
    fn deconstruct() {
        let packet = Packet::new_checked(&PACKET_BYTES[..]).unwrap();
        assert_eq!(packet.addr(), 0x1234);
    }

    #[test]
    fn construct() {
        let mut bytes = [0xa5u8; LEN];
        let mut packet = Packet::new_unchecked(&mut bytes[..]);
        packet.set_addr(0x1234);
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn parse() {
        let packet = Packet::new_unchecked(&PACKET_BYTES[..]);
        assert_eq!(RegisterReadRepr::parse(&packet), Ok(REPR));
    }

    #[test]
    fn emit() {
        let mut bytes = [0u8; LEN];
        REPR.emit(&mut Packet::new_unchecked(&mut bytes[..]))
            .unwrap();
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn impossible_length() {
        assert_eq!(
            Packet::new_checked(&PACKET_BYTES[..LEN - 1]).unwrap_err(),
            Error::DecodeUnexpectedEnd
        );
        assert_eq!(
            Packet::new_checked(&[0u8; LEN + 1][..]).unwrap_err(),
            Error::DecodeBadLength
        );
        let mut short = [0u8; LEN - 1];
        assert_eq!(
            REPR.emit(&mut Packet::new_unchecked(&mut short[..])),
            Err(Error::EncodeBufferTooSmall)
        );
    }
}
