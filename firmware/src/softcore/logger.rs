//! The defmt global logger: each log call becomes one wire `Log` packet on the UART.
//!
//! defmt calls `acquire`, then `write` any number of times, then `release` for one log frame.
//! The frame is collected in a buffer of [`MAX_LOG_LEN`] bytes and sent as one packet in
//! `release`, through [`LINK`] so it takes the control source's next sequence number. The
//! whole sequence runs inside a critical section (interrupts off on the single hart), which is
//! what makes the unsynchronised state below sound.
//!
//! A frame longer than [`MAX_LOG_LEN`] cannot be decoded once cut, so it is not sent; it is
//! counted in [`dropped_logs`]. So is a log call made while the firmware holds [`LINK`] (the
//! driver never logs, so this only happens on a programming error).

use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicU32, Ordering};

use critical_section::{CriticalSection, RestoreState};
use stereocal_wire::{LogRepr, PacketRepr, DELIMITER, MAX_LOG_LEN};

use crate::softcore::finisher::{self, ExitCode};
use crate::softcore::link::{Uart0, LINK};
use crate::softcore::panic;

/// Log frames that were not sent (too long, or the link was busy).
static DROPPED: AtomicU32 = AtomicU32::new(0);

/// Log frames the logger could not send since boot.
pub fn dropped_logs() -> u32 {
    DROPPED.load(Ordering::Relaxed)
}

fn count_dropped() {
    // No atomic read-modify-write on riscv32imc; the caller is inside the critical section.
    DROPPED.store(
        DROPPED.load(Ordering::Relaxed).wrapping_add(1),
        Ordering::Relaxed,
    );
}

struct State {
    taken: bool,
    restore: RestoreState,
    encoder: defmt::Encoder,
    frame: [u8; MAX_LOG_LEN],
    len: usize,
    too_long: bool,
}

impl State {
    fn append(frame: &mut [u8; MAX_LOG_LEN], len: &mut usize, too_long: &mut bool, bytes: &[u8]) {
        match frame.get_mut(*len..*len + bytes.len()) {
            Some(dest) => {
                dest.copy_from_slice(bytes);
                *len += bytes.len();
            }
            None => *too_long = true,
        }
    }
}

struct Shared(UnsafeCell<State>);

// SAFETY: `State` is only touched between `acquire` and `release`, inside the critical section
// `acquire` takes, on the only hart.
unsafe impl Sync for Shared {}

static STATE: Shared = Shared(UnsafeCell::new(State {
    taken: false,
    restore: RestoreState::invalid(),
    encoder: defmt::Encoder::new(),
    frame: [0; MAX_LOG_LEN],
    len: 0,
    too_long: false,
}));

#[defmt::global_logger]
struct UartLogger;

// SAFETY: `acquire` takes a critical section and refuses re-entry, as the trait requires.
unsafe impl defmt::Logger for UartLogger {
    fn acquire() {
        // SAFETY: released in `release` with the state saved here.
        let restore = unsafe { critical_section::acquire() };
        // SAFETY: interrupts are off on the only hart: nothing else holds a reference.
        let state = unsafe { &mut *STATE.0.get() };
        if state.taken && !panic::is_panicking() {
            // A log call inside a log call is a firmware bug; defmt requires that `acquire`
            // not return then. Stop with the bug status (as the panic handler would, without
            // linking a panic path): end the interrupted frame with a lone delimiter first.
            Uart0::device().write_byte(DELIMITER);
            // SAFETY: the firmware only runs on QEMU `virt`, which has the finisher.
            unsafe { finisher::exit(ExitCode::Panic) }
        }
        // While panicking, a frame the panic interrupted is abandoned.
        state.taken = true;
        state.restore = restore;
        state.len = 0;
        state.too_long = false;
        let State {
            encoder,
            frame,
            len,
            too_long,
            ..
        } = state;
        encoder.start_frame(|bytes| State::append(frame, len, too_long, bytes));
    }

    unsafe fn flush() {
        // Every packet is written to the UART synchronously in `release`.
    }

    unsafe fn release() {
        // SAFETY: defmt calls `release` only after `acquire`, inside its critical section.
        let state = unsafe { &mut *STATE.0.get() };
        let State {
            encoder,
            frame,
            len,
            too_long,
            ..
        } = &mut *state;
        encoder.end_frame(|bytes| State::append(frame, len, too_long, bytes));
        if state.too_long {
            count_dropped();
        } else {
            // SAFETY: we are inside the critical section taken in `acquire`.
            let cs = unsafe { CriticalSection::new() };
            match state.frame.get(..state.len) {
                Some(frame) => send(cs, frame),
                // `append` keeps `len` within the frame; counted like a too-long frame.
                None => count_dropped(),
            }
        }
        state.taken = false;
        // SAFETY: `restore` is what `acquire` got from the matching `critical_section::acquire`.
        unsafe { critical_section::release(state.restore) };
    }

    unsafe fn write(bytes: &[u8]) {
        // SAFETY: as in `release`.
        let state = unsafe { &mut *STATE.0.get() };
        let State {
            encoder,
            frame,
            len,
            too_long,
            ..
        } = state;
        encoder.write(bytes, |out| State::append(frame, len, too_long, out));
    }
}

fn send(cs: CriticalSection<'_>, frame: &[u8]) {
    let packet = PacketRepr::Log(LogRepr { frame });
    let sent = match LINK.borrow(cs).try_borrow_mut() {
        Ok(mut link) => link.send(&packet).is_ok(),
        Err(_) if panic::is_panicking() => {
            // SAFETY: the code that holds the borrow panicked and never runs again (panics
            // abort on this target), so this is the only live access to the writer.
            let link = unsafe { &mut *LINK.borrow(cs).as_ptr() };
            link.send(&packet).is_ok()
        }
        Err(_) => false,
    };
    if !sent {
        count_dropped();
    }
}
