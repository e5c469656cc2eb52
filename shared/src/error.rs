//! The one error type of the crate.

use core::fmt;

/// Everything that can go wrong while encoding or decoding a packet.
///
/// The variant name starts with the phase that failed (`Decode…` on the receiving side,
/// `Encode…` on the sending side), so a log line says on which side of the link to look.
/// `Copy` and small, so firmware can store it in a counter table or send it in an
/// [`ErrorReport`](crate::ErrorReportRepr) without allocation.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error {
    /// The COBS byte transform of a frame was invalid (a code byte points past the frame end).
    DecodeBadCobs,
    /// The frame was empty or shorter than the fields it has to contain.
    DecodeUnexpectedEnd,
    /// The CRC at the end of the packet did not match its contents.
    DecodeBadCrc,
    /// The protocol version byte is not in [`SUPPORTED_VERSIONS`](crate::SUPPORTED_VERSIONS).
    DecodeUnknownVersion,
    /// The packet kind byte names no kind this crate knows; a newer peer may send it.
    DecodeUnknownKind,
    /// The payload length disagrees with the header or with the kind's layout.
    DecodeBadLength,
    /// A record count or row width exceeds the kind's maximum.
    DecodeTooManyRecords,
    /// A Sobel orientation had one of its two top bits set (orientations are 6-bit).
    DecodeBadOrientation,
    /// A link frame under forward error correction had a length no body gives, or a block
    /// with more damage than the code repairs.
    DecodeBadFec,
    /// The output buffer is shorter than the encoded frame.
    EncodeBufferTooSmall,
    /// More records (points, pixels, log bytes) than the kind's maximum.
    EncodeTooManyRecords,
    /// A Sobel patch does not hold exactly 16x16 pixels.
    EncodeBadPatchSize,
    /// A Sobel orientation had one of its two top bits set (orientations are 6-bit).
    EncodeBadOrientation,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = match self {
            Error::DecodeBadCobs => "decode: invalid COBS encoding",
            Error::DecodeUnexpectedEnd => "decode: frame shorter than its fields",
            Error::DecodeBadCrc => "decode: CRC mismatch",
            Error::DecodeUnknownVersion => "decode: unsupported protocol version",
            Error::DecodeUnknownKind => "decode: unknown packet kind",
            Error::DecodeBadLength => "decode: payload length does not match the packet layout",
            Error::DecodeTooManyRecords => "decode: record count above the packet kind's maximum",
            Error::DecodeBadOrientation => "decode: Sobel orientation wider than 6 bits",
            Error::DecodeBadFec => "decode: link frame beyond what its error correction repairs",
            Error::EncodeBufferTooSmall => "encode: output buffer too small",
            Error::EncodeTooManyRecords => "encode: record count above the packet kind's maximum",
            Error::EncodeBadPatchSize => "encode: Sobel patch is not 16x16 pixels",
            Error::EncodeBadOrientation => "encode: Sobel orientation wider than 6 bits",
        };
        f.write_str(text)
    }
}

impl core::error::Error for Error {}
