//! Little-endian integer fields at fixed offsets.
//!
//! Every multi-byte field on the wire is little-endian (the byte order of both the RV32
//! soft-core and the usual host). The readers index the slice, so they panic on a short
//! buffer; the packet views only call them on ranges that `check_len` has proven present.

use core::ops::Range;

/// A fixed byte range of a field inside a payload.
pub(crate) type Field = Range<usize>;

pub(crate) fn read_u16(bytes: &[u8], field: Field) -> u16 {
    let b = &bytes[field];
    u16::from_le_bytes([b[0], b[1]])
}

pub(crate) fn read_i16(bytes: &[u8], field: Field) -> i16 {
    let b = &bytes[field];
    i16::from_le_bytes([b[0], b[1]])
}

pub(crate) fn read_u32(bytes: &[u8], field: Field) -> u32 {
    let b = &bytes[field];
    u32::from_le_bytes([b[0], b[1], b[2], b[3]])
}

pub(crate) fn read_u64(bytes: &[u8], field: Field) -> u64 {
    let b = &bytes[field];
    u64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]])
}

pub(crate) fn write_u16(bytes: &mut [u8], field: Field, value: u16) {
    bytes[field].copy_from_slice(&value.to_le_bytes());
}

pub(crate) fn write_i16(bytes: &mut [u8], field: Field, value: i16) {
    bytes[field].copy_from_slice(&value.to_le_bytes());
}

pub(crate) fn write_u32(bytes: &mut [u8], field: Field, value: u32) {
    bytes[field].copy_from_slice(&value.to_le_bytes());
}

pub(crate) fn write_u64(bytes: &mut [u8], field: Field, value: u64) {
    bytes[field].copy_from_slice(&value.to_le_bytes());
}
