//! Unix domain socket: QEMU's `-chardev socket,id=..,path=..,server=on`.

use std::io;
use std::os::unix::net::UnixStream;
use std::path::Path;
use std::time::Duration;

use super::{LinkError, StreamLink, TimedStream};

/// A link over a Unix stream socket.
pub type UnixLink = StreamLink<UnixStream>;

impl TimedStream for UnixStream {
    fn set_receive_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        self.set_read_timeout(Some(timeout))
    }
}

impl StreamLink<UnixStream> {
    /// Connects to the socket at `path`.
    pub fn unix(path: impl AsRef<Path>) -> Result<Self, LinkError> {
        let path = path.as_ref();
        let name = format!("unix {}", path.display());
        match UnixStream::connect(path) {
            Ok(stream) => Ok(Self::from_stream(stream, name)),
            Err(source) => Err(LinkError::Open { link: name, source }),
        }
    }
}
