//! A device that captures with cameras of its own: a board on a serial port, or the firmware
//! under an emulator that somebody else started, on a TCP or Unix socket.
//!
//! The host configures and enables such a device and then only listens: pairs arrive when
//! the cameras take them, stamped with the device's own capture time. It takes no pixels from
//! the host, so [`Device::submit_pair`] is an error rather than a silent no-op; sessions on it
//! read pairs with [`Session::receive`](crate::session::Session::receive).

use std::time::{Duration, Instant};

use super::{Device, Link, LinkError};

/// A [`Link`] to a stereo head that grabs its own frames.
#[derive(Debug)]
pub struct OwnCameras<L> {
    link: L,
    name: String,
    timeout: Duration,
}

impl<L: Link> OwnCameras<L> {
    /// Wraps `link` (named `name` in errors, e.g. `"serial /dev/ttyUSB0"`); the host waits
    /// at most `timeout` for an answer or for the next pair.
    pub fn new(link: L, name: impl Into<String>, timeout: Duration) -> Self {
        Self {
            link,
            name: name.into(),
            timeout,
        }
    }
}

impl<L: Link> Link for OwnCameras<L> {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.link.send(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], deadline: Instant) -> Result<usize, LinkError> {
        self.link.recv(buf, deadline)
    }
}

impl<L: Link> Device for OwnCameras<L> {
    fn submit_pair(&mut self, _: &[u8], _: &[u8], _: u64) -> Result<(), LinkError> {
        Err(LinkError::OwnCameras {
            link: self.name.clone(),
        })
    }

    fn answer_timeout(&self) -> Duration {
        self.timeout
    }
}
