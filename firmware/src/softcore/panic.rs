//! The panic handler: report on the link, then stop the machine with a failure status.
//!
//! A panic is a firmware bug (data from the link or the input region is checked and answered
//! with errors, never a panic). The handler ends whatever frame the panic interrupted with a
//! lone delimiter, logs the panic message and location as a defmt error (a `Log` packet with
//! the control source's next sequence number), and exits QEMU through the `sifive_test` finisher with
//! [`ExitCode::Panic`]. A panic inside the handler exits at once.

use core::panic::PanicInfo;
use core::sync::atomic::{AtomicBool, Ordering};

use stereocal_wire::DELIMITER;

use crate::softcore::finisher::{self, ExitCode};
use crate::softcore::link::Uart0;

static PANICKING: AtomicBool = AtomicBool::new(false);

/// Whether the firmware is in its panic handler.
pub fn is_panicking() -> bool {
    PANICKING.load(Ordering::Relaxed)
}

#[panic_handler]
fn panic(info: &PanicInfo<'_>) -> ! {
    if !is_panicking() {
        PANICKING.store(true, Ordering::Relaxed);
        Uart0::device().write_byte(DELIMITER);
        defmt::error!("panic: {}", defmt::Display2Format(info));
    }
    // SAFETY: the firmware only runs on QEMU `virt`, which has the finisher.
    unsafe { finisher::exit(ExitCode::Panic) }
}
