//! TCP: QEMU's `-chardev socket,id=..,host=..,port=..,server=on` or a board's network bridge.

use std::io;
use std::net::{TcpStream, ToSocketAddrs};
use std::time::Duration;

use super::{LinkError, StreamLink, TimedStream};

/// A link over a TCP connection.
pub type TcpLink = StreamLink<TcpStream>;

impl TimedStream for TcpStream {
    fn set_receive_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        self.set_read_timeout(Some(timeout))
    }
}

impl StreamLink<TcpStream> {
    /// Connects to `addr` (e.g. `"127.0.0.1:4444"`). Nagle is switched off: register
    /// packets are a few bytes each and the driver waits for every answer.
    pub fn tcp(addr: &str) -> Result<Self, LinkError> {
        let name = format!("tcp {addr}");
        let open = |source| LinkError::Open {
            link: name.clone(),
            source,
        };
        let addrs = addr.to_socket_addrs().map_err(open)?;
        let stream = TcpStream::connect(&addrs.collect::<Vec<_>>()[..]).map_err(open)?;
        stream.set_nodelay(true).map_err(open)?;
        Ok(Self::from_stream(stream, name))
    }
}
