//! Register-level model of the fabric and the soft-core driver.
#![no_std]
