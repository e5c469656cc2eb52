//! Registers: offset, reset value and what each bit does on a bus access.

use crate::regs;

/// One register, with its bits split by access type. Bits in none of the masks are reserved:
/// they read 0 and ignore writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Register {
    pub name: &'static str,
    /// Byte offset from [`regs::BASE_ADDRESS`].
    pub offset: u16,
    pub reset: u32,
    pub ro_mask: u32,
    pub rw_mask: u32,
    pub w1c_mask: u32,
    pub wo_mask: u32,
    /// A bus read removes the head of a FIFO; never read it speculatively.
    pub pops_on_read: bool,
}

impl Register {
    /// Bits that belong to some field.
    pub const fn defined_mask(&self) -> u32 {
        self.ro_mask | self.rw_mask | self.w1c_mask | self.wo_mask
    }
}

/// The register at a byte offset, if any.
pub fn register_at(offset: u16) -> Option<&'static Register> {
    regs::REGISTERS.iter().find(|r| r.offset == offset)
}
