//! Whether a device sent the in-process device's bytes.
//!
//! The firmware answers the host's `Hello` with the `LOG` capability added (it has a defmt
//! logger; the in-process device does not). Every byte after that first link frame must be
//! identical: register answers, every frame's packets, their sequence numbers and CRCs.

use stereocal_wire::{decode, Capabilities, PacketRepr, DELIMITER};

/// How a device's stream differs from the in-process device's.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum StreamMismatch {
    /// A stream has no complete link frame.
    #[error("the {who} sent no complete link frame")]
    NoFrame {
        /// `device` or `in-process device`.
        who: &'static str,
    },
    /// A stream's first link frame is not a `Hello`.
    #[error("the {who}'s first link frame is not a Hello")]
    NoHello {
        /// `device` or `in-process device`.
        who: &'static str,
    },
    /// The `Hello`s differ beyond the `LOG` capability.
    #[error(
        "the Hellos differ: the device's sequence {device_seq} version {device_version} \
         capabilities {device_caps:#x}, the in-process device's {in_process_seq} \
         {in_process_version} {in_process_caps:#x} (plus LOG)"
    )]
    Hello {
        /// The device's header sequence number.
        device_seq: u16,
        /// Its protocol version.
        device_version: u8,
        /// Its capability bits.
        device_caps: u32,
        /// The in-process device's sequence number.
        in_process_seq: u16,
        /// Its protocol version.
        in_process_version: u8,
        /// Its capability bits.
        in_process_caps: u32,
    },
    /// The bytes after the `Hello` differ.
    #[error(
        "the streams differ after the Hello at byte {at} (link frame {frame}): the device \
         sent {device_len} bytes, the in-process device {in_process_len}"
    )]
    Bytes {
        /// The first differing byte after the `Hello`.
        at: usize,
        /// The link frame it is in, counted after the `Hello`.
        frame: usize,
        /// Bytes after the `Hello` from the device.
        device_len: usize,
        /// Bytes after the `Hello` from the in-process device.
        in_process_len: usize,
    },
}

/// Checks that `device` sent what `in_process` sent (see the module docs).
pub fn compare_streams(device: &[u8], in_process: &[u8]) -> Result<(), StreamMismatch> {
    let (d_hello, d_rest) = split_hello(device, "device")?;
    let (i_hello, i_rest) = split_hello(in_process, "in-process device")?;
    if d_hello.seq != i_hello.seq
        || d_hello.version != i_hello.version
        || d_hello.capabilities != i_hello.capabilities | Capabilities::LOG.0
    {
        return Err(StreamMismatch::Hello {
            device_seq: d_hello.seq,
            device_version: d_hello.version,
            device_caps: d_hello.capabilities,
            in_process_seq: i_hello.seq,
            in_process_version: i_hello.version,
            in_process_caps: i_hello.capabilities,
        });
    }
    if d_rest == i_rest {
        return Ok(());
    }
    let at = d_rest
        .iter()
        .zip(i_rest)
        .position(|(a, b)| a != b)
        .unwrap_or(d_rest.len().min(i_rest.len()));
    Err(StreamMismatch::Bytes {
        at,
        frame: d_rest[..at].iter().filter(|&&b| b == DELIMITER).count(),
        device_len: d_rest.len(),
        in_process_len: i_rest.len(),
    })
}

/// What a stream's `Hello` says.
struct Hello {
    seq: u16,
    version: u8,
    capabilities: u32,
}

/// The first link frame's `Hello` and the bytes after it.
fn split_hello<'a>(
    bytes: &'a [u8],
    who: &'static str,
) -> Result<(Hello, &'a [u8]), StreamMismatch> {
    let end = bytes
        .iter()
        .position(|&b| b == DELIMITER)
        .ok_or(StreamMismatch::NoFrame { who })?;
    let (first, rest) = bytes.split_at(end + 1);
    let mut frame = first.to_vec();
    match decode(&mut frame) {
        Ok((header, PacketRepr::Hello(hello))) => Ok((
            Hello {
                seq: header.seq,
                version: hello.version,
                capabilities: hello.capabilities.0,
            },
            rest,
        )),
        _ => Err(StreamMismatch::NoHello { who }),
    }
}
