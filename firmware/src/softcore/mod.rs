//! What the soft-core needs around the driver: the UART, the QEMU finisher, the frame-grabber
//! input region, and on the bare-metal target the link writer, the defmt logger and the panic
//! handler.
//!
//! `uart`, `finisher` and `frame_input` build everywhere (the host writes frame-input files
//! with [`frame_input::InputHeader::emit`] and tests the parser); the rest only exists on
//! `target_os = "none"`, where it is linked into the ELF.

pub mod finisher;
pub mod frame_input;
pub mod uart;

#[cfg(target_os = "none")]
pub mod link;
#[cfg(target_os = "none")]
mod logger;
#[cfg(target_os = "none")]
pub mod panic;

#[cfg(target_os = "none")]
pub use logger::dropped_logs;
