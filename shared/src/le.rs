//! Little-endian integer fields at fixed offsets, and sub-slices that cannot panic.
//!
//! Every multi-byte field on the wire is little-endian (the byte order of both the RV32
//! soft-core and the usual host). The packet views only call these on ranges that
//! `check_len` has proven present; should a range ever be missing anyway, a read gives 0, a
//! write does nothing and a sub-slice is empty, instead of a panic, so the firmware links no
//! panicking path through the wire crate (tests/tests/firmware_panic_free.rs).

use core::ops::Range;
use core::slice::SliceIndex;

/// A fixed byte range of a field inside a payload.
pub(crate) type Field = Range<usize>;

/// The `N` bytes of `field`, if it is `N` bytes long and inside `bytes`.
fn array<const N: usize>(bytes: &[u8], field: Field) -> Option<[u8; N]> {
    bytes.get(field)?.try_into().ok()
}

/// Writes `value` into `field` if it is `N` bytes long and inside `bytes`.
fn put<const N: usize>(bytes: &mut [u8], field: Field, value: [u8; N]) {
    if let Some(out) = bytes
        .get_mut(field)
        .and_then(|b| <&mut [u8; N]>::try_from(b).ok())
    {
        *out = value;
    }
}

pub(crate) fn read_u16(bytes: &[u8], field: Field) -> u16 {
    array(bytes, field).map_or(0, u16::from_le_bytes)
}

pub(crate) fn read_i16(bytes: &[u8], field: Field) -> i16 {
    array(bytes, field).map_or(0, i16::from_le_bytes)
}

pub(crate) fn read_u32(bytes: &[u8], field: Field) -> u32 {
    array(bytes, field).map_or(0, u32::from_le_bytes)
}

pub(crate) fn read_i32(bytes: &[u8], field: Field) -> i32 {
    array(bytes, field).map_or(0, i32::from_le_bytes)
}

pub(crate) fn read_u64(bytes: &[u8], field: Field) -> u64 {
    array(bytes, field).map_or(0, u64::from_le_bytes)
}

pub(crate) fn write_u16(bytes: &mut [u8], field: Field, value: u16) {
    put(bytes, field, value.to_le_bytes());
}

pub(crate) fn write_i16(bytes: &mut [u8], field: Field, value: i16) {
    put(bytes, field, value.to_le_bytes());
}

pub(crate) fn write_u32(bytes: &mut [u8], field: Field, value: u32) {
    put(bytes, field, value.to_le_bytes());
}

pub(crate) fn write_i32(bytes: &mut [u8], field: Field, value: i32) {
    put(bytes, field, value.to_le_bytes());
}

pub(crate) fn write_u64(bytes: &mut [u8], field: Field, value: u64) {
    put(bytes, field, value.to_le_bytes());
}

/// `&bytes[range]`, or an empty slice when `range` is not inside `bytes`.
pub(crate) fn sub<R: SliceIndex<[u8], Output = [u8]>>(bytes: &[u8], range: R) -> &[u8] {
    bytes.get(range).unwrap_or_default()
}

/// `&mut bytes[range]`, or an empty slice when `range` is not inside `bytes`.
pub(crate) fn sub_mut<R: SliceIndex<[u8], Output = [u8]>>(bytes: &mut [u8], range: R) -> &mut [u8] {
    bytes.get_mut(range).unwrap_or_default()
}

/// The byte at `at`, or 0 when `at` is not inside `bytes`.
pub(crate) fn read_u8(bytes: &[u8], at: usize) -> u8 {
    bytes.get(at).copied().unwrap_or(0)
}

/// Sets the byte at `at` if it is inside `bytes`.
pub(crate) fn write_u8(bytes: &mut [u8], at: usize, value: u8) {
    if let Some(b) = bytes.get_mut(at) {
        *b = value;
    }
}
