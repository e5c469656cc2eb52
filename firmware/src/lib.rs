//! stereocal firmware crate: the register-level model of the FPGA front end ("fabric") and,
//! later, the soft-core driver that drains it.
//!
//! `no_std`, no allocation: every buffer is a fixed array sized by const generics, so the same
//! code runs on the `riscv32imc` soft-core and on the host.
#![no_std]

pub mod driver;
pub mod fabric;
pub mod softcore;
