//! A link that keeps every byte it received: the device's side of a conversation, for
//! byte-for-byte comparisons between devices and for reading logs back after a run.

use std::time::{Duration, Instant};

use super::{FrameInput, Link, LinkError};

/// `inner`, with every byte received from it kept in order.
#[derive(Debug)]
pub struct Recording<L> {
    inner: L,
    received: Vec<u8>,
}

impl<L> Recording<L> {
    /// Wraps `inner`, with nothing received yet.
    pub fn new(inner: L) -> Self {
        Self {
            inner,
            received: Vec::new(),
        }
    }

    /// Every byte received so far.
    pub fn received(&self) -> &[u8] {
        &self.received
    }

    /// Takes the bytes received so far, leaving the record empty.
    pub fn take_received(&mut self) -> Vec<u8> {
        std::mem::take(&mut self.received)
    }

    /// The link being recorded.
    pub fn inner(&self) -> &L {
        &self.inner
    }
}

impl<L: Link> Link for Recording<L> {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.inner.send(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], deadline: Instant) -> Result<usize, LinkError> {
        let n = self.inner.recv(buf, deadline)?;
        self.received.extend_from_slice(&buf[..n]);
        Ok(n)
    }

    fn answer_timeout(&self) -> Duration {
        self.inner.answer_timeout()
    }
}

impl<D: FrameInput> FrameInput for Recording<D> {
    fn submit_pair(
        &mut self,
        left: &[u8],
        right: &[u8],
        timestamp_us: u64,
    ) -> Result<(), LinkError> {
        self.inner.submit_pair(left, right, timestamp_us)
    }

    fn lookahead(&self) -> usize {
        self.inner.lookahead()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::link::ReplayLink;

    #[test]
    fn keeps_what_it_hands_out() {
        let mut link = Recording::new(ReplayLink::new(vec![1, 2, 3, 0, 5]));
        let mut buf = [0u8; 2];
        let deadline = Instant::now() + Duration::from_millis(100);
        let n = link.recv(&mut buf, deadline).unwrap();
        assert_eq!(link.received(), &buf[..n]);
        assert_eq!(link.take_received(), buf[..n].to_vec());
        assert!(link.received().is_empty());
    }
}
