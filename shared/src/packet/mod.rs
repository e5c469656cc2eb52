//! Typed views over packet bytes, one module per packet kind.
//!
//! Each module has:
//! - a `Packet<T: AsRef<[u8]>>` view over the bytes of one payload (or, in [`header`], of a
//!   whole packet), with a private `field` module of byte ranges;
//! - `Packet::new_checked`, which runs `check_len`: **once `check_len` has passed, no accessor
//!   of the view can panic**, whatever the bytes are. `new_unchecked` skips the check, and then
//!   accessors may panic on a short buffer; it exists for emitting into a buffer whose length
//!   the caller has already made right;
//! - a `Repr` with `parse(&Packet) -> Result<Repr, Error>`, `emit(&self, &mut Packet)` into a
//!   caller-owned buffer, and `buffer_len()`, the payload length `emit` needs. `emit` checks
//!   the buffer length itself and returns [`Error::EncodeBufferTooSmall`](crate::Error)
//!   instead of panicking.
//!
//! All multi-byte fields are little-endian. Most users want the whole-packet
//! [`encode`](crate::encode) / [`decode`](crate::decode) and the
//! [`Accumulator`](crate::Accumulator), not these views.

/// The constructors every view shares; `check_len` is written per kind.
macro_rules! packet_view {
    ($(#[$attr:meta])*) => {
        $(#[$attr])*
        #[derive(Debug, Clone, PartialEq, Eq)]
        pub struct Packet<T: AsRef<[u8]>> {
            buffer: T,
        }

        impl<T: AsRef<[u8]>> Packet<T> {
            /// Wraps `buffer` without checking its length (accessors may then panic).
            pub const fn new_unchecked(buffer: T) -> Packet<T> {
                Packet { buffer }
            }

            /// Wraps `buffer` and runs `check_len`, after which no accessor panics.
            pub fn new_checked(buffer: T) -> Result<Packet<T>, crate::Error> {
                let packet = Self::new_unchecked(buffer);
                packet.check_len()?;
                Ok(packet)
            }

            /// Gives the buffer back.
            pub fn into_inner(self) -> T {
                self.buffer
            }
        }
    };
}

/// Checks that a buffer holds exactly a fixed-size payload of `len` bytes.
fn check_fixed_len(actual: usize, len: usize) -> Result<(), crate::Error> {
    match actual.cmp(&len) {
        core::cmp::Ordering::Less => Err(crate::Error::DecodeUnexpectedEnd),
        core::cmp::Ordering::Equal => Ok(()),
        core::cmp::Ordering::Greater => Err(crate::Error::DecodeBadLength),
    }
}

/// Checks that `emit` has room for `needed` bytes.
fn check_room(actual: usize, needed: usize) -> Result<(), crate::Error> {
    if actual < needed {
        Err(crate::Error::EncodeBufferTooSmall)
    } else {
        Ok(())
    }
}

pub mod camera;
pub mod encoders;
pub mod error_report;
pub mod frame_end;
pub mod frame_failure;
pub mod frame_start;
pub mod header;
pub mod hello;
pub mod kind;
pub mod log;
pub mod point_batch;
pub mod register_read;
pub mod register_value;
pub mod register_write;
pub mod sobel_patch;
pub mod sobel_pixel;
pub mod sobel_rows;
pub mod source;
