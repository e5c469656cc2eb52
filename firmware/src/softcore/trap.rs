//! The exception handler: report the trap on the link, then stop the machine.
//!
//! A trap (illegal instruction, access fault, misaligned access, an `ecall`) is a firmware
//! bug or a board fault: a bus error from a peripheral that is not there. Without a handler
//! riscv-rt parks the hart, and the host sees nothing but silence until its timeout; this one
//! ends whatever frame the trap interrupted with a lone delimiter, logs what trapped and where
//! (`mcause`, `mepc`, `mtval` and the return address) as a defmt error, and exits through the
//! finisher with [`ExitCode::Trap`], so the host names the fault at once. A trap inside the
//! handler exits without the log.

use core::sync::atomic::{AtomicBool, Ordering};

use stereocal_wire::DELIMITER;

use crate::softcore::finisher::{self, ExitCode};
use crate::softcore::link::Uart0;

static TRAPPED: AtomicBool = AtomicBool::new(false);

#[export_name = "ExceptionHandler"]
fn exception_handler(frame: &riscv_rt::TrapFrame) -> ! {
    // Load and store, not a swap: the soft-core's RV32IMC has no atomic instructions, and a
    // trap handler runs with nothing else on the hart.
    if !TRAPPED.load(Ordering::Relaxed) {
        TRAPPED.store(true, Ordering::Relaxed);
        Uart0::device().write_byte(DELIMITER);
        defmt::error!(
            "trap: mcause {=u32:#x} mepc {=u32:#x} mtval {=u32:#x} ra {=u32:#x}",
            riscv::register::mcause::read().bits() as u32,
            riscv::register::mepc::read() as u32,
            riscv::register::mtval::read() as u32,
            frame.ra as u32
        );
    }
    // SAFETY: the firmware only runs on machines with the `virt` finisher (QEMU, the SoC).
    unsafe { finisher::exit(ExitCode::Trap) }
}
