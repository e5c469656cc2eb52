//! Memory-mapped register access for the soft-core.

use crate::{regs, RegisterBus};

/// The fabric's registers at a physical address, accessed with volatile 32-bit loads and
/// stores.
///
/// Offsets that are not 32-bit aligned or fall outside [`regs::WINDOW_SIZE`] are not sent
/// to the bus: such reads return 0 and such writes are dropped, so a bad offset cannot reach
/// another device or fault the core.
#[derive(Debug)]
pub struct Mmio {
    base: usize,
}

impl Mmio {
    /// Register access at `base`.
    ///
    /// # Safety
    /// `base` must be 4-byte aligned and the start of [`regs::WINDOW_SIZE`] bytes of the
    /// fabric's registers (or memory standing in for them) that stay mapped and valid for
    /// volatile 32-bit access for the life of the returned value, and nothing else may
    /// treat that memory as ordinary Rust data meanwhile. Two `Mmio` on one window are
    /// allowed (accesses are volatile), but interleaved read-modify-writes then race.
    pub const unsafe fn new(base: usize) -> Self {
        Self { base }
    }

    /// Register access at [`regs::BASE_ADDRESS`], where the fabric sits on the soft-core's bus.
    ///
    /// # Safety
    /// As for [`Mmio::new`]: only on the soft-core (or a machine with the same map).
    pub const unsafe fn at_base_address() -> Self {
        Self {
            base: regs::BASE_ADDRESS,
        }
    }

    /// The address of offset 0.
    pub const fn base(&self) -> usize {
        self.base
    }

    fn address(&self, offset: u16) -> Option<*mut u32> {
        if offset % 4 != 0 || u32::from(offset) + 4 > regs::WINDOW_SIZE {
            return None;
        }
        Some(self.base.wrapping_add(usize::from(offset)) as *mut u32)
    }
}

impl RegisterBus for Mmio {
    fn read(&mut self, offset: u16) -> u32 {
        match self.address(offset) {
            // SAFETY: `new`'s contract makes every aligned word of the window valid for
            // volatile reads, and `address` only returns such words.
            Some(p) => unsafe { core::ptr::read_volatile(p) },
            None => 0,
        }
    }

    fn write(&mut self, offset: u16, value: u32) {
        if let Some(p) = self.address(offset) {
            // SAFETY: as in `read`, for volatile writes.
            unsafe { core::ptr::write_volatile(p, value) }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::regs::{control, width};

    const WORDS: usize = regs::WINDOW_SIZE as usize / 4;

    #[test]
    fn reads_and_writes_land_on_the_word_at_the_offset() {
        let mut window = [0u32; WORDS];
        window[usize::from(width::OFFSET) / 4] = 1280;
        {
            // SAFETY: `window` is aligned, WINDOW_SIZE bytes long and outlives `bus`; it is
            // only touched through `bus` in this block.
            let mut bus = unsafe { Mmio::new(window.as_mut_ptr() as usize) };
            assert_eq!(bus.read(width::OFFSET), 1280);
            bus.write(control::OFFSET, 0x1);
        }
        assert_eq!(window[usize::from(control::OFFSET) / 4], 0x1);
    }

    #[test]
    fn misaligned_and_out_of_window_offsets_never_touch_memory() {
        let mut window = [0xAAAA_AAAAu32; WORDS];
        {
            // SAFETY: as above.
            let mut bus = unsafe { Mmio::new(window.as_mut_ptr() as usize) };
            assert_eq!(bus.read(2), 0);
            assert_eq!(bus.read(regs::WINDOW_SIZE as u16), 0);
            bus.write(6, 0);
            bus.write(u16::MAX, 0);
        }
        assert!(window.iter().all(|&w| w == 0xAAAA_AAAA));
    }
}
