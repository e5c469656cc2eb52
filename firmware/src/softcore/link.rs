//! The soft-core's end of the link: UART0 as a [`ByteSink`] and the one [`PacketWriter`] that
//! numbers every packet the firmware sends.
//!
//! The driver's packets, the defmt log packets and the panic report all go through [`LINK`],
//! so they share one sequence counter and the host's gap detection sees a single stream.

use core::cell::RefCell;

use critical_section::Mutex;

use crate::driver::{ByteSink, PacketWriter};
use crate::softcore::uart::{Ns16550, VIRT_UART0};

/// UART0 of the QEMU `virt` machine as a byte sink. Zero-sized: every handle is the same
/// device, so a handle can live in a `static`.
pub struct Uart0;

impl Uart0 {
    /// The register-level driver of the device.
    pub fn device() -> Ns16550 {
        // SAFETY: VIRT_UART0 is the NS16550 of the `virt` machine; the firmware runs on one
        // hart without interrupt handlers, so accesses never interleave.
        unsafe { Ns16550::new(VIRT_UART0) }
    }
}

impl ByteSink for Uart0 {
    fn write(&mut self, bytes: &[u8]) {
        Self::device().write_all(bytes);
    }
}

/// The writer every packet of the firmware goes through.
pub static LINK: Mutex<RefCell<PacketWriter<Uart0>>> =
    Mutex::new(RefCell::new(PacketWriter::new(Uart0)));
