//! `Hello` (`0x01`), sent by both sides when a link comes up.
//!
//! ```text
//!  0        1                  5
//! +--------+------------------+
//! |version |   capabilities   |
//! |   u8   |      u32 LE      |
//! +--------+------------------+
//! ```
//! `version` is the highest protocol version the sender speaks (the header carries the one
//! this packet is written in). Capability bits a receiver does not know are kept and ignored.

use core::ops::BitOr;

use crate::le::{self, Field};
use crate::packet::{check_fixed_len, check_room};
use crate::Error;

mod field {
    use super::Field;
    pub const VERSION: usize = 0;
    pub const CAPABILITIES: Field = 1..5;
}

/// Payload length of a `Hello`.
pub const LEN: usize = field::CAPABILITIES.end;

packet_view! {
    /// A view over a `Hello` payload.
}

impl<T: AsRef<[u8]>> Packet<T> {
    /// Checks that the buffer is exactly [`LEN`] bytes.
    pub fn check_len(&self) -> Result<(), Error> {
        check_fixed_len(self.buffer.as_ref().len(), LEN)
    }

    /// Highest protocol version the sender speaks.
    pub fn version(&self) -> u8 {
        le::read_u8(self.buffer.as_ref(), field::VERSION)
    }

    /// Capability bits.
    pub fn capabilities(&self) -> u32 {
        le::read_u32(self.buffer.as_ref(), field::CAPABILITIES)
    }
}

impl<T: AsRef<[u8]> + AsMut<[u8]>> Packet<T> {
    /// Sets the highest protocol version the sender speaks.
    pub fn set_version(&mut self, value: u8) {
        le::write_u8(self.buffer.as_mut(), field::VERSION, value);
    }

    /// Sets the capability bits.
    pub fn set_capabilities(&mut self, value: u32) {
        le::write_u32(self.buffer.as_mut(), field::CAPABILITIES, value);
    }
}

/// What a peer can do, as bits; unknown bits are kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Capabilities(pub u32);

impl Capabilities {
    /// Sends `PointBatch` packets.
    pub const POINTS: Capabilities = Capabilities(1 << 0);
    /// Sends full Sobel rows (`SobelRows`).
    pub const SOBEL_ROWS: Capabilities = Capabilities(1 << 1);
    /// Sends Sobel patches around keypoints (`SobelPatch`).
    pub const SOBEL_PATCHES: Capabilities = Capabilities(1 << 2);
    /// Sends defmt `Log` packets.
    pub const LOG: Capabilities = Capabilities(1 << 3);
    /// Accepts `RegisterWrite` / `RegisterRead`.
    pub const REGISTERS: Capabilities = Capabilities(1 << 4);
    /// Forward error correction of the device's link frames ([`fec`](crate::fec)). A device
    /// sets it when it can protect its frames; a host sets it to ask for that, and the device
    /// protects every link frame after its `Hello` answer.
    pub const FEC: Capabilities = Capabilities(1 << 5);

    /// `true` when every bit of `other` is set in `self`.
    pub const fn contains(self, other: Capabilities) -> bool {
        self.0 & other.0 == other.0
    }
}

impl BitOr for Capabilities {
    type Output = Capabilities;
    fn bitor(self, rhs: Capabilities) -> Capabilities {
        Capabilities(self.0 | rhs.0)
    }
}

/// A parsed `Hello`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct HelloRepr {
    /// Highest protocol version the sender speaks.
    pub version: u8,
    /// What the sender can do.
    pub capabilities: Capabilities,
}

impl HelloRepr {
    /// Reads a `Hello` payload.
    pub fn parse<T: AsRef<[u8]> + ?Sized>(packet: &Packet<&T>) -> Result<HelloRepr, Error> {
        packet.check_len()?;
        Ok(HelloRepr {
            version: packet.version(),
            capabilities: Capabilities(packet.capabilities()),
        })
    }

    /// Payload length `emit` writes.
    pub const fn buffer_len(&self) -> usize {
        LEN
    }

    /// Writes the payload into `packet`.
    pub fn emit<T: AsRef<[u8]> + AsMut<[u8]>>(&self, packet: &mut Packet<T>) -> Result<(), Error> {
        check_room(packet.buffer.as_ref().len(), self.buffer_len())?;
        packet.set_version(self.version);
        packet.set_capabilities(self.capabilities.0);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    static PACKET_BYTES: [u8; 5] = [
        0x01, // version 1
        0x1f, 0x00, 0x00, 0x80, // capabilities: five known bits and bit 31
    ];

    fn repr() -> HelloRepr {
        HelloRepr {
            version: 1,
            capabilities: Capabilities::POINTS
                | Capabilities::SOBEL_ROWS
                | Capabilities::SOBEL_PATCHES
                | Capabilities::LOG
                | Capabilities::REGISTERS
                | Capabilities(1 << 31),
        }
    }

    #[test]
    fn deconstruct() {
        let packet = Packet::new_checked(&PACKET_BYTES[..]).unwrap();
        assert_eq!(packet.version(), 1);
        assert_eq!(packet.capabilities(), 0x8000_001f);
    }

    #[test]
    fn construct() {
        let mut bytes = [0xa5u8; LEN];
        let mut packet = Packet::new_unchecked(&mut bytes[..]);
        packet.set_version(1);
        packet.set_capabilities(0x8000_001f);
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn parse() {
        let packet = Packet::new_unchecked(&PACKET_BYTES[..]);
        assert_eq!(HelloRepr::parse(&packet), Ok(repr()));
        assert!(repr().capabilities.contains(Capabilities::LOG));
    }

    #[test]
    fn emit() {
        let mut bytes = [0u8; LEN];
        repr()
            .emit(&mut Packet::new_unchecked(&mut bytes[..]))
            .unwrap();
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn impossible_length() {
        assert_eq!(
            Packet::new_checked(&PACKET_BYTES[..4]).unwrap_err(),
            Error::DecodeUnexpectedEnd
        );
        assert_eq!(
            Packet::new_checked(&[0u8; 6][..]).unwrap_err(),
            Error::DecodeBadLength
        );
        let mut short = [0u8; 4];
        assert_eq!(
            repr().emit(&mut Packet::new_unchecked(&mut short[..])),
            Err(Error::EncodeBufferTooSmall)
        );
    }
}
