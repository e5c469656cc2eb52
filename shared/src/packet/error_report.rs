//! `ErrorReport` (`0x21`, the spec's `Error` kind), both ways: the sender hit a problem.
//!
//! ```text
//!  0          2                  6
//! +----------+------------------+
//! |   code   |      detail      |
//! |  u16 LE  |      u32 LE      |
//! +----------+------------------+
//! ```
//! What `detail` holds depends on the code (see [`ErrorCode`]).

use crate::le::{self, Field};
use crate::packet::{check_fixed_len, check_room};
use crate::Error;

mod field {
    use super::Field;
    pub const CODE: Field = 0..2;
    pub const DETAIL: Field = 2..6;
}

/// Payload length of an `ErrorReport`.
pub const LEN: usize = field::DETAIL.end;

packet_view! {
    /// A view over an `ErrorReport` payload.
}

impl<T: AsRef<[u8]>> Packet<T> {
    /// Checks that the buffer is exactly [`LEN`] bytes.
    pub fn check_len(&self) -> Result<(), Error> {
        check_fixed_len(self.buffer.as_ref().len(), LEN)
    }

    /// Error code.
    pub fn code(&self) -> ErrorCode {
        ErrorCode::from(le::read_u16(self.buffer.as_ref(), field::CODE))
    }

    /// Code-specific detail.
    pub fn detail(&self) -> u32 {
        le::read_u32(self.buffer.as_ref(), field::DETAIL)
    }
}

impl<T: AsRef<[u8]> + AsMut<[u8]>> Packet<T> {
    /// Sets the error code.
    pub fn set_code(&mut self, value: ErrorCode) {
        le::write_u16(self.buffer.as_mut(), field::CODE, u16::from(value));
    }

    /// Sets the detail word.
    pub fn set_detail(&mut self, value: u32) {
        le::write_u32(self.buffer.as_mut(), field::DETAIL, value);
    }
}

/// What went wrong at the peer. Unknown codes are kept so they round-trip.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ErrorCode {
    /// `0x0001`: a received frame did not decode; `detail` is the sequence number of the last
    /// packet that did.
    BadPacket,
    /// `0x0002`: a register access named an address outside the map; `detail` is the address.
    UnknownRegister,
    /// `0x0003`: the peer's protocol version is not supported; `detail` is that version.
    UnsupportedVersion,
    /// `0x0004`: the device is not ready for the request (e.g. a frame is in flight);
    /// `detail` is the packet kind byte of the refused request.
    Busy,
    /// `0x0100`: the fabric's registers hold a configuration it cannot run; `detail` is the
    /// byte address of the register at fault (`0xFFFF_FFFF` when no one register is).
    InvalidConfig,
    /// `0x0101`: the host sent a kind only the device sends; `detail` is the kind byte.
    UnexpectedKind,
    /// `0x0102`: a camera frame could not be processed; `detail` is a
    /// [`FrameFailure`](crate::FrameFailure) cause and value.
    FrameFailed,
    /// Any other value.
    Unknown(u16),
}

impl From<u16> for ErrorCode {
    fn from(value: u16) -> Self {
        match value {
            0x0001 => ErrorCode::BadPacket,
            0x0002 => ErrorCode::UnknownRegister,
            0x0003 => ErrorCode::UnsupportedVersion,
            0x0004 => ErrorCode::Busy,
            0x0100 => ErrorCode::InvalidConfig,
            0x0101 => ErrorCode::UnexpectedKind,
            0x0102 => ErrorCode::FrameFailed,
            other => ErrorCode::Unknown(other),
        }
    }
}

impl From<ErrorCode> for u16 {
    fn from(code: ErrorCode) -> u16 {
        match code {
            ErrorCode::BadPacket => 0x0001,
            ErrorCode::UnknownRegister => 0x0002,
            ErrorCode::UnsupportedVersion => 0x0003,
            ErrorCode::Busy => 0x0004,
            ErrorCode::InvalidConfig => 0x0100,
            ErrorCode::UnexpectedKind => 0x0101,
            ErrorCode::FrameFailed => 0x0102,
            ErrorCode::Unknown(other) => other,
        }
    }
}

/// A parsed `ErrorReport`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ErrorReportRepr {
    /// What went wrong.
    pub code: ErrorCode,
    /// Code-specific detail.
    pub detail: u32,
}

impl ErrorReportRepr {
    /// Reads an `ErrorReport` payload.
    pub fn parse<T: AsRef<[u8]> + ?Sized>(packet: &Packet<&T>) -> Result<ErrorReportRepr, Error> {
        packet.check_len()?;
        Ok(ErrorReportRepr {
            code: packet.code(),
            detail: packet.detail(),
        })
    }

    /// Payload length `emit` writes.
    pub const fn buffer_len(&self) -> usize {
        LEN
    }

    /// Writes the payload into `packet`.
    pub fn emit<T: AsRef<[u8]> + AsMut<[u8]>>(&self, packet: &mut Packet<T>) -> Result<(), Error> {
        check_room(packet.buffer.as_ref().len(), self.buffer_len())?;
        packet.set_code(self.code);
        packet.set_detail(self.detail);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    static PACKET_BYTES: [u8; 6] = [
        0x02, 0x00, // code UnknownRegister
        0x00, 0x90, 0x00, 0x00, // detail 0x9000
    ];

    const REPR: ErrorReportRepr = ErrorReportRepr {
        code: ErrorCode::UnknownRegister,
        detail: 0x9000,
    };

    #[test]
    fn deconstruct() {
        let packet = Packet::new_checked(&PACKET_BYTES[..]).unwrap();
        assert_eq!(packet.code(), ErrorCode::UnknownRegister);
        assert_eq!(packet.detail(), 0x9000);
    }

    #[test]
    fn construct() {
        let mut bytes = [0xa5u8; LEN];
        let mut packet = Packet::new_unchecked(&mut bytes[..]);
        packet.set_code(ErrorCode::UnknownRegister);
        packet.set_detail(0x9000);
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn parse() {
        let packet = Packet::new_unchecked(&PACKET_BYTES[..]);
        assert_eq!(ErrorReportRepr::parse(&packet), Ok(REPR));
    }

    #[test]
    fn emit() {
        let mut bytes = [0u8; LEN];
        REPR.emit(&mut Packet::new_unchecked(&mut bytes[..]))
            .unwrap();
        assert_eq!(bytes, PACKET_BYTES);
    }

    #[test]
    fn every_code_round_trips() {
        for value in 0..=u16::MAX {
            assert_eq!(u16::from(ErrorCode::from(value)), value);
        }
        assert_eq!(ErrorCode::from(0x0102), ErrorCode::FrameFailed);
        assert_eq!(ErrorCode::from(0x0103), ErrorCode::Unknown(0x0103));
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
