//! The whole packet: a 7-byte header, the payload, and a CRC-32C trailer.
//!
//! ```text
//!  0        1        2        3        5              7                7+n        11+n
//! +--------+--------+--------+--------+--------------+-- ... --+------------------+
//! |version |  kind  | source |  seq   | payload len n| payload |  CRC-32C (LE)    |
//! |   u8   |   u8   |   u8   | u16 LE |    u16 LE    | n bytes | over bytes 0..7+n|
//! +--------+--------+--------+--------+--------------+-- ... --+------------------+
//! ```
//! `seq` counts the packets of `source` alone (see [`Source`]).

use crate::checksum::crc32c;
use crate::le::{self, Field};
use crate::packet::check_room;
use crate::packet::kind::PacketKind;
use crate::packet::source::Source;
use crate::Error;

mod field {
    use super::Field;
    pub const VERSION: usize = 0;
    pub const KIND: usize = 1;
    pub const SOURCE: usize = 2;
    pub const SEQ: Field = 3..5;
    pub const PAYLOAD_LEN: Field = 5..7;
    pub const PAYLOAD: usize = 7;
}

/// Bytes before the payload.
pub const HEADER_LEN: usize = field::PAYLOAD;
/// Bytes of the CRC trailer.
pub const CRC_LEN: usize = 4;

packet_view! {
    /// A view over a whole packet (header, payload, CRC), before COBS framing.
}

impl<T: AsRef<[u8]>> Packet<T> {
    /// Checks that the buffer holds the header, exactly `payload_len` payload bytes, and the CRC.
    pub fn check_len(&self) -> Result<(), Error> {
        let len = self.buffer.as_ref().len();
        if len < HEADER_LEN + CRC_LEN {
            return Err(Error::DecodeUnexpectedEnd);
        }
        let needed = HEADER_LEN + usize::from(self.payload_len()) + CRC_LEN;
        super::check_fixed_len(len, needed)
    }

    /// Protocol version of the sender.
    pub fn version(&self) -> u8 {
        le::read_u8(self.buffer.as_ref(), field::VERSION)
    }

    /// Packet kind.
    pub fn kind(&self) -> PacketKind {
        PacketKind::from(le::read_u8(self.buffer.as_ref(), field::KIND))
    }

    /// Which sender of its end wrote the packet.
    pub fn source(&self) -> Source {
        Source::from(le::read_u8(self.buffer.as_ref(), field::SOURCE))
    }

    /// Sequence number; the source increments it (wrapping) per packet, so gaps show loss.
    pub fn seq(&self) -> u16 {
        le::read_u16(self.buffer.as_ref(), field::SEQ)
    }

    /// Payload length in bytes.
    pub fn payload_len(&self) -> u16 {
        le::read_u16(self.buffer.as_ref(), field::PAYLOAD_LEN)
    }

    /// The payload bytes.
    pub fn payload(&self) -> &[u8] {
        let data = self.buffer.as_ref();
        le::sub(data, field::PAYLOAD..data.len().saturating_sub(CRC_LEN))
    }

    /// The CRC stored in the trailer.
    pub fn crc(&self) -> u32 {
        let data = self.buffer.as_ref();
        le::read_u32(data, data.len().saturating_sub(CRC_LEN)..data.len())
    }

    /// `true` when the trailer matches the CRC-32C of everything before it.
    pub fn verify_crc(&self) -> bool {
        let data = self.buffer.as_ref();
        crc32c(le::sub(data, ..data.len().saturating_sub(CRC_LEN))) == self.crc()
    }
}

impl<T: AsRef<[u8]> + AsMut<[u8]>> Packet<T> {
    /// Sets the protocol version.
    pub fn set_version(&mut self, value: u8) {
        le::write_u8(self.buffer.as_mut(), field::VERSION, value);
    }

    /// Sets the packet kind.
    pub fn set_kind(&mut self, value: PacketKind) {
        le::write_u8(self.buffer.as_mut(), field::KIND, u8::from(value));
    }

    /// Sets the source.
    pub fn set_source(&mut self, value: Source) {
        le::write_u8(self.buffer.as_mut(), field::SOURCE, u8::from(value));
    }

    /// Sets the sequence number.
    pub fn set_seq(&mut self, value: u16) {
        le::write_u16(self.buffer.as_mut(), field::SEQ, value);
    }

    /// Sets the payload length.
    pub fn set_payload_len(&mut self, value: u16) {
        le::write_u16(self.buffer.as_mut(), field::PAYLOAD_LEN, value);
    }

    /// The payload bytes, for a payload view to emit into.
    pub fn payload_mut(&mut self) -> &mut [u8] {
        let data = self.buffer.as_mut();
        let end = data.len().saturating_sub(CRC_LEN);
        le::sub_mut(data, field::PAYLOAD..end)
    }

    /// Computes the CRC over header and payload and stores it in the trailer.
    pub fn fill_crc(&mut self) {
        let data = self.buffer.as_mut();
        let end = data.len().saturating_sub(CRC_LEN);
        let crc = crc32c(le::sub(data, ..end));
        le::write_u32(data, end..data.len(), crc);
    }
}

/// The parsed header of a packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Header {
    /// Protocol version of the sender.
    pub version: u8,
    /// Packet kind.
    pub kind: PacketKind,
    /// Which sender of its end wrote the packet.
    pub source: Source,
    /// Sequence number, counted per source.
    pub seq: u16,
    /// Payload length in bytes.
    pub payload_len: u16,
}

impl Header {
    /// Reads the header of a checked packet (the CRC and version are checked by
    /// [`decode`](crate::decode), not here).
    pub fn parse<T: AsRef<[u8]> + ?Sized>(packet: &Packet<&T>) -> Result<Header, Error> {
        packet.check_len()?;
        Ok(Header {
            version: packet.version(),
            kind: packet.kind(),
            source: packet.source(),
            seq: packet.seq(),
            payload_len: packet.payload_len(),
        })
    }

    /// Bytes of the whole packet: header, payload and CRC.
    pub fn buffer_len(&self) -> usize {
        HEADER_LEN + usize::from(self.payload_len) + CRC_LEN
    }

    /// Writes the header fields (not the payload or the CRC).
    pub fn emit<T: AsRef<[u8]> + AsMut<[u8]>>(&self, packet: &mut Packet<T>) -> Result<(), Error> {
        check_room(packet.buffer.as_ref().len(), self.buffer_len())?;
        packet.set_version(self.version);
        packet.set_kind(self.kind);
        packet.set_source(self.source);
        packet.set_seq(self.seq);
        packet.set_payload_len(self.payload_len);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The `register_read` vector of the spec: RegisterRead of 0x0104, from the host's
    /// control source, seq 3.
    static PACKET_BYTES: [u8; 13] = [
        0x02, // version 2
        0x03, // kind RegisterRead
        0x00, // source Control
        0x03, 0x00, // seq 3
        0x02, 0x00, // payload_len 2
        0x04, 0x01, // payload: addr 0x0104
        0x2f, 0x3f, 0x0a, 0xba, // CRC-32C 0xba0a3f2f
    ];

    const HEADER: Header = Header {
        version: 2,
        kind: PacketKind::RegisterRead,
        source: Source::Control,
        seq: 3,
        payload_len: 2,
    };

    #[test]
    fn deconstruct() {
        let packet = Packet::new_checked(&PACKET_BYTES[..]).unwrap();
        assert_eq!(packet.version(), 2);
        assert_eq!(packet.kind(), PacketKind::RegisterRead);
        assert_eq!(packet.source(), Source::Control);
        assert_eq!(packet.seq(), 3);
        assert_eq!(packet.payload_len(), 2);
        assert_eq!(packet.payload(), &[0x04, 0x01]);
        assert_eq!(packet.crc(), 0xba0a_3f2f);
        assert!(packet.verify_crc());
    }

    #[test]
    fn construct() {
        let mut bytes = [0xa5u8; 13];
        let mut packet = Packet::new_unchecked(&mut bytes[..]);
        packet.set_version(2);
        packet.set_kind(PacketKind::RegisterRead);
        packet.set_source(Source::Control);
        packet.set_seq(3);
        packet.set_payload_len(2);
        packet.payload_mut().copy_from_slice(&[0x04, 0x01]);
        packet.fill_crc();
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn parse() {
        let packet = Packet::new_unchecked(&PACKET_BYTES[..]);
        assert_eq!(Header::parse(&packet), Ok(HEADER));
        assert_eq!(HEADER.buffer_len(), PACKET_BYTES.len());
    }

    #[test]
    fn emit() {
        let mut bytes = [0u8; 13];
        let mut packet = Packet::new_unchecked(&mut bytes[..]);
        HEADER.emit(&mut packet).unwrap();
        packet.payload_mut().copy_from_slice(&[0x04, 0x01]);
        packet.fill_crc();
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn corrupted_byte_fails_the_crc() {
        for at in 0..PACKET_BYTES.len() {
            let mut bytes = PACKET_BYTES;
            bytes[at] ^= 0x10;
            assert!(!Packet::new_unchecked(&bytes[..]).verify_crc(), "byte {at}");
        }
    }

    #[test]
    fn impossible_length() {
        assert_eq!(
            Packet::new_checked(&PACKET_BYTES[..10]).unwrap_err(),
            Error::DecodeUnexpectedEnd
        );
        assert_eq!(
            Packet::new_checked(&PACKET_BYTES[..12]).unwrap_err(),
            Error::DecodeUnexpectedEnd
        );
        let mut long = [0u8; 14];
        long[..13].copy_from_slice(&PACKET_BYTES);
        assert_eq!(
            Packet::new_checked(&long[..]).unwrap_err(),
            Error::DecodeBadLength
        );
        let mut short = [0u8; 12];
        assert_eq!(
            HEADER.emit(&mut Packet::new_unchecked(&mut short[..])),
            Err(Error::EncodeBufferTooSmall)
        );
    }
}
