//! Runtime choice of the vector width of the row kernels on x86-64 hosts.
//!
//! The host builds for the x86-64 baseline, whose vectors are SSE2's 128 bits; the row
//! kernels are integer lane arithmetic that AVX2 runs twice as wide, so each kernel is also
//! compiled for AVX2 and picked per call when the CPU has it. The integers are the same at
//! any width (no floating point, no lane-dependent rounding). `no_std` has no
//! `is_x86_feature_detected!`, so the check is done here from CPUID and XCR0, once.

use core::arch::x86_64::{__cpuid_count, _xgetbv, CpuidResult};
use core::sync::atomic::{AtomicU8, Ordering};

/// 0 = not checked yet, 1 = no AVX2, 2 = AVX2 usable.
static AVX2: AtomicU8 = AtomicU8::new(0);

/// Whether AVX2 instructions may run: the CPU has them and the OS saves the YMM registers.
#[inline]
pub(crate) fn has_avx2() -> bool {
    match AVX2.load(Ordering::Relaxed) {
        0 => {
            let yes = detect();
            // Racing first calls store the same answer.
            AVX2.store(1 + u8::from(yes), Ordering::Relaxed);
            yes
        }
        state => state == 2,
    }
}

fn detect() -> bool {
    const OSXSAVE: u32 = 1 << 27;
    const AVX: u32 = 1 << 28;
    const AVX2_BIT: u32 = 1 << 5;
    /// XCR0: the OS saves and restores the SSE (bit 1) and AVX (bit 2) register state.
    const XCR0_SSE_AVX: u64 = 0b110;
    let leaf1 = cpuid(1);
    if leaf1.ecx & (OSXSAVE | AVX) != OSXSAVE | AVX {
        return false;
    }
    // SAFETY: OSXSAVE is set, so XGETBV exists and XCR0 may be read.
    if unsafe { xcr0() } & XCR0_SSE_AVX != XCR0_SSE_AVX {
        return false;
    }
    cpuid(0).eax >= 7 && cpuid(7).ebx & AVX2_BIT != 0
}

/// CPUID `leaf`, sub-leaf 0; every x86-64 CPU has the instruction.
fn cpuid(leaf: u32) -> CpuidResult {
    // `__cpuid_count` is a safe function in newer toolchains and `unsafe` in the oldest one
    // the workspace supports (`rust-version`); the block serves the latter.
    #[allow(unused_unsafe)]
    // SAFETY: CPUID is part of x86-64.
    unsafe {
        __cpuid_count(leaf, 0)
    }
}

/// XCR0, the OS-enabled register state.
///
/// # Safety
/// Only callable when CPUID reports OSXSAVE.
#[target_feature(enable = "xsave")]
unsafe fn xcr0() -> u64 {
    _xgetbv(0)
}
