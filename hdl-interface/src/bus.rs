//! The register access interface shared by the soft-core, the fabric model and tests.

use crate::{register_at, Access, Error, Field};

/// 32-bit register reads and writes at byte offsets inside the fabric's window.
///
/// Implementors decide what an access outside the register map does (see [`crate::Mmio`]
/// and [`crate::RegisterBank`]); neither may panic. The provided methods add field-level
/// access on top.
pub trait RegisterBus {
    /// Reads the register at `offset` (bytes from the window's base).
    fn read(&mut self, offset: u16) -> u32;

    /// Writes the register at `offset`.
    fn write(&mut self, offset: u16, value: u32);

    /// Reads one field. Reading a [`crate::Register::pops_on_read`] register has its side
    /// effect.
    fn read_field(&mut self, field: &Field) -> u32 {
        field.extract(self.read(field.offset))
    }

    /// Writes one field and leaves the register's other `rw` fields as they were.
    ///
    /// The register is read first only if it has other `rw` bits to keep. Its `w1c` and `wo`
    /// bits are written as 0, so this never clears a flag or fires a strobe it was not
    /// asked to: writing 1 to a `w1c` field clears that flag, writing 1 to a `wo` field
    /// fires that strobe.
    fn write_field(&mut self, field: &Field, value: u32) -> Result<(), Error> {
        if field.access == Access::Ro {
            return Err(Error::FieldReadOnly { field: field.name });
        }
        let register = register_at(field.offset).ok_or(Error::UnmappedOffset {
            offset: field.offset,
        })?;
        let keep = register.rw_mask & !field.mask();
        let current = if keep == 0 {
            0
        } else {
            self.read(field.offset) & keep
        };
        let updated = field.insert(current, value)?;
        self.write(field.offset, updated);
        Ok(())
    }
}

impl<B: RegisterBus + ?Sized> RegisterBus for &mut B {
    fn read(&mut self, offset: u16) -> u32 {
        (**self).read(offset)
    }

    fn write(&mut self, offset: u16, value: u32) {
        (**self).write(offset, value)
    }
}
