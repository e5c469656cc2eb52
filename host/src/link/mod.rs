//! Byte links between the host and the device: one small trait, one implementation per
//! transport.
//!
//! A link moves opaque bytes; framing, CRCs and sequence numbers are the wire format's and
//! the [`driver`](crate::driver)'s business. Keeping the trait at two methods (and object-safe)
//! lets the driver run unchanged over the in-process device, a serial port, or QEMU's chardev
//! on a TCP or Unix socket.
//!
//! | transport | type | constructor |
//! |---|---|---|
//! | fabric model + soft-core driver inside the host | [`InProcessLink`] | [`InProcessLink::new`] |
//! | any such device in a thread of its own, working ahead of the host | [`Threaded`] | [`Threaded::new`] |
//! | serial port (UART of a real board) | [`SerialLink`] | [`StreamLink::serial`] |
//! | TCP (QEMU `-chardev socket,host=..,port=..`) | [`TcpLink`] | [`StreamLink::tcp`] |
//! | Unix socket (QEMU `-chardev socket,path=..`) | [`UnixLink`] | [`StreamLink::unix`] |
//! | a byte capture played back | [`ReplayLink`] | [`ReplayLink::new`], [`ReplayLink::from_file`] |
//! | any link above, its received bytes damaged by seed | [`FaultLink`] | [`FaultLink::new`] |
//! | the firmware ELF under `qemu-system-riscv32`, or on the SoC simulator `sc-soc-sim` | `MachineDevice` (`stereocal-tools`) | `MachineDevice::start` |
//!
//! A device whose pixels the host provides also has a [`FrameInput`]; a head that grabs its
//! own frames (a board, an emulator started by hand) has only its link, named and timed by
//! [`OwnCameras`].

mod error;
mod fault;
mod frame_input;
mod in_process;
mod own_cameras;
mod protection;
mod recording;
mod replay;
mod serial;
mod stream;
mod tcp;
mod threaded;
#[cfg(unix)]
mod unix;

use std::time::{Duration, Instant};

pub use error::LinkError;
pub use fault::{BadRate, FaultConfig, FaultCounts, FaultLink};
pub use frame_input::FrameInput;
pub use in_process::InProcessLink;
pub use own_cameras::OwnCameras;
pub use protection::LinkProtection;
pub use recording::Recording;
pub use replay::ReplayLink;
pub use serial::SerialLink;
pub use stream::{StreamLink, TimedStream};
pub use tcp::TcpLink;
pub use threaded::Threaded;
#[cfg(unix)]
pub use unix::UnixLink;

/// A bidirectional byte pipe to the device.
///
/// Object-safe: the driver is generic over `L: Link`, and `Box<dyn Link>` is a `Link`, so a
/// transport chosen at run time costs one virtual call per receive.
pub trait Link: Send {
    /// Sends all of `bytes` to the device.
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError>;

    /// Waits until at least one byte is available or `deadline` passes; copies up to
    /// `buf.len()` bytes into `buf` and returns how many (never 0).
    ///
    /// Passing the deadline is [`LinkError::Timeout`]; a peer that closed the link is
    /// [`LinkError::Closed`].
    fn recv(&mut self, buf: &mut [u8], deadline: Instant) -> Result<usize, LinkError>;

    /// How long the host waits for one answer or one frame pair over this link.
    fn answer_timeout(&self) -> Duration {
        DEFAULT_ANSWER_TIMEOUT
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

/// The answer timeout of a link that does not state its own: a device answers a request
/// within microseconds and sends a pair's packets within a frame time, so seconds of silence
/// mean it stopped, whatever its frame rate.
pub const DEFAULT_ANSWER_TIMEOUT: Duration = Duration::from_secs(5);

impl<L: Link + ?Sized> Link for Box<L> {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        (**self).send(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], deadline: Instant) -> Result<usize, LinkError> {
        (**self).recv(buf, deadline)
    }

    fn answer_timeout(&self) -> Duration {
        (**self).answer_timeout()
    }

    fn take_sent(&mut self, out: &mut Vec<u8>) -> Result<(), LinkError> {
        (**self).take_sent(out)
    }
}

impl<L: Link + ?Sized> Link for &mut L {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        (**self).send(bytes)
    }

    fn recv(&mut self, buf: &mut [u8], deadline: Instant) -> Result<usize, LinkError> {
        (**self).recv(buf, deadline)
    }

    fn answer_timeout(&self) -> Duration {
        (**self).answer_timeout()
    }

    fn take_sent(&mut self, out: &mut Vec<u8>) -> Result<(), LinkError> {
        (**self).take_sent(out)
    }
}
