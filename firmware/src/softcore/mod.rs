//! What the soft-core needs around the driver: the UART, the QEMU finisher, the frame-grabber
//! input region, and on the bare-metal target the link writer, the defmt logger and the panic
//! handler.
//!
//! `uart`, `finisher`, `frame_input`, `instructions` and `stack` build everywhere (the host
//! writes frame-input files with [`frame_input::InputHeader::emit`] and reads instruction
//! and stack reports with [`instructions::InstructionReport::parse`] and
//! [`stack::StackReport::parse`]); the rest only exists on
//! `target_os = "none"`, where it is linked into the ELF.
//!
//! # Running the ELF under QEMU
//! ```text
//! cargo build --release -p stereocal-firmware --target riscv32imc-unknown-none-elf
//! qemu-system-riscv32 -machine virt -bios none \
//!     -kernel target/riscv32imc-unknown-none-elf/release/stereocal-firmware \
//!     -display none -monitor none \
//!     -chardev socket,id=link,path=/tmp/stereocal.sock,server=on,wait=on -serial chardev:link \
//!     -device loader,file=frames.bin,addr=0x81000000
//! ```
//! The UART is the link, raw bytes both ways: use a socket, `stdio` (with `signal=off`) or a
//! `file:` chardev, never `-nographic` (its monitor multiplexer eats `0x01` bytes).
//! `frames.bin` is the frame-grabber input ([`frame_input`]). The firmware answers `Hello` /
//! `RegisterRead` / `RegisterWrite` until the host writes `CONTROL.ENABLE = 1`; with
//! [`frame_input::FLAG_AUTOSTART`] (no host to ask) it announces itself with a `Hello` and
//! starts at once (a host that asked first gets exactly one `Hello`, as from the in-process
//! device, so the two byte streams stay comparable). Then it sends every frame's packets and
//! exits: status 0 when every frame ran, 2 for a bad input region (after a `Hello` and a log
//! saying why), 3 when a frame failed (an `ErrorReport` said why), 4 on a trap and 101 on a panic (a defmt
//! `Log` packet carries what trapped or the panic message). The host may send more packets between frames; they are read
//! when the current frame is done (QEMU holds them back meanwhile; a real UART would need the
//! host to wait for `FrameEnd`).
//!
//! Instructions per frame: set [`frame_input::FLAG_COUNT_INSTRUCTIONS`] and run with
//! `-icount shift=0`; each image then logs its `minstret` deltas ([`instructions`]), and
//! after the last frame the main loop's stack high-water mark ([`stack`]).
//! `stereocal hil --count-instructions` does both.

pub mod finisher;
pub mod frame_input;
pub mod instructions;
pub mod soc;
pub mod stack;
pub mod uart;

#[cfg(target_os = "none")]
pub mod link;
#[cfg(target_os = "none")]
mod logger;
#[cfg(target_os = "none")]
pub mod panic;
#[cfg(target_os = "none")]
pub mod trap;
#[cfg(target_os = "none")]
pub mod wired;

#[cfg(target_os = "none")]
pub use logger::dropped_logs;
