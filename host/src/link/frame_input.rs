//! The camera side of a device whose pixels the host provides: the in-process device takes
//! them through a call, the firmware under QEMU had them loaded into its frame-grabber region
//! at boot. The bytes the device answers with travel over its [`Link`](super::Link), like
//! every other device's.
//!
//! A head that grabs its own frames ([`OwnCameras`](super::OwnCameras)) has no frame input:
//! a session on it can only [`receive`](crate::session::Session::receive), and asking it to
//! take a pair does not compile.

use super::{InProcessLink, LinkError};

/// A device's camera input, driven by the host.
pub trait FrameInput {
    /// Delivers a stereo pair (raster order, 8-bit grey, the configured size) captured at
    /// `timestamp_us`; its packets arrive over the link, left camera first.
    fn submit_pair(
        &mut self,
        left: &[u8],
        right: &[u8],
        timestamp_us: u64,
    ) -> Result<(), LinkError>;

    /// Pairs a session may submit beyond the one whose packets it is waiting for: 0 for a
    /// device that computes a pair only while the host waits for it, more for one that works
    /// on its own ([`Threaded`](super::Threaded)).
    fn lookahead(&self) -> usize {
        0
    }
}

/// A borrowed input is an input: the caller keeps the device, e.g. to stop an emulator and
/// read its exit status after a session on it failed.
impl<F: FrameInput + ?Sized> FrameInput for &mut F {
    fn submit_pair(
        &mut self,
        left: &[u8],
        right: &[u8],
        timestamp_us: u64,
    ) -> Result<(), LinkError> {
        (**self).submit_pair(left, right, timestamp_us)
    }

    fn lookahead(&self) -> usize {
        (**self).lookahead()
    }
}

impl FrameInput for InProcessLink {
    fn submit_pair(
        &mut self,
        left: &[u8],
        right: &[u8],
        timestamp_us: u64,
    ) -> Result<(), LinkError> {
        InProcessLink::submit_pair(self, left, right, timestamp_us).map(|_| ())
    }
}
