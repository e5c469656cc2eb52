//! Register map and stream ports of the stereocal fabric, and the register access both sides
//! of the bus use.
//!
//! - [`regs`] is generated from `hdl-interface/regmap.toml` by `cargo regen`: offsets, field
//!   positions, reset values, enums, parameters and stream-port layouts.
//! - [`RegisterBus`] is how a driver talks to the fabric; [`Mmio`] implements it on the
//!   soft-core, [`RegisterBank`] in memory for the fabric model and for tests.
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
mod register;
// Generated; rustfmt would only fight the generator.
#[rustfmt::skip]
pub mod regs;

pub use access::Access;
pub use bank::RegisterBank;
pub use bitrange::BitRange;
pub use bus::RegisterBus;
pub use config::FabricConfig;
pub use error::Error;
pub use field::Field;
pub use mmio::Mmio;
pub use register::{register_at, Register};
