//! Register map and stream ports of the stereocal fabric, and the register access both sides
//! of the bus use.
//!
//! - [`regs`] is generated from `hdl-interface/regmap.toml` by `cargo regen`: offsets, field
//!   positions, reset values, enums, parameters and stream-port layouts.
//! - [`Registers`] ([`regs_api`]), also generated, is the typed register interface: one
//!   getter/setter per field, following the field's access type, range and enum. It is
//!   implemented for every [`RegisterBus`].
//! - [`RegisterBus`] (hand-written) is the transport under it, 32-bit reads and writes at
//!   byte offsets; [`Mmio`] implements it on the soft-core, [`RegisterBank`] in memory for the
//!   fabric model and for tests. [`RegisterBus::read_burst`] drains a FIFO in one call.
//! - [`PixelIn`] is the PIXEL_IN stream port, for a program that feeds the frames itself.
//! - [`FabricConfig`] is the typed, validated configuration the driver writes and the model
//!   reads.
#![no_std]

mod access;
mod bank;
mod bitrange;
mod bus;
mod config;
mod error;
mod field;
mod mmio;
mod pixel_in;
mod register;
// Generated; rustfmt would only fight the generator.
#[rustfmt::skip]
pub mod regs;
#[rustfmt::skip]
pub mod regs_api;

pub use access::Access;
pub use bank::RegisterBank;
pub use bitrange::BitRange;
pub use bus::RegisterBus;
pub use config::FabricConfig;
pub use error::Error;
pub use field::Field;
pub use mmio::Mmio;
pub use pixel_in::PixelIn;
pub use register::{register_at, Register};
pub use regs_api::Registers;
