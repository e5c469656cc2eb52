//! stereocal firmware crate: the register-level model of the FPGA front end ("fabric") with
//! its fast path and its stream engine (which packetizes the fabric's FIFOs onto the link),
//! the wire framing both ends of the device use, the soft-core driver that configures and
//! runs the fabric through its registers, and the soft-core's own peripherals (UART, logger,
//! panic report, exit).
//!
//! `no_std`, no allocation: every buffer is a fixed array sized by const generics, so the same
//! code runs on the `riscv32imc` soft-core and on the host.
#![no_std]

pub mod driver;
pub mod fabric;
pub mod framing;
pub mod softcore;
