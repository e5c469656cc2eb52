//! Serial port: the soft-core's UART on a real board (8N1, no flow control).

use std::io;
use std::time::Duration;

use serialport::SerialPort;

use super::{LinkError, StreamLink, TimedStream};

/// A link over a serial port.
pub type SerialLink = StreamLink<Box<dyn SerialPort>>;

impl TimedStream for Box<dyn SerialPort> {
    fn set_receive_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        self.set_timeout(timeout).map_err(io::Error::from)
    }
}

impl StreamLink<Box<dyn SerialPort>> {
    /// Opens `device` (e.g. `/dev/ttyUSB0`, `COM3`) at `baud` bits per second, 8N1.
    pub fn serial(device: &str, baud: u32) -> Result<Self, LinkError> {
        let name = format!("serial {device}");
        match serialport::new(device, baud).open() {
            Ok(port) => Ok(Self::from_stream(port, name)),
            Err(e) => Err(LinkError::Open {
                link: name,
                source: io::Error::from(e),
            }),
        }
    }
}
