//! In-memory registers: the fabric model's side of the bus, and a fake for driver tests.

use crate::{regs, Error, Field, Register, RegisterBus};

/// Every register of the map in memory, with the access rules of the description.
///
/// Two views of the same storage:
/// - the **bus** (the [`RegisterBus`] impl, [`RegisterBank::try_read`],
///   [`RegisterBank::try_write`]) is what the driver sees: `ro` bits ignore writes, `w1c` bits
///   clear where a 1 is written, `wo` bits read as 0, reserved bits read 0;
/// - the **device** (`device_*`) is what the fabric model uses: it sees `wo` strobes and can
///   set any field, including `ro` and `w1c` ones.
///
/// Through the [`RegisterBus`] trait, an access at a misaligned or unmapped offset reads 0
/// and writes nothing, like a bus that answers a decode error with zeros; the access is
/// counted in [`RegisterBank::bus_errors`] and kept in [`RegisterBank::last_bus_error`] so a
/// test can assert on it. `try_read`/`try_write` return the error instead.
///
/// `pops_on_read` registers are plain `ro` storage here: the bank has no FIFO. A model that
/// owns the FIFOs wraps the bank in its own [`RegisterBus`] and serves those offsets.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RegisterBank {
    values: [u32; regs::REGISTERS.len()],
    bus_errors: u32,
    last_bus_error: Option<Error>,
}

impl Default for RegisterBank {
    fn default() -> Self {
        Self::new()
    }
}

impl RegisterBank {
    /// All registers at their reset values.
    pub fn new() -> Self {
        let mut values = [0; regs::REGISTERS.len()];
        for (value, register) in values.iter_mut().zip(regs::REGISTERS.iter()) {
            *value = register.reset;
        }
        Self {
            values,
            bus_errors: 0,
            last_bus_error: None,
        }
    }

    /// Puts every register back to its reset value (a power-on reset; the bus error
    /// record is kept).
    pub fn reset(&mut self) {
        for (value, register) in self.values.iter_mut().zip(regs::REGISTERS.iter()) {
            *value = register.reset;
        }
    }

    fn index(offset: u16) -> Result<(usize, &'static Register), Error> {
        if offset % 4 != 0 {
            return Err(Error::MisalignedOffset { offset });
        }
        regs::REGISTERS
            .iter()
            .enumerate()
            .find(|(_, r)| r.offset == offset)
            .ok_or(Error::UnmappedOffset { offset })
    }

    /// A bus read: `wo` and reserved bits read as 0.
    pub fn try_read(&self, offset: u16) -> Result<u32, Error> {
        let (i, r) = Self::index(offset)?;
        Ok(self.values[i] & (r.ro_mask | r.rw_mask | r.w1c_mask))
    }

    /// A bus write: `rw` and `wo` bits take `value`, `w1c` bits clear where `value` has a 1,
    /// `ro` and reserved bits keep their value.
    pub fn try_write(&mut self, offset: u16, value: u32) -> Result<(), Error> {
        let (i, r) = Self::index(offset)?;
        let old = self.values[i];
        let written = r.rw_mask | r.wo_mask;
        let kept = old & !written & !(r.w1c_mask & value);
        self.values[i] = kept | (value & written);
        Ok(())
    }

    /// Bus accesses through [`RegisterBus`] that hit no register.
    pub fn bus_errors(&self) -> u32 {
        self.bus_errors
    }

    /// The last such access's error.
    pub fn last_bus_error(&self) -> Option<Error> {
        self.last_bus_error
    }

    fn record(&mut self, e: Error) {
        self.bus_errors = self.bus_errors.saturating_add(1);
        self.last_bus_error = Some(e);
    }

    /// The device's view of a register: every defined bit, `wo` strobes included.
    pub fn device_read(&self, offset: u16) -> Result<u32, Error> {
        let (i, _) = Self::index(offset)?;
        Ok(self.values[i])
    }

    /// Sets a register from the device side, whatever the bus access of its bits; reserved
    /// bits stay 0.
    pub fn device_write(&mut self, offset: u16, value: u32) -> Result<(), Error> {
        let (i, r) = Self::index(offset)?;
        self.values[i] = value & r.defined_mask();
        Ok(())
    }

    /// A field as the device sees it.
    pub fn device_field(&self, field: &Field) -> Result<u32, Error> {
        Ok(field.extract(self.device_read(field.offset)?))
    }

    /// Sets a field from the device side (e.g. STATUS.BUSY, a FIFO level, a `w1c` flag).
    /// `value` must be in the field's range.
    pub fn device_set_field(&mut self, field: &Field, value: u32) -> Result<(), Error> {
        let (i, _) = Self::index(field.offset)?;
        self.values[i] = field.insert(self.values[i], value)?;
        Ok(())
    }

    /// Returns a `wo` strobe's value and clears it, as the fabric consumes a strobe in the
    /// clock after the write.
    pub fn device_take_field(&mut self, field: &Field) -> Result<u32, Error> {
        let (i, _) = Self::index(field.offset)?;
        let value = field.extract(self.values[i]);
        self.values[i] &= !field.mask();
        Ok(value)
    }
}

impl RegisterBus for RegisterBank {
    fn read(&mut self, offset: u16) -> u32 {
        match self.try_read(offset) {
            Ok(v) => v,
            Err(e) => {
                self.record(e);
                0
            }
        }
    }

    fn write(&mut self, offset: u16, value: u32) {
        if let Err(e) = self.try_write(offset, value) {
            self.record(e);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::regs::{
        control, output_mode, point_fifo_level, point_overflow_count, status, version, width,
    };

    #[test]
    fn every_register_starts_at_its_reset_value() {
        let mut bank = RegisterBank::new();
        for r in regs::REGISTERS.iter() {
            // `wo` bits read 0 on the bus whatever their reset.
            assert_eq!(bank.read(r.offset), r.reset & !r.wo_mask, "{}", r.name);
        }
        assert_eq!(bank.read_field(&width::VALUE), 640);
        assert_eq!(bank.read_field(&output_mode::SOBEL_SCALE), 1);
        assert_eq!(bank.read_field(&version::MAJOR), regs::VERSION_MAJOR);
        assert_eq!(bank.read_field(&version::MAGIC), 0x5C01);
    }

    #[test]
    fn bus_writes_to_ro_registers_are_ignored_but_the_device_can_set_them() {
        let mut bank = RegisterBank::new();
        bank.write(point_fifo_level::OFFSET, 77);
        bank.write(version::OFFSET, 0);
        assert_eq!(bank.read(point_fifo_level::OFFSET), 0);
        assert_eq!(bank.read(version::OFFSET), version::RESET);
        bank.device_set_field(&point_fifo_level::LEVEL, 77).unwrap();
        assert_eq!(bank.read(point_fifo_level::OFFSET), 77);
        bank.device_write(point_overflow_count::OFFSET, u32::MAX)
            .unwrap();
        assert_eq!(bank.read_field(&point_overflow_count::COUNT), u32::MAX);
        assert_eq!(bank.bus_errors(), 0);
    }

    #[test]
    fn w1c_flags_clear_only_where_one_is_written_and_ro_bits_survive() {
        let mut bank = RegisterBank::new();
        bank.device_set_field(&status::BUSY, 1).unwrap();
        bank.device_set_field(&status::FRAME_DONE, 1).unwrap();
        bank.device_set_field(&status::POINT_OVERFLOW, 1).unwrap();
        bank.write(status::OFFSET, 0);
        assert_eq!(bank.read(status::OFFSET), 0b0111);
        bank.write(
            status::OFFSET,
            status::FRAME_DONE.mask() | status::BUSY.mask(),
        );
        assert_eq!(
            bank.read(status::OFFSET),
            0b0101,
            "BUSY is ro, FRAME_DONE cleared"
        );
        bank.write_field(&status::POINT_OVERFLOW, 1).unwrap();
        assert_eq!(bank.read(status::OFFSET), 0b0001);
    }

    #[test]
    fn wo_strobes_read_zero_on_the_bus_and_are_taken_by_the_device() {
        let mut bank = RegisterBank::new();
        bank.write_field(&control::ENABLE, 1).unwrap();
        bank.write_field(&control::FRAME_ARM, 1).unwrap();
        assert_eq!(bank.read(control::OFFSET), control::ENABLE.mask());
        assert_eq!(bank.device_take_field(&control::FRAME_ARM), Ok(1));
        assert_eq!(bank.device_take_field(&control::FRAME_ARM), Ok(0));
        assert_eq!(
            bank.device_field(&control::ENABLE),
            Ok(1),
            "ENABLE kept by the RMW"
        );
    }

    #[test]
    fn write_field_keeps_other_rw_fields_and_checks_ranges() {
        let mut bank = RegisterBank::new();
        bank.write_field(&output_mode::SOBEL_SCALE, 3).unwrap();
        assert_eq!(
            bank.read_field(&output_mode::SOBEL_OUTPUT),
            output_mode::SobelOutput::Patches.bits()
        );
        assert_eq!(
            bank.write_field(&width::VALUE, 1281),
            Err(Error::FieldOutOfRange {
                field: "WIDTH.VALUE",
                value: 1281,
                min: regs::MIN_SIDE,
                max: regs::MAX_WIDTH
            })
        );
        assert_eq!(
            bank.read_field(&width::VALUE),
            640,
            "a rejected write changes nothing"
        );
        assert_eq!(
            bank.write_field(&point_fifo_level::LEVEL, 1),
            Err(Error::FieldReadOnly {
                field: "POINT_FIFO_LEVEL.LEVEL"
            })
        );
    }

    #[test]
    fn reserved_bits_read_zero_from_both_sides() {
        let mut bank = RegisterBank::new();
        bank.write(width::OFFSET, 0xFFFF_0000 | 800);
        assert_eq!(bank.read(width::OFFSET), 800);
        bank.device_write(status::OFFSET, u32::MAX).unwrap();
        assert_eq!(bank.device_read(status::OFFSET), Ok(0xF));
    }

    #[test]
    fn out_of_map_offsets_are_typed_errors_and_counted_bus_errors() {
        let mut bank = RegisterBank::new();
        assert_eq!(bank.try_read(2), Err(Error::MisalignedOffset { offset: 2 }));
        assert_eq!(
            bank.try_write(0xFC, 1),
            Err(Error::UnmappedOffset { offset: 0xFC })
        );
        assert_eq!(
            bank.device_read(u16::MAX),
            Err(Error::MisalignedOffset { offset: u16::MAX })
        );
        let before = bank.clone();
        assert_eq!(bank.read(0xFC), 0);
        bank.write(0x1000, 5);
        assert_eq!(bank.bus_errors(), 2);
        assert_eq!(
            bank.last_bus_error(),
            Some(Error::UnmappedOffset { offset: 0x1000 })
        );
        for r in regs::REGISTERS.iter() {
            assert_eq!(bank.device_read(r.offset), before.device_read(r.offset));
        }
    }

    #[test]
    fn reset_restores_every_register() {
        let mut bank = RegisterBank::new();
        bank.write_field(&width::VALUE, 1280).unwrap();
        bank.device_set_field(&status::FRAME_DONE, 1).unwrap();
        bank.reset();
        assert_eq!(bank, RegisterBank::new());
    }
}

#[cfg(test)]
mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Whatever the fabric set and whatever the bus writes, each bit follows its access type.
        #[test]
        fn bus_writes_follow_the_access_masks(
            index in 0..regs::REGISTERS.len(),
            device in any::<u32>(),
            written in any::<u32>(),
        ) {
            let r = &regs::REGISTERS[index];
            let mut bank = RegisterBank::new();
            bank.device_write(r.offset, device).unwrap();
            let before = bank.device_read(r.offset).unwrap();
            bank.try_write(r.offset, written).unwrap();
            let after = bank.device_read(r.offset).unwrap();
            prop_assert_eq!(after & r.ro_mask, before & r.ro_mask);
            prop_assert_eq!(after & r.rw_mask, written & r.rw_mask);
            prop_assert_eq!(after & r.wo_mask, written & r.wo_mask);
            prop_assert_eq!(after & r.w1c_mask, before & r.w1c_mask & !written);
            prop_assert_eq!(after & !r.defined_mask(), 0);
            prop_assert_eq!(bank.try_read(r.offset).unwrap(), after & !r.wo_mask);
        }

        /// No offset makes the bank panic; only mapped, aligned offsets succeed.
        #[test]
        fn any_offset_is_answered(offset in any::<u16>(), value in any::<u32>()) {
            let mut bank = RegisterBank::new();
            let mapped = crate::register_at(offset).is_some();
            prop_assert_eq!(bank.try_write(offset, value).is_ok(), mapped);
            prop_assert_eq!(bank.try_read(offset).is_ok(), mapped);
            bank.write(offset, value);
            let _ = bank.read(offset);
            prop_assert_eq!(bank.bus_errors(), if mapped { 0 } else { 2 });
        }
    }
}
