//! The `sifive_test` finisher of QEMU's `virt` machine: the way the firmware ends a simulation.
//!
//! A 32-bit write of `0x5555` powers the machine off with exit status 0; `(code << 16) | 0x3333`
//! makes QEMU exit with status `code`. The host runner tells a clean run from a failed one by
//! that status, so every exit path of the firmware goes through [`exit`].

use core::ptr;

use crate::softcore::uart::{Ns16550, VIRT_UART0};

/// Base address of the `sifive_test` device on QEMU's `virt` machine.
pub const VIRT_TEST: usize = 0x0010_0000;

const FINISHER_PASS: u32 = 0x5555;
const FINISHER_FAIL: u32 = 0x3333;

/// Why the firmware stops; the value is QEMU's exit status.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u16)]
pub enum ExitCode {
    /// Every frame was processed and the link saw FrameEnd for each.
    Success = 0,
    /// The program panicked (a bug): a report went out on the link first.
    Panic = 101,
    /// The frame-grabber input region did not hold a valid header or enough pixels.
    BadInput = 2,
    /// At least one frame could not be processed (an `ErrorReport` on the link says why).
    FrameFailed = 3,
    /// The core took an exception (a bug, or a bus error on the board): a log said which.
    Trap = 4,
}

impl ExitCode {
    /// The word the finisher register expects for this code.
    pub const fn finisher_word(self) -> u32 {
        match self {
            Self::Success => FINISHER_PASS,
            code => ((code as u32) << 16) | FINISHER_FAIL,
        }
    }
}

/// Ends the simulation with `code`, once the link's last bytes have left the UART (the
/// finisher stops the machine at once, and bytes still in the transmitter would be lost).
///
/// # Safety
/// [`VIRT_TEST`] must be the `sifive_test` device (true on QEMU `virt`); on other machines the
/// write lands wherever that address maps.
pub unsafe fn exit(code: ExitCode) -> ! {
    // SAFETY: the finisher's machine, QEMU `virt`, has its NS16550 at VIRT_UART0.
    unsafe { Ns16550::new(VIRT_UART0) }.flush();
    // SAFETY: the caller guarantees the device is there; the write is its whole protocol.
    unsafe { ptr::write_volatile(VIRT_TEST as *mut u32, code.finisher_word()) };
    // QEMU stops at the write; real silicon without the device parks here.
    loop {
        core::hint::spin_loop();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finisher_words_follow_qemu_protocol() {
        assert_eq!(ExitCode::Success.finisher_word(), 0x5555);
        assert_eq!(ExitCode::Panic.finisher_word(), (101 << 16) | 0x3333);
        assert_eq!(ExitCode::BadInput.finisher_word(), 0x0002_3333);
    }
}
