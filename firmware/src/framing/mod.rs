//! Wire framing shared by the soft-core and the fabric's stream engine: the byte sink a link
//! is, the [`Framer`] that turns a packet into a link frame (CRC-32C, COBS, optional forward
//! error correction), the per-source [`Numbering`], and the soft-core's [`PacketWriter`].
//!
//! Each sender on the link frames its own packets: the soft-core its control packets, each
//! camera channel's stream engine that camera's frames. Neither rewrites the other's bytes.

mod numbering;
mod sink;

pub use numbering::Numbering;
pub use sink::{ByteSink, Framer, PacketWriter};
