//! TCP: QEMU's `-chardev socket,id=..,host=..,port=..,server=on` or a board's network bridge.

use std::io;
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

use super::{LinkError, StreamLink, TimedStream};

/// How long one connection attempt may take: a head that is off or unroutable would otherwise
/// hold the host for the system's own SYN retries (about two minutes on Linux).
const CONNECT_TIMEOUT: Duration = Duration::from_secs(5);

/// A link over a TCP connection.
pub type TcpLink = StreamLink<TcpStream>;

impl TimedStream for TcpStream {
    fn set_receive_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        self.set_read_timeout(Some(timeout))
    }
}

impl StreamLink<TcpStream> {
    /// Connects to `addr` (e.g. `"127.0.0.1:4444"`), trying each address it resolves to for
    /// at most 5 s. Nagle is switched off: register packets are a few bytes
    /// each and the driver waits for every answer.
    pub fn tcp(addr: &str) -> Result<Self, LinkError> {
        let name = format!("tcp {addr}");
        let open = |source| LinkError::Open {
            link: name.clone(),
            source,
        };
        let mut last = io::Error::new(io::ErrorKind::NotFound, "resolves to no address");
        for a in addr.to_socket_addrs().map_err(open)? {
            match TcpStream::connect_timeout(&a, CONNECT_TIMEOUT) {
                Ok(stream) => {
                    stream.set_nodelay(true).map_err(open)?;
                    return Ok(Self::from_stream(stream, name));
                }
                Err(e) => last = e,
            }
        }
        Err(open(last))
    }
}
