//! What can go wrong on a link.

use std::io;
use std::time::Duration;

/// A link failure. Every variant names the link (`"tcp 127.0.0.1:4444"`, `"serial
/// /dev/ttyUSB0"`, `"in-process"`) so a message says which transport to look at.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LinkError {
    /// The receive deadline passed before a byte arrived.
    #[error("{link}: receive deadline passed after {waited:?} without a byte")]
    Timeout {
        /// The link.
        link: String,
        /// How long the receive call waited.
        waited: Duration,
    },
    /// The peer closed the link (end of stream).
    #[error("{link}: closed by the device")]
    Closed {
        /// The link.
        link: String,
    },
    /// The link could not be opened.
    #[error("{link}: cannot open: {source}")]
    Open {
        /// The link.
        link: String,
        /// The operating system's or the serial library's reason.
        #[source]
        source: io::Error,
    },
    /// A read or write failed.
    #[error("{link}: {source}")]
    Io {
        /// The link.
        link: String,
        /// The operating system's reason.
        #[source]
        source: io::Error,
    },
    /// The in-process device refused a frame or a packet.
    #[error("in-process device: {0}")]
    Device(String),
}
