//! Register map and stream ports of the fabric, and what is generated from them.
#![no_std]
