//! The soft-core's end of the link: UART0 as a [`ByteSink`] and the one [`PacketWriter`] every
//! packet the firmware sends goes through.
//!
//! The driver's packets, the defmt log packets and the panic report all go through [`LINK`]:
//! the soft-core's own packets (answers, errors, logs, the panic report) as its control
//! source, numbered by the writer; each camera channel's as that channel's source, numbered
//! by the channel.

use core::cell::RefCell;

use critical_section::Mutex;

use crate::framing::{ByteSink, PacketWriter};
use crate::softcore::instructions::instret;
use crate::softcore::uart::{Ns16550, VIRT_UART0};

/// UART0 of the QEMU `virt` machine as a byte sink.
///
/// It also counts the instructions spent waiting for the transmitter: that wait depends on
/// how fast the other end reads (under QEMU, the host draining the socket), so it is kept
/// apart from the driver's own work, which is the same on every run.
pub struct Uart0 {
    waited: u64,
}

impl Uart0 {
    /// The sink; no instructions waited yet.
    pub const fn new() -> Self {
        Self { waited: 0 }
    }

    /// The register-level driver of the device.
    pub fn device() -> Ns16550 {
        // SAFETY: VIRT_UART0 is the NS16550 of the `virt` machine; the firmware runs on one
        // hart without interrupt handlers, so accesses never interleave.
        unsafe { Ns16550::new(VIRT_UART0) }
    }

    /// Instructions spent waiting for the transmitter since the last call.
    pub fn take_waited(&mut self) -> u64 {
        core::mem::take(&mut self.waited)
    }
}

impl Default for Uart0 {
    fn default() -> Self {
        Self::new()
    }
}

impl ByteSink for Uart0 {
    fn write(&mut self, bytes: &[u8]) {
        let mut uart = Self::device();
        for &byte in bytes {
            if !uart.ready_to_send() {
                let start = instret();
                while !uart.ready_to_send() {
                    core::hint::spin_loop();
                }
                self.waited = self.waited.wrapping_add(instret().wrapping_sub(start));
            }
            uart.write_byte(byte);
        }
    }
}

/// The writer every packet of the firmware goes through.
pub static LINK: Mutex<RefCell<PacketWriter<Uart0>>> =
    Mutex::new(RefCell::new(PacketWriter::new(Uart0::new())));
