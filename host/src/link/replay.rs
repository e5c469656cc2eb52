//! A link that plays back bytes captured earlier (a QEMU session, a board's UART dump) and
//! keeps what the host sends, so a run can be reproduced and tested without the device.

use std::path::Path;
use std::time::Instant;

use super::{Link, LinkError};

/// Plays back a byte capture in chunks of a chosen size.
#[derive(Debug, Clone)]
pub struct ReplayLink {
    bytes: Vec<u8>,
    pos: usize,
    chunk: usize,
    sent: Vec<u8>,
}

impl ReplayLink {
    /// Plays `bytes` back as fast as the driver asks, in chunks of up to 4096 bytes.
    pub fn new(bytes: Vec<u8>) -> Self {
        Self {
            bytes,
            pos: 0,
            chunk: 4096,
            sent: Vec::new(),
        }
    }

    /// Reads the capture from `path`.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self, LinkError> {
        let path = path.as_ref();
        std::fs::read(path)
            .map(Self::new)
            .map_err(|source| LinkError::Open {
                link: format!("replay {}", path.display()),
                source,
            })
    }

    /// Delivers at most `chunk` bytes per receive (at least 1), to exercise reassembly
    /// across arbitrary splits.
    pub fn with_chunk(mut self, chunk: usize) -> Self {
        self.chunk = chunk.max(1);
        self
    }

    /// Everything the host sent so far.
    pub fn sent(&self) -> &[u8] {
        &self.sent
    }
}

impl Link for ReplayLink {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.sent.extend_from_slice(bytes);
        Ok(())
    }

    /// Hands out the next chunk; at the end of the capture the link is closed.
    fn recv(&mut self, buf: &mut [u8], _deadline: Instant) -> Result<usize, LinkError> {
        let left = &self.bytes[self.pos..];
        if left.is_empty() {
            return Err(LinkError::Closed {
                link: "replay".into(),
            });
        }
        let n = left.len().min(self.chunk).min(buf.len());
        buf[..n].copy_from_slice(&left[..n]);
        self.pos += n;
        Ok(n)
    }
}
