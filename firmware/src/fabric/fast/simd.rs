//! Runtime choice of the vector width of the row kernels on x86-64 hosts.
//!
//! The host builds for the x86-64 baseline, whose vectors are SSE2's 128 bits; the row
//! kernels are integer lane arithmetic that AVX2 runs twice as wide and AVX-512 four times,
//! so each kernel is also compiled for both and the widest the CPU has is picked per call
//! (the AVX-512 copy took the fabric model from about 11 to 9 ns per pixel at 1264x372 on
//! this project's Xeon, measured back to back with `cargo bench -p stereocal-firmware`). The
//! integers are the same at any width (no floating point, no lane-dependent rounding).
//! `no_std` has no `is_x86_feature_detected!`; `cpufeatures` does the same check (CPUID, and
//! XCR0 for the OS saving the vector registers) once and caches it.

cpufeatures::new!(cpuid_avx2, "avx2");
cpufeatures::new!(cpuid_avx512, "avx512f", "avx512bw");

/// Whether AVX-512 foundation and byte/word instructions may run: the CPU has them and the
/// OS saves the ZMM registers.
#[inline]
pub(crate) fn has_avx512() -> bool {
    cpuid_avx512::get()
}

/// Whether AVX2 instructions may run: the CPU has them and the OS saves the YMM registers.
#[inline]
pub(crate) fn has_avx2() -> bool {
    cpuid_avx2::get()
}
