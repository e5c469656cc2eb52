//! Sub-pixel and sub-scale refinement: fit a quadratic to the DoG cube around an extremum and
//! solve `H·o = -g` for the offset `o = (dx, dy, ds)` (Lowe 2004 §4, Brown & Lowe 2002).
//!
//! # Arithmetic (exact integers, one rounding)
//! With central differences, `2g` and `4H` are integer combinations of the cube samples
//! (`2g`: 17 bits, `4H`: 19 bits). Then `4H·o = -2·(2g)`, so
//! `o = -2·adj(4H)·(2g) / det(4H)`, computed in `i128` and divided once with rounding to the
//! nearest Q2.13 code (ties away from zero). In the fabric this is the one divider of the front
//! end, pipelined over [`REFINE_LATENCY`] enabled clocks at one candidate per clock (see the
//! constant); the octave model delays `refine()`'s result by that many registers.
//!
//! # Output format
//! `dx, dy, ds` are [`Offset`] = `fixed::types::I3F13` (i16, Q2.13, 1/8192 sample, the wire's
//! format). A point is rejected when `det(H) == 0` or any `|o_i| > max_offset` (default 0.5:
//! beyond it the true extremum is nearer another sample, which a streaming detector cannot
//! revisit, Lowe's re-centring being impossible in one pass).

use crate::fabric::extrema::Cube;
use fixed::types::I3F13;

/// Refinement latency in enabled clocks: the pipeline of `hdl-interface/rtl/sc_refine.v`,
/// one candidate per clock.
///
/// 18 stages: (1) the sums `2g`, `4H`; (2) the six cofactors (20x20-bit products); (3) `det`
/// and the three dot products (20x39 and 39x17-bit products); (4) magnitudes, rounding term,
/// overflow test and divider step 14; (5)-(17) divider steps 13..1, one per stage; (18) step 0,
/// sign and limit, the refine register. Why 18: as one clock stage the refinement was
/// 144.7 ns of logic with iCE40 HX cell delays (≤ 6.9 MHz), the one path keeping the fabric
/// below the 9.73 MHz that 640x240 at 60 Hz needs; split so that no stage holds more than one
/// level of products or one of the fifteen dependent 59-bit compare/subtract steps of the
/// restoring divider (about 8 ns each), near the convolvers' depth. The longest stage is
/// 13.7 ns of logic (yosys `sta`, same cells; stage 3), ≤ 72.9 MHz before routing.
pub const REFINE_LATENCY: u32 = 18;

/// Offset format: Q2.13 in an `i16`.
pub type Offset = I3F13;

/// Fractional bits of [`Offset`].
pub const OFFSET_FRAC_BITS: u32 = 13;

/// The quadratic-fit offsets `[dx, dy, ds]` of cube `c` (`c[s][y][x]`), or `None` when the fit
/// is degenerate or any offset exceeds `max_offset` (raw Q2.13) in magnitude.
pub fn refine(c: &Cube, max_offset: u16) -> Option<[Offset; 3]> {
    let v = |s: usize, y: usize, x: usize| c[s][y][x] as i64;
    let c0 = v(1, 1, 1);
    let g2 = [
        v(1, 1, 2) - v(1, 1, 0),
        v(1, 2, 1) - v(1, 0, 1),
        v(2, 1, 1) - v(0, 1, 1),
    ];
    let hxx = 4 * (v(1, 1, 2) + v(1, 1, 0) - 2 * c0);
    let hyy = 4 * (v(1, 2, 1) + v(1, 0, 1) - 2 * c0);
    let hss = 4 * (v(2, 1, 1) + v(0, 1, 1) - 2 * c0);
    let hxy = v(1, 2, 2) - v(1, 2, 0) - v(1, 0, 2) + v(1, 0, 0);
    let hxs = v(2, 1, 2) - v(2, 1, 0) - v(0, 1, 2) + v(0, 1, 0);
    let hys = v(2, 2, 1) - v(2, 0, 1) - v(0, 2, 1) + v(0, 0, 1);
    let h = [[hxx, hxy, hxs], [hxy, hyy, hys], [hxs, hys, hss]];
    // Adjugate of the symmetric matrix (cofactors).
    let a00 = h[1][1] * h[2][2] - h[1][2] * h[2][1];
    let a01 = h[0][2] * h[2][1] - h[0][1] * h[2][2];
    let a02 = h[0][1] * h[1][2] - h[0][2] * h[1][1];
    let a11 = h[0][0] * h[2][2] - h[0][2] * h[2][0];
    let a12 = h[0][2] * h[1][0] - h[0][0] * h[1][2];
    let a22 = h[0][0] * h[1][1] - h[0][1] * h[1][0];
    let adj = [[a00, a01, a02], [a01, a11, a12], [a02, a12, a22]];
    let det = h[0][0] as i128 * a00 as i128
        + h[0][1] as i128 * a01 as i128
        + h[0][2] as i128 * a02 as i128;
    if det == 0 {
        return None;
    }
    let mut o = [Offset::ZERO; 3];
    for (i, oi) in o.iter_mut().enumerate() {
        let dot: i128 = (0..3).map(|j| adj[i][j] as i128 * g2[j] as i128).sum();
        let num = -2 * dot * (1i128 << OFFSET_FRAC_BITS);
        let q = div_round(num, det);
        if q.unsigned_abs() > (max_offset as u128).min(i16::MAX as u128) {
            return None;
        }
        *oi = Offset::from_bits(q as i16);
    }
    Some(o)
}

/// `n / d` rounded to nearest, ties away from zero (`d != 0`).
fn div_round(n: i128, d: i128) -> i128 {
    let (na, da) = (n.unsigned_abs(), d.unsigned_abs());
    let q = ((na + da / 2) / da) as i128;
    if (n < 0) != (d < 0) {
        -q
    } else {
        q
    }
}
