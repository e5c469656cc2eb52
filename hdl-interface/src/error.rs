//! Errors of register access.

use core::fmt;

/// What was wrong with a register access or a configuration value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Error {
    /// The byte offset is not a multiple of 4.
    MisalignedOffset { offset: u16 },
    /// No register lives at this byte offset.
    UnmappedOffset { offset: u16 },
    /// The value is outside what the field accepts (`min..=max`, from the description).
    FieldOutOfRange {
        field: &'static str,
        value: u32,
        min: u32,
        max: u32,
    },
    /// The bus cannot write this field (it is `ro`).
    FieldReadOnly { field: &'static str },
    /// Width and height must be multiples of `2^(octaves - 1)` so each octave has whole pixels.
    FrameNotDivisible {
        width: u16,
        height: u16,
        octaves: u8,
    },
    /// A field holds a code that names no value of its enum.
    UnknownEnumValue { field: &'static str, value: u32 },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Error::MisalignedOffset { offset } => {
                write!(f, "register offset {offset:#06x} is not 32-bit aligned")
            }
            Error::UnmappedOffset { offset } => {
                write!(f, "no register at offset {offset:#06x}")
            }
            Error::FieldOutOfRange {
                field,
                value,
                min,
                max,
            } => {
                write!(f, "{field} = {value} is outside {min}..={max}")
            }
            Error::FieldReadOnly { field } => write!(f, "{field} is read-only"),
            Error::FrameNotDivisible {
                width,
                height,
                octaves,
            } => write!(
                f,
                "frame {width}x{height} is not a multiple of {} as {octaves} octaves need",
                1u32 << octaves.saturating_sub(1).min(31)
            ),
            Error::UnknownEnumValue { field, value } => {
                write!(f, "{field} holds {value}, which names no value")
            }
        }
    }
}

impl core::error::Error for Error {}
