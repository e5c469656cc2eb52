//! Runtime choice of the vector width of the row kernels on x86-64 hosts.
//!
//! The host builds for the x86-64 baseline, whose vectors are SSE2's 128 bits; the row
//! kernels are integer lane arithmetic that AVX2 runs twice as wide, so each kernel is also
//! compiled for AVX2 and picked per call when the CPU has it. The integers are the same at
//! any width (no floating point, no lane-dependent rounding). `no_std` has no
//! `is_x86_feature_detected!`; `cpufeatures` does the same check (CPUID, and XCR0 for the OS
//! saving the YMM registers) once and caches it.

cpufeatures::new!(cpuid_avx2, "avx2");

/// Whether AVX2 instructions may run: the CPU has them and the OS saves the YMM registers.
#[inline]
pub(crate) fn has_avx2() -> bool {
    cpuid_avx2::get()
}
