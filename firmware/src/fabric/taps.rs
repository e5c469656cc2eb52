//! Quantized 5-tap Gaussian kernels (thesis table 4.2) and their LUT distributed-arithmetic
//! tables.
//!
//! # Width and rounding
//! Taps are unsigned 10-bit integers that sum to exactly `1 << TAP_BITS` = 1024, so the DC gain
//! is exactly one: a flat image stays flat bit for bit. The row pass keeps the exact sum
//! `Σ tap·pixel` and the column pass rounds once, `(Σ tap·row + 2^19) >> 20` (round half up;
//! `convolver.rs`).
//!
//! # Which sigmas: the design column of table 4.2, not the "discrete" column
//! Table 4.2 lists the σ the thesis *designed* (0.7664, 0.9656, 1.2166: Lowe's schedule
//! `σ_i = sqrt(k² - 1)·k^(i-1)` with `k = 2^(1/3)` on a base of σ = 1) and the σ its 5-tap
//! kernels *measured* ("discrete σ": 0.8292, 0.9354, 1.1040). The variance of a discrete kernel
//! adds exactly under convolution, so taps whose variance equals the design variance make the
//! cascade exactly the designed scale space: base variance 1, then 1 + 0.5879 = k², + 0.9316 =
//! k⁴, + 1.4805 = 4, i.e. G3 has σ = 2 and the subsampled G3 is again a base of σ = 1.
//! With the measured column instead, the variance steps (0.688, 0.875, 1.219) grow faster than
//! the scale, so the middle DoG is never the scale extremum of a blob (its |D| is below one of
//! its neighbours for every blob size) and the detector finds almost nothing.
//! [`TABLE_4_2_DISCRETE_TAPS`] are kernels with exactly the thesis' discrete column (G0 1.1592,
//! then 0.8292, 0.9354, 1.1040), quantized the same way; `tests/scale_space.rs` runs them
//! through the fast path on the textured test image and on a real frame and checks that they
//! find next to no point where [`GAUSS_TAPS`] find hundreds, checks the blob argument for both columns, and that blobs of σ 1.4, 2.8, 5.6 are
//! found in octaves 0, 1, 2 to within 0.1 pixel with [`GAUSS_TAPS`].
//! G0, the input filter, runs on the camera image only (octave 0); it brings a camera blur of
//! σ ≈ 0.5 to the base σ = 1 the cascade expects: `σ_G0 = sqrt(1 - 0.5²) = 0.866`. Octaves 1..
//! take the subsampled G3 unfiltered (thesis fig. 4.5: input, G1, G2, G3).
//!
//! # How the taps were chosen
//! For a target σ we (1) find the continuous `s` whose sampled, truncated, normalised Gaussian
//! `exp(-i²/2s²)`, `i = -2..2`, has discrete deviation σ (bisection), (2) round its outer taps
//! to 1/1024, (3) search the outer two taps ±3 codes, the centre tap absorbing the remainder
//! (unity DC), keeping unimodal kernels, for the smallest `|σ_q - σ|`, ties broken by the
//! distance to the unrounded kernel. With 10 bits the variance moves in steps of 2/1024; the
//! three cascade variances sum to exactly 3 (3072/1024):
//!
//! | kernel | taps (/1024)           | σ (design) | σ_q (these taps) |
//! |--------|------------------------|------------|------------------|
//! | G0     |  35 244 466 244  35    | 0.8660     | 0.866025         |
//! | G1     |  18 229 530 229  18    | 0.7664     | 0.766740         |
//! | G2     |  57 249 412 249  57    | 0.9656     | 0.965215         |
//! | G3     | 130 238 288 238 130    | 1.2166     | 1.216745         |
//!
//! `tests/taps.rs` recomputes σ_q and the sums from these integers.

/// Fractional bits of a tap (taps sum to `1 << TAP_BITS`).
pub const TAP_BITS: u32 = 10;

/// One symmetric 5-tap kernel, outermost tap first.
pub type Taps = [u16; 5];

/// The four kernels: G0 (input filter, octave 0 only) and the cascade G1..G3.
pub const GAUSS_TAPS: [Taps; 4] = [
    [35, 244, 466, 244, 35],
    [18, 229, 530, 229, 18],
    [57, 249, 412, 249, 57],
    [130, 238, 288, 238, 130],
];

/// Kernels whose discrete σ is the thesis' "discrete σ" column of table 4.2 (G0 1.1592, then
/// 0.8292, 0.9354, 1.1040), 10-bit taps found as above: σ_q 1.159202, 0.829156, 0.935414,
/// 1.103970. Not the fabric's kernels (see the module documentation): kept to show why.
pub const TABLE_4_2_DISCRETE_TAPS: [Taps; 4] = [
    [111, 244, 314, 244, 111],
    [28, 240, 488, 240, 28],
    [50, 248, 428, 248, 50],
    [94, 248, 340, 248, 94],
];

/// Standard deviation of the discrete kernel `taps` (thesis eq. 4.4), for documentation tests.
pub fn discrete_sigma(taps: &Taps) -> f64 {
    let mut var = 0u32;
    for (i, &t) in taps.iter().enumerate() {
        let d = i as i32 - 2;
        var += (d * d) as u32 * t as u32;
    }
    libm_sqrt(var as f64 / (1u32 << TAP_BITS) as f64)
}

/// Newton square root (no `std` here); only used for documentation figures, not the pixel path.
fn libm_sqrt(v: f64) -> f64 {
    if v <= 0.0 {
        return 0.0;
    }
    let mut r = if v > 1.0 { v } else { 1.0 };
    for _ in 0..64 {
        r = 0.5 * (r + v / r);
    }
    r
}

/// Partial-product table for LUT distributed arithmetic (thesis 4.2.3): entry `m` (5 bits, bit
/// `j` = bit plane value of pixel `j`) is the sum of the taps whose pixel bit is set. Width
/// `bk + n - 1 = 10 + 4` bits; 32 entries.
pub const fn da_lut(taps: &Taps) -> [u16; 32] {
    let mut lut = [0u16; 32];
    let mut m = 0;
    while m < 32 {
        let mut s = 0u16;
        let mut j = 0;
        while j < 5 {
            if m & (1 << j) != 0 {
                s += taps[j];
            }
            j += 1;
        }
        lut[m] = s;
        m += 1;
    }
    lut
}

/// The DA tables of [`GAUSS_TAPS`], as the fabric holds them in LUT ROMs.
pub const GAUSS_LUTS: [[u16; 32]; 4] = [
    da_lut(&GAUSS_TAPS[0]),
    da_lut(&GAUSS_TAPS[1]),
    da_lut(&GAUSS_TAPS[2]),
    da_lut(&GAUSS_TAPS[3]),
];
