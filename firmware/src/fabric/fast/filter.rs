//! Row kernels of the fast path, written over equal-length slices so the compiler vectorises
//! them. Integer results are identical to the register-level stages.
//!
//! No kernel can panic: each works on the common length of its slices (the callers pass
//! equal lengths, so that is every pixel), the main loops run over sub-slices of exactly that
//! length, and the border pixels are read with `get`.

use crate::fabric::convolver::COLUMN_SHIFT;
use crate::fabric::cordic::{CordicState, ATAN_BAM16};
use crate::fabric::dog::dog;
use crate::fabric::taps::Taps;

/// Defines the public kernel `$name` over the inlined body `$body`: on x86-64 the body is
/// also compiled for AVX2 and that copy runs when the CPU has it (see `simd.rs`); the
/// integers are the same at either width.
macro_rules! kernel {
    ($(#[$doc:meta])* pub fn $name:ident($($arg:ident: $ty:ty),* $(,)?) = $body:ident;) => {
        $(#[$doc])*
        pub fn $name($($arg: $ty),*) {
            #[cfg(target_arch = "x86_64")]
            if crate::fabric::fast::simd::has_avx512() {
                #[target_feature(enable = "avx512f,avx512bw")]
                unsafe fn wider($($arg: $ty),*) {
                    $body($($arg),*)
                }
                // SAFETY: `wider` needs only AVX-512F/BW, which the CPU was just found to have.
                return unsafe { wider($($arg),*) };
            }
            #[cfg(target_arch = "x86_64")]
            if crate::fabric::fast::simd::has_avx2() {
                #[target_feature(enable = "avx2")]
                unsafe fn wide($($arg: $ty),*) {
                    $body($($arg),*)
                }
                // SAFETY: `wide` needs only AVX2, which the CPU was just found to have.
                return unsafe { wide($($arg),*) };
            }
            $body($($arg),*)
        }
    };
}

/// `i` clamped to `0..=last` (replicated border); `min`/`max` rather than `clamp`, which
/// asserts its bounds.
#[inline(always)]
fn clamp(i: isize, last: usize) -> usize {
    i.max(0).min(last as isize) as usize
}

/// `r[i]` at the clamped column `i`, or 0 if `r` is empty.
#[inline(always)]
fn at_clamped(r: &[u16], i: isize, last: usize) -> u16 {
    r.get(clamp(i, last)).copied().unwrap_or(0)
}

/// The row stage's exact sum: five 16x16-bit products widened to 32 bits (the form SSE2
/// multiplies with `pmullw`/`pmulhuw`), equal to [`crate::fabric::convolver::da_row`].
#[inline(always)]
fn row_dot(t: &Taps, a: u16, b: u16, c: u16, d: u16, e: u16) -> u32 {
    let m = |t: u16, v: u16| t as u32 * v as u32;
    m(t[0], a) + m(t[1], b) + m(t[2], c) + m(t[3], d) + m(t[4], e)
}

/// The column stage's once-rounded result `(Σ t·v + 2^19) >> 20` of five row sums
/// ([`ROW_BITS`](crate::fabric::convolver::ROW_BITS) wide, at most `1024 · 65535`), in
/// 64-bit lanes (32x32 -> 64-bit multiplies, which SSE2 has as `pmuludq`). The kernels are
/// symmetric (`tests/taps.rs`), so mirrored rows are added first (27 bits) and three products
/// suffice. Equal to [`crate::fabric::convolver::da_column`].
#[inline(always)]
fn column_dot(t: &Taps, v: [u32; 5]) -> u16 {
    let m = |t: u16, v: u32| u64::from(t) * u64::from(v);
    let s = m(t[0], v[0] + v[4]) + m(t[1], v[1] + v[3]) + m(t[2], v[2]);
    ((s + (1 << (COLUMN_SHIFT - 1))) >> COLUMN_SHIFT) as u16
}

kernel! {
    /// Horizontal 5-tap filter of `src` into `dst` (same length), replicated border: the exact
    /// (unrounded) row sums the column pass takes.
    pub fn row_filter(t: &Taps, src: &[u16], dst: &mut [u32]) = row_filter_body;
}

/// The body of [`row_filter`].
#[inline(always)]
fn row_filter_body(t: &Taps, src: &[u16], dst: &mut [u32]) {
    let w = src.len().min(dst.len());
    let (src, dst) = (&src[..w], &mut dst[..w]);
    if w == 0 {
        return;
    }
    let last = w - 1;
    let border = |x: usize| {
        let at = |k: isize| at_clamped(src, x as isize + k, last);
        row_dot(t, at(-2), at(-1), at(0), at(1), at(2))
    };
    if w >= 5 {
        let n = w - 4;
        let (s0, s1, s2, s3, s4) = (
            &src[0..n],
            &src[1..n + 1],
            &src[2..n + 2],
            &src[3..n + 3],
            &src[4..n + 4],
        );
        let d = &mut dst[2..n + 2];
        for i in 0..n {
            d[i] = row_dot(t, s0[i], s1[i], s2[i], s3[i], s4[i]);
        }
        for x in [0, 1, w - 2, w - 1] {
            if let Some(d) = dst.get_mut(x) {
                *d = border(x);
            }
        }
    } else {
        for (x, d) in dst.iter_mut().enumerate() {
            *d = border(x);
        }
    }
}

kernel! {
    /// Vertical 5-tap filter: `rows` are the row sums of input rows `y-2 ..= y+2` (already
    /// border-clamped); rounds once to Q8.8.
    pub fn column_filter(t: &Taps, rows: [&[u32]; 5], dst: &mut [u16]) = column_filter_body;
}

/// The body of [`column_filter`].
#[inline(always)]
fn column_filter_body(t: &Taps, rows: [&[u32]; 5], dst: &mut [u16]) {
    let n = rows.iter().fold(dst.len(), |n, r| n.min(r.len()));
    let dst = &mut dst[..n];
    let (r0, r1, r2, r3, r4) = (
        &rows[0][..n],
        &rows[1][..n],
        &rows[2][..n],
        &rows[3][..n],
        &rows[4][..n],
    );
    for i in 0..n {
        dst[i] = column_dot(t, [r0[i], r1[i], r2[i], r3[i], r4[i]]);
    }
}

kernel! {
    /// `dst[x] = dog(a[x], b[x])`.
    pub fn dog_row(a: &[u16], b: &[u16], dst: &mut [i16]) = dog_row_body;
}

/// The body of [`dog_row`].
#[inline(always)]
fn dog_row_body(a: &[u16], b: &[u16], dst: &mut [i16]) {
    let n = dst.len().min(a.len()).min(b.len());
    let (a, b, dst) = (&a[..n], &b[..n], &mut dst[..n]);
    for i in 0..n {
        dst[i] = dog(a[i], b[i]);
    }
}

kernel! {
    /// Sobel of the centre row of `rows = [y-1, y, y+1]` (border-clamped), replicated columns.
    pub fn sobel_row(rows: [&[u16]; 3], sx: &mut [i32], sy: &mut [i32]) = sobel_row_body;
}

/// The body of [`sobel_row`].
#[inline(always)]
fn sobel_row_body(rows: [&[u16]; 3], sx: &mut [i32], sy: &mut [i32]) {
    let w = rows
        .iter()
        .fold(sx.len().min(sy.len()), |w, r| w.min(r.len()));
    let (a, b, c) = (&rows[0][..w], &rows[1][..w], &rows[2][..w]);
    let (sx, sy) = (&mut sx[..w], &mut sy[..w]);
    let at = |r: &[u16], i: isize| at_clamped(r, i, w.saturating_sub(1)) as i32;
    let border = |x: usize| {
        let x = x as isize;
        let gx = (at(a, x + 1) + 2 * at(b, x + 1) + at(c, x + 1))
            - (at(a, x - 1) + 2 * at(b, x - 1) + at(c, x - 1));
        let gy = (at(c, x - 1) + 2 * at(c, x) + at(c, x + 1))
            - (at(a, x - 1) + 2 * at(a, x) + at(a, x + 1));
        (gx, gy)
    };
    if w >= 3 {
        let n = w - 2;
        let (a0, a1, a2) = (&a[0..n], &a[1..n + 1], &a[2..n + 2]);
        let (b0, b2) = (&b[0..n], &b[2..n + 2]);
        let (c0, c1, c2) = (&c[0..n], &c[1..n + 1], &c[2..n + 2]);
        let (dx, dy) = (&mut sx[1..n + 1], &mut sy[1..n + 1]);
        for i in 0..n {
            let (a0, a1, a2) = (a0[i] as i32, a1[i] as i32, a2[i] as i32);
            let (c0, c1, c2) = (c0[i] as i32, c1[i] as i32, c2[i] as i32);
            dx[i] = (a2 + 2 * b2[i] as i32 + c2) - (a0 + 2 * b0[i] as i32 + c0);
            dy[i] = (c0 + 2 * c1 + c2) - (a0 + 2 * a1 + a2);
        }
        for x in [0, w - 1] {
            if let (Some(gx), Some(gy)) = (sx.get_mut(x), sy.get_mut(x)) {
                (*gx, *gy) = border(x);
            }
        }
    } else {
        for (x, (gx, gy)) in sx.iter_mut().zip(sy.iter_mut()).enumerate() {
            (*gx, *gy) = border(x);
        }
    }
}

kernel! {
    /// Branch-free CORDIC over a row: the same fold, rotations and rounding as
    /// [`crate::fabric::cordic::cordic`], written with selects so it vectorises (four `i32`
    /// lanes a register, so every operation saved counts).
    ///
    /// Two savings against the literal steps, neither changing a bit: the fold leaves `y >= 0`,
    /// so rotation 0 always turns clockwise and needs no sign; and a rotation's angle update
    /// `±a_k` is `a_k - 2·(a_k & m)` for the sign mask `m`, so the four signed angles are one
    /// constant minus twice a sum of masked angles. The angle is kept in `i32`, unwrapped: the
    /// final `>> 10` floors and `& 63` takes it modulo `64 · 1024 = 2^16`, which is the wrap.
    pub fn cordic_row(sx: &[i32], sy: &[i32], magnitude: &mut [u8], orientation: &mut [u8]) = cordic_row_body;
}

/// The body of [`cordic_row`].
#[inline(always)]
fn cordic_row_body(sx: &[i32], sy: &[i32], magnitude: &mut [u8], orientation: &mut [u8]) {
    /// `Σ a_k`, k = 0..=4: the angle when every rotation is clockwise.
    const CLOCKWISE: i32 = {
        let mut sum = 0;
        let mut k = 0;
        while k < ATAN_BAM16.len() {
            sum += ATAN_BAM16[k] as i32;
            k += 1;
        }
        sum
    };
    let n = magnitude
        .len()
        .min(orientation.len())
        .min(sx.len())
        .min(sy.len());
    let (sx, sy) = (&sx[..n], &sy[..n]);
    let (magnitude, orientation) = (&mut magnitude[..n], &mut orientation[..n]);
    for i in 0..n {
        let s = fold_select(sx[i], sy[i]);
        let (mut x, mut y) = (s.x + s.y, s.y - s.x);
        let mut counter = 0;
        for (k, &a) in ATAN_BAM16.iter().enumerate().skip(1) {
            // m = 0 when y >= 0 (rotate clockwise), -1 otherwise; (v ^ m) - m is ±v.
            let m = y >> 31;
            let (dx, dy) = (y >> k, x >> k);
            x += (dx ^ m) - m;
            y -= (dy ^ m) - m;
            counter += a as i32 & m;
        }
        let z = s.z as i32 + CLOCKWISE - 2 * counter;
        let mag = (x >> 1) + (x >> 3);
        magnitude[i] = ((mag + 512) >> 10).clamp(0, 255) as u8;
        orientation[i] = if x == 0 {
            0
        } else {
            ((z + 512) >> 10) as u8 & 63
        };
    }
}

/// Quadrant fold by two selects: half turn when below the x axis (or on its negative half),
/// then a quarter turn when in the second quadrant. Equal to [`crate::fabric::cordic::fold`].
#[inline(always)]
pub(crate) fn fold_select(sx: i32, sy: i32) -> CordicState {
    let half = sy < 0 || (sy == 0 && sx < 0);
    let (x, y, z) = if half {
        (-sx, -sy, 32768u16)
    } else {
        (sx, sy, 0)
    };
    let quarter = x <= 0 && y > 0;
    if quarter {
        CordicState {
            x: y,
            y: -x,
            z: z + 16384,
        }
    } else {
        CordicState { x, y, z }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;
    use crate::fabric::convolver::{da_column, da_row};
    use crate::fabric::taps::{GAUSS_LUTS, GAUSS_TAPS};
    use proptest::prelude::*;
    use std::vec;
    use std::vec::Vec;

    /// The largest sum the row stage produces: all five samples 0xFFFF, taps summing to 1024.
    const MAX_ROW_SUM: u32 = 1024 * 0xFFFF;

    /// The fast column pass on one pixel of kernel `k`.
    fn column(k: usize, v: [u32; 5]) -> u16 {
        let rows = v.map(|v| [v]);
        let mut out = [0u16];
        column_filter(
            &GAUSS_TAPS[k],
            [&rows[0], &rows[1], &rows[2], &rows[3], &rows[4]],
            &mut out,
        );
        out[0]
    }

    /// A Sobel component: anything the Sobel stage can produce (`|g| <= 4 · 65535 < 2^18`),
    /// with the axes, the extremes and tiny values drawn often.
    fn sobel_value() -> impl Strategy<Value = i32> {
        prop_oneof![
            -(1i32 << 18)..(1 << 18),
            -4i32..=4,
            Just(4 * 65535),
            Just(-4 * 65535),
        ]
    }

    proptest! {
        /// The row CORDIC, as dispatched (AVX2 where the CPU has it) and as the portable body,
        /// equals the step-by-step scalar CORDIC on rows long enough for every vector loop and
        /// its remainder.
        #[test]
        fn cordic_row_equals_the_scalar_cordic(
            v in prop::collection::vec((sobel_value(), sobel_value()), 0..200),
        ) {
            let (sx, sy): (Vec<i32>, Vec<i32>) = v.iter().copied().unzip();
            let expected: Vec<(u8, u8)> = v
                .iter()
                .map(|&(x, y)| {
                    let (mag, ori) = crate::fabric::cordic::cordic(x, y);
                    (crate::fabric::cordic::magnitude_code(mag), ori)
                })
                .collect();
            for kernel in [cordic_row, cordic_row_body] {
                let (mut m, mut o) = (vec![0u8; v.len()], vec![0u8; v.len()]);
                kernel(&sx, &sy, &mut m, &mut o);
                let got: Vec<(u8, u8)> = m.into_iter().zip(o).collect();
                prop_assert_eq!(&got, &expected);
            }
        }

        /// Every dispatched kernel equals its portable body (the AVX2 copy, where it runs,
        /// computes the same integers).
        #[test]
        fn dispatched_kernels_equal_their_bodies(
            rows in prop::array::uniform5(prop::collection::vec(any::<u16>(), 77)),
            sums in prop::array::uniform5(prop::collection::vec(0u32..=MAX_ROW_SUM, 77)),
            k in 0usize..4,
        ) {
            let t = &GAUSS_TAPS[k];
            let (mut a, mut b) = ([0u32; 77], [0u32; 77]);
            row_filter(t, &rows[0], &mut a);
            row_filter_body(t, &rows[0], &mut b);
            prop_assert_eq!(a, b);
            let s = [&sums[0][..], &sums[1][..], &sums[2][..], &sums[3][..], &sums[4][..]];
            let (mut a, mut b) = ([0u16; 77], [0u16; 77]);
            column_filter(t, s, &mut a);
            column_filter_body(t, s, &mut b);
            prop_assert_eq!(a, b);
            let (mut a, mut b) = ([0i16; 77], [0i16; 77]);
            dog_row(&rows[0], &rows[1], &mut a);
            dog_row_body(&rows[0], &rows[1], &mut b);
            prop_assert_eq!(a, b);
            let r = [&rows[0][..], &rows[1][..], &rows[2][..]];
            let (mut ax, mut ay, mut bx, mut by) = ([0i32; 77], [0i32; 77], [0i32; 77], [0i32; 77]);
            sobel_row(r, &mut ax, &mut ay);
            sobel_row_body(r, &mut bx, &mut by);
            prop_assert_eq!((ax, ay), (bx, by));
        }

        /// The column pass equals the 36-bit DA accumulator, including the largest row sum
        /// the row stage can produce.
        #[test]
        fn column_dot_equals_the_da_column(
            v in prop::array::uniform5(prop_oneof![0u32..=MAX_ROW_SUM, Just(MAX_ROW_SUM)]),
            k in 0usize..4,
        ) {
            prop_assert_eq!(column(k, v), da_column(&GAUSS_LUTS[k], v));
        }

        /// Exact ties `m · 2^20 + 2^19` (and one either side) round up, as the DA does: four
        /// row sums drawn, the fifth (G0's odd outer tap, 35) solved for the tie.
        #[test]
        fn column_dot_rounds_ties_up(
            rest in prop::array::uniform4(0u32..=MAX_ROW_SUM / 2),
            d in -1i64..=1,
        ) {
            let t = GAUSS_TAPS[0];
            let partial: i64 = (1..5).map(|j| i64::from(t[j]) * i64::from(rest[j - 1])).sum();
            // Smallest v0 >= 0 with t0 · v0 + partial ≡ 2^19 + d (mod 2^20); t0 is odd, so it
            // is invertible modulo 2^20.
            let modulus = 1i64 << 20;
            // Newton's iteration doubles the correct low bits: 1, 2, 4, ... 32 >= 20.
            let mut inverse = 1i64;
            for _ in 0..5 {
                inverse = (inverse * (2 - i64::from(t[0]) * inverse)).rem_euclid(modulus);
            }
            let v0 = (((1i64 << 19) + d - partial).rem_euclid(modulus) * inverse) % modulus;
            prop_assume!(v0 <= i64::from(MAX_ROW_SUM));
            let v = [v0 as u32, rest[0], rest[1], rest[2], rest[3]];
            let sum: i64 = (0..5).map(|j| i64::from(t[j]) * i64::from(v[j])).sum();
            prop_assert_eq!(sum.rem_euclid(modulus), (1 << 19) + d);
            prop_assert_eq!(i64::from(column(0, v)), (sum + (1 << 19)) >> 20);
            prop_assert_eq!(column(0, v), da_column(&GAUSS_LUTS[0], v));
        }

        #[test]
        fn row_filter_equals_the_da_row(s in prop::array::uniform5(any::<u16>()), k in 0usize..4) {
            let mut out = [0u32; 5];
            row_filter(&GAUSS_TAPS[k], &s, &mut out);
            prop_assert_eq!(out[2], da_row(&GAUSS_LUTS[k], s));
        }
    }
}
