//! stereocal firmware crate: the register-level model of the FPGA front end ("fabric") with
//! its fast path, the soft-core driver that configures it and packetizes its FIFOs, and the
//! soft-core's own peripherals (UART, logger, panic report, exit).
//!
//! `no_std`, no allocation: every buffer is a fixed array sized by const generics, so the same
//! code runs on the `riscv32imc` soft-core and on the host.
#![no_std]

pub mod driver;
pub mod fabric;
pub mod softcore;
