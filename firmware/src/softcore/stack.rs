//! The main loop's worst-case stack, measured: paint at boot, scan after the frames.
//!
//! The stack region is what riscv-rt's linker script leaves between the end of `.bss`/heap
//! (`__estack`) and `_stack_start` (`__sstack`, the end of the program's RAM in
//! `firmware/memory.x`); the stack grows down from its top. On the bare-metal target
//! `paint` (first thing in `main`) fills every word of the region below the current stack
//! pointer with [`PAINT`], and `high_water` finds the lowest word that no longer holds it:
//! the stack reached down to there. `main` takes the mark twice: once when both channels are
//! built (boot: the constructors build each `Driver` by value in their own frames, the
//! deepest the stack goes), then it paints again and takes the main loop's mark after the
//! last frame (before the row-kernel measurement, whose buffers are not the loop's, and the
//! finisher). Both figures count from the top of the region, so they include `main`'s own
//! frame, which holds both channels. A word the program happened to write with
//! the pattern itself would hide up to that word: the figure is a lower bound, exact to a
//! few words in practice.
//!
//! With [`FLAG_COUNT_INSTRUCTIONS`](super::frame_input::FLAG_COUNT_INSTRUCTIONS) the firmware
//! logs the result as a defmt `println` (a `Log` packet; without the flag the stream carries
//! no extra packet, so it stays byte-identical to the in-process device's):
//!
//! ```text
//! stack: boot 3078916 main_loop 2173912 region 16668568
//! ```
//! [`StackReport::parse`] reads it back on the host.

use super::instructions::fields;

/// The word painted over the free stack at boot.
pub const PAINT: u32 = 0x57AC_C0DE;

/// The stack high-water marks of one run, in bytes from the top of the stack region down to
/// the deepest overwritten word.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StackReport {
    /// Boot: from reset until the channels are built (their constructors' frames).
    pub boot: u32,
    /// The main loop: from the repaint after boot until the last frame is done (`main`'s
    /// own frame, holding both channels, included).
    pub main_loop: u32,
    /// Bytes of the whole stack region.
    pub region: u32,
}

impl StackReport {
    /// The deeper of the two marks.
    pub fn worst(&self) -> u32 {
        self.boot.max(self.main_loop)
    }
}

impl StackReport {
    /// Reads a report from a decoded log message; `None` when `text` is not one.
    pub fn parse(text: &str) -> Option<Self> {
        let [boot, main_loop, region] = fields(text, "stack:", ["boot", "main_loop", "region"])?;
        Some(Self {
            boot: u32::try_from(boot).ok()?,
            main_loop: u32::try_from(main_loop).ok()?,
            region: u32::try_from(region).ok()?,
        })
    }
}

#[cfg(target_os = "none")]
pub use painted::{high_water, log, paint};

#[cfg(target_os = "none")]
mod painted {
    use core::arch::asm;
    use core::ptr::addr_of;

    use super::{StackReport, PAINT};

    extern "C" {
        /// riscv-rt's linker script: the bottom of the stack region (end of the heap).
        static __estack: u8;
        /// riscv-rt's linker script: the top of the stack region (`_stack_start`).
        static __sstack: u8;
    }

    /// The stack region, word-aligned: `(bottom, top)`.
    fn region() -> (usize, usize) {
        let bottom = addr_of!(__estack) as usize;
        let top = addr_of!(__sstack) as usize;
        ((bottom + 3) & !3, top & !3)
    }

    /// Fills the stack region below the current stack pointer with [`PAINT`].
    ///
    /// The loop is assembly: it writes memory no Rust object owns (below `sp`, where nothing
    /// is live), and uses no stack itself.
    #[inline(never)]
    pub fn paint() {
        let (bottom, _) = region();
        // SAFETY: every word written lies in the stack region below this function's stack
        // pointer: free stack, which holds nothing live (no interrupts are enabled, one hart).
        unsafe {
            asm!(
                "1:",
                "bgeu {p}, sp, 2f",
                "sw {pattern}, 0({p})",
                "addi {p}, {p}, 4",
                "j 1b",
                "2:",
                p = inout(reg) bottom => _,
                pattern = in(reg) PAINT,
                options(nostack),
            );
        }
    }

    /// The deepest the stack has reached since [`paint`], in bytes from the top of the
    /// region, and the region's size.
    #[inline(never)]
    pub fn high_water() -> (u32, u32) {
        let (bottom, top) = region();
        let lowest: usize;
        // SAFETY: reads words of the stack region from its bottom up to the first one that
        // differs from the paint (at the latest this function's own frame, below `top`).
        unsafe {
            asm!(
                "1:",
                "bgeu {p}, {top}, 2f",
                "lw {word}, 0({p})",
                "bne {word}, {pattern}, 2f",
                "addi {p}, {p}, 4",
                "j 1b",
                "2:",
                p = inout(reg) bottom => lowest,
                top = in(reg) top,
                pattern = in(reg) PAINT,
                word = out(reg) _,
                options(nostack, readonly),
            );
        }
        ((top - lowest) as u32, (top - bottom) as u32)
    }

    /// Sends `report` as a log packet in the format [`StackReport::parse`] reads.
    pub fn log(report: &StackReport) {
        defmt::println!(
            "stack: boot {=u32} main_loop {=u32} region {=u32}",
            report.boot,
            report.main_loop,
            report.region
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_logged_text_parses() {
        assert_eq!(
            StackReport::parse("stack: boot 8192 main_loop 4096 region 16000000"),
            Some(StackReport {
                boot: 8192,
                main_loop: 4096,
                region: 16_000_000
            })
        );
    }

    #[test]
    fn other_messages_are_not_reports() {
        assert_eq!(StackReport::parse("stack: boot 8192 main_loop 4096"), None);
        assert_eq!(
            StackReport::parse("kernels: pixels 1 gaussian 2 dog 3 sobel_cordic 4"),
            None
        );
    }
}
