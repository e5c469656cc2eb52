//! A link whose far end takes camera frames: what a [`Session`](crate::session::Session) runs
//! on.
//!
//! The in-process device gets its pixels through a call; the firmware under QEMU got them
//! in its frame-grabber region before it booted. A session does not care which: it hands
//! every pair to [`Device::submit_pair`] and reads the packets back over the link.

use std::time::{Duration, Instant};

use super::{InProcessLink, Link, LinkError};

/// How long the host waits for the in-process device's answer to one request or one frame.
/// It answers synchronously, so this only bounds a device that has nothing to send.
const IN_PROCESS_TIMEOUT: Duration = Duration::from_secs(5);

/// A [`Link`] to a stereo front end.
pub trait Device: Link {
    /// Delivers a stereo pair (raster order, 8-bit grey, the configured size) captured at
    /// `timestamp_us`; its packets arrive over the link, left camera first.
    fn submit_pair(
        &mut self,
        left: &[u8],
        right: &[u8],
        timestamp_us: u64,
    ) -> Result<(), LinkError>;

    /// How long the host waits for one answer or one frame pair from this device.
    fn answer_timeout(&self) -> Duration;

    /// Pairs a session may submit beyond the one whose packets it is waiting for: 0 for a
    /// device that computes a pair only while the host waits for it, more for one that works
    /// on its own ([`Threaded`](super::Threaded)).
    fn lookahead(&self) -> usize {
        0
    }

    /// Appends to `out` every byte the device has sent so far and the host has not read.
    /// The default reads them through [`Link::recv`] without waiting, so a wrapper that
    /// records or damages what `recv` returns sees them; a device that holds its output in
    /// memory hands it over whole.
    fn take_sent(&mut self, out: &mut Vec<u8>) -> Result<(), LinkError> {
        let mut chunk = [0u8; 4096];
        loop {
            match self.recv(&mut chunk, Instant::now()) {
                Ok(n) => out.extend_from_slice(chunk.get(..n).unwrap_or_default()),
                Err(LinkError::Timeout { .. }) => return Ok(()),
                Err(e) => return Err(e),
            }
        }
    }
}

/// A borrowed device is a device: the caller keeps it, e.g. to stop an emulator and read its
/// exit status after a session on it failed.
impl<D: Device + ?Sized> Device for &mut D {
    fn submit_pair(
        &mut self,
        left: &[u8],
        right: &[u8],
        timestamp_us: u64,
    ) -> Result<(), LinkError> {
        (**self).submit_pair(left, right, timestamp_us)
    }

    fn answer_timeout(&self) -> Duration {
        (**self).answer_timeout()
    }

    fn lookahead(&self) -> usize {
        (**self).lookahead()
    }

    fn take_sent(&mut self, out: &mut Vec<u8>) -> Result<(), LinkError> {
        (**self).take_sent(out)
    }
}

impl Device for InProcessLink {
    fn submit_pair(
        &mut self,
        left: &[u8],
        right: &[u8],
        timestamp_us: u64,
    ) -> Result<(), LinkError> {
        InProcessLink::submit_pair(self, left, right, timestamp_us).map(|_| ())
    }

    fn answer_timeout(&self) -> Duration {
        IN_PROCESS_TIMEOUT
    }

    fn take_sent(&mut self, out: &mut Vec<u8>) -> Result<(), LinkError> {
        InProcessLink::take_sent(self, out);
        Ok(())
    }
}
