//! Register fields: where a value sits in a register and which values are valid.

use crate::{Access, BitRange, Error};

/// One field of one register, as the description defines it. The constants in
/// [`crate::regs`] are the only ones a program normally needs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    /// `REGISTER.FIELD`, for error messages.
    pub name: &'static str,
    /// Byte offset of the register holding the field.
    pub offset: u16,
    pub bits: BitRange,
    pub access: Access,
    /// Value after reset (unshifted).
    pub reset: u32,
    /// Smallest and largest value the fabric accepts (unshifted, inclusive).
    pub min: u32,
    pub max: u32,
}

impl Field {
    /// The field's bits in its register.
    pub const fn mask(&self) -> u32 {
        self.bits.mask()
    }

    /// The field's value in a register value.
    pub const fn extract(&self, register: u32) -> u32 {
        self.bits.extract(register)
    }

    /// `value` if the fabric accepts it in this field.
    pub const fn check(&self, value: u32) -> Result<u32, Error> {
        if value < self.min || value > self.max || value > self.bits.max_value() {
            Err(Error::FieldOutOfRange {
                field: self.name,
                value,
                min: self.min,
                max: self.max,
            })
        } else {
            Ok(value)
        }
    }

    /// `register` with this field set to `value`, after [`Field::check`].
    pub const fn insert(&self, register: u32, value: u32) -> Result<u32, Error> {
        if let Err(e) = self.check(value) {
            return Err(e);
        }
        match self.bits.insert(register, value) {
            Some(r) => Ok(r),
            None => Err(Error::FieldOutOfRange {
                field: self.name,
                value,
                min: self.min,
                max: self.max,
            }),
        }
    }
}
