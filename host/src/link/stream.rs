//! A [`Link`] over any blocking byte stream with a read timeout: sockets and serial ports.

use std::io::{self, ErrorKind, Read, Write};
use std::time::{Duration, Instant};

use super::{Link, LinkError};

/// Shortest read timeout handed to the OS: sockets refuse a zero timeout, and a deadline
/// that is less than this away is as good as passed.
const MIN_WAIT: Duration = Duration::from_millis(1);

/// A blocking byte stream whose reads can be bounded in time.
pub trait TimedStream: Read + Write + Send {
    /// Makes the next reads return (with `WouldBlock` or `TimedOut`) after `timeout`.
    fn set_receive_timeout(&mut self, timeout: Duration) -> io::Result<()>;
}

/// A link over a stream: TCP, Unix socket or serial port.
#[derive(Debug)]
pub struct StreamLink<S> {
    stream: S,
    name: String,
}

impl<S: TimedStream> StreamLink<S> {
    /// Wraps an open stream; `name` appears in every error (e.g. `"tcp 127.0.0.1:4444"`).
    pub fn from_stream(stream: S, name: impl Into<String>) -> Self {
        Self {
            stream,
            name: name.into(),
        }
    }

    /// The name given at construction.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The stream, e.g. to shut a socket down.
    pub fn stream_mut(&mut self) -> &mut S {
        &mut self.stream
    }

    fn io_error(&self, source: io::Error) -> LinkError {
        LinkError::Io {
            link: self.name.clone(),
            source,
        }
    }
}

impl<S: TimedStream> Link for StreamLink<S> {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.stream
            .write_all(bytes)
            .and_then(|()| self.stream.flush())
            .map_err(|e| self.io_error(e))
    }

    fn recv(&mut self, buf: &mut [u8], deadline: Instant) -> Result<usize, LinkError> {
        if buf.is_empty() {
            return Ok(0);
        }
        let start = Instant::now();
        loop {
            let now = Instant::now();
            let left = deadline.saturating_duration_since(now);
            if left.is_zero() {
                return Err(LinkError::Timeout {
                    link: self.name.clone(),
                    waited: now - start,
                });
            }
            self.stream
                .set_receive_timeout(left.max(MIN_WAIT))
                .map_err(|e| self.io_error(e))?;
            match self.stream.read(buf) {
                Ok(0) => {
                    return Err(LinkError::Closed {
                        link: self.name.clone(),
                    })
                }
                Ok(n) => return Ok(n),
                Err(e)
                    if matches!(
                        e.kind(),
                        ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
                    ) => {}
                Err(e) => return Err(self.io_error(e)),
            }
        }
    }
}
