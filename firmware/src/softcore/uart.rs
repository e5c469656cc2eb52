//! Polled driver for the NS16550-compatible UART that carries the link.
//!
//! On the QEMU `virt` machine the UART sits at [`VIRT_UART0`]; QEMU's model needs no baud-rate or
//! FIFO setup, and a real 16550 behind the same registers only needs [`Ns16550::init`] for the
//! line format (its divisor latch is the bitstream's default). Everything is polled: the firmware has one job at a time and never enables
//! interrupts, so a busy-wait on the line status register is the simplest correct design.

use core::ptr;

/// Base address of UART0 on QEMU's `virt` machine.
pub const VIRT_UART0: usize = 0x1000_0000;

/// Receive buffer (read) / transmit holding (write) register.
const RBR_THR: usize = 0;
/// Interrupt enable register.
const IER: usize = 1;
/// Line control register.
const LCR: usize = 3;
/// Line status register.
const LSR: usize = 5;

/// LSR: a received byte is waiting in RBR.
const LSR_DATA_READY: u8 = 1 << 0;
/// LSR: the transmit holding register can take a byte.
const LSR_THR_EMPTY: u8 = 1 << 5;
/// LSR: the holding and the shift register are both empty: every byte has left.
const LSR_TX_EMPTY: u8 = 1 << 6;
/// LCR: 8 data bits, no parity, one stop bit.
const LCR_8N1: u8 = 0b0000_0011;

/// One NS16550 UART, addressed through byte-wide registers.
pub struct Ns16550 {
    base: *mut u8,
}

impl Ns16550 {
    /// A handle to the UART whose registers start at `base`.
    ///
    /// # Safety
    /// `base` must be the address of an NS16550 register block that nothing else drives while
    /// this handle is used (the soft-core has a single hart and no interrupt handlers).
    pub const unsafe fn new(base: usize) -> Self {
        Self {
            base: base as *mut u8,
        }
    }

    fn read_reg(&self, offset: usize) -> u8 {
        // SAFETY: `new`'s contract makes `base + offset` (offset < 8) a device register.
        unsafe { ptr::read_volatile(self.base.add(offset)) }
    }

    fn write_reg(&mut self, offset: usize, value: u8) {
        // SAFETY: as in `read_reg`.
        unsafe { ptr::write_volatile(self.base.add(offset), value) }
    }

    /// Sets 8N1 framing and masks every UART interrupt.
    ///
    /// The FIFO control register is left alone: changing its enable bit empties the receive
    /// FIFO, which would lose bytes the host sent before the firmware booted.
    pub fn init(&mut self) {
        self.write_reg(IER, 0);
        self.write_reg(LCR, LCR_8N1);
    }

    /// Whether the transmitter can take a byte now.
    pub fn ready_to_send(&self) -> bool {
        self.read_reg(LSR) & LSR_THR_EMPTY != 0
    }

    /// Sends one byte, waiting until the transmitter can take it.
    pub fn write_byte(&mut self, byte: u8) {
        while !self.ready_to_send() {
            core::hint::spin_loop();
        }
        self.write_reg(RBR_THR, byte);
    }

    /// Waits until every byte written has left the transmitter. THR empty only means the
    /// next byte may be written while the last one is still shifting out (under QEMU, still
    /// waiting for the host to read the socket); a program that stops must wait for this.
    pub fn flush(&mut self) {
        while self.read_reg(LSR) & LSR_TX_EMPTY == 0 {
            core::hint::spin_loop();
        }
    }

    /// Sends every byte of `bytes` in order.
    pub fn write_all(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            self.write_byte(byte);
        }
    }

    /// The next received byte, if one is waiting.
    pub fn try_read_byte(&mut self) -> Option<u8> {
        (self.read_reg(LSR) & LSR_DATA_READY != 0).then(|| self.read_reg(RBR_THR))
    }

    /// The next received byte, waiting for it.
    pub fn read_byte(&mut self) -> u8 {
        loop {
            if let Some(byte) = self.try_read_byte() {
                return byte;
            }
            core::hint::spin_loop();
        }
    }
}
