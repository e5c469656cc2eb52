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

    /// Reads `words.len()` registers in one burst, cycling through `offsets`:
    /// `words[i] = read(offsets[i % offsets.len()])`, in that order (nothing when `offsets`
    /// is empty).
    ///
    /// This is how FIFO entries are drained: `[DATA, POSITION]` repeated N times pops N Sobel
    /// entries and reads each one's holding register right after its pop. The provided loop
    /// is what an MMIO bus does (one volatile load per word); a software device overrides it
    /// to serve the burst without a call per word.
    fn read_burst(&mut self, offsets: &[u16], words: &mut [u32]) {
        for (word, &offset) in words.iter_mut().zip(offsets.iter().cycle()) {
            *word = self.read(offset);
        }
    }

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

    fn read_burst(&mut self, offsets: &[u16], words: &mut [u32]) {
        (**self).read_burst(offsets, words)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::regs::{control, status};

    /// Registers where every bit reads back as written, and a log of the accesses.
    struct Recorder {
        value: u32,
        reads: usize,
        writes: [Option<(u16, u32)>; 4],
        count: usize,
    }

    impl RegisterBus for Recorder {
        fn read(&mut self, _offset: u16) -> u32 {
            self.reads += 1;
            self.value
        }

        fn write(&mut self, offset: u16, value: u32) {
            self.writes[self.count] = Some((offset, value));
            self.count += 1;
        }
    }

    fn recorder(value: u32) -> Recorder {
        Recorder {
            value,
            reads: 0,
            writes: [None; 4],
            count: 0,
        }
    }

    #[test]
    fn a_burst_cycles_through_its_offsets() {
        struct Echo;
        impl RegisterBus for Echo {
            fn read(&mut self, offset: u16) -> u32 {
                offset.into()
            }
            fn write(&mut self, _offset: u16, _value: u32) {}
        }
        let mut words = [0; 5];
        Echo.read_burst(&[0x48, 0x4C], &mut words);
        assert_eq!(words, [0x48, 0x4C, 0x48, 0x4C, 0x48]);
        let mut untouched = [7; 2];
        Echo.read_burst(&[], &mut untouched);
        assert_eq!(untouched, [7, 7]);
    }

    #[test]
    fn clearing_a_flag_neither_reads_nor_clears_the_other_flags() {
        let mut bus = recorder(0xF);
        bus.write_field(&status::SOBEL_OVERFLOW, 1).unwrap();
        assert_eq!(bus.reads, 0);
        assert_eq!(
            bus.writes[0],
            Some((status::OFFSET, status::SOBEL_OVERFLOW.mask()))
        );
    }

    #[test]
    fn firing_a_strobe_keeps_rw_bits_and_fires_no_other_strobe() {
        // As if the bus returned every bit set (a wo bit must still be written as 0).
        let mut bus = recorder(u32::MAX);
        // Through `&mut Recorder`, the form a driver generic over `B: RegisterBus` receives.
        fn fire<B: RegisterBus>(mut bus: B) -> Result<(), Error> {
            bus.write_field(&control::FRAME_ARM, 1)
        }
        fire(&mut bus).unwrap();
        assert_eq!(bus.reads, 1);
        assert_eq!(
            bus.writes[0],
            Some((
                control::OFFSET,
                control::ENABLE.mask() | control::FRAME_ARM.mask()
            ))
        );
    }
}
