//! A device that captures with cameras of its own: a board on a serial port, or the firmware
//! under an emulator that somebody else started, on a TCP or Unix socket.
//!
//! The host configures and enables such a device and then only listens: pairs arrive when
//! the cameras take them, stamped with the device's own capture time. It takes no pixels from
//! the host, so it has no [`FrameInput`](super::FrameInput); sessions on it read pairs with
//! [`Session::receive`](crate::session::Session::receive).

use std::time::{Duration, Instant};

use super::{Link, LinkError};

/// A [`Link`] to a stereo head that grabs its own frames, with the time the host waits for
/// its next pair (the head's frame period and then some, which only its user knows).
#[derive(Debug)]
pub struct OwnCameras<L> {
    link: L,
    timeout: Duration,
}

impl<L: Link> OwnCameras<L> {
    /// Wraps `link`; the host waits at most `timeout` for an answer or for the next pair.
    pub fn new(link: L, timeout: Duration) -> Self {
        Self { link, timeout }
    }
}

impl<L: Link> Link for OwnCameras<L> {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.link.send(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], deadline: Instant) -> Result<usize, LinkError> {
        self.link.recv(buf, deadline)
    }

    fn answer_timeout(&self) -> Duration {
        self.timeout
    }
}
