//! Edge-response rejection (Lowe 2004 §4.1, beyond the thesis): a DoG extremum on an edge has
//! one large and one small principal curvature. With the 2x2 spatial Hessian of the middle DoG
//! image, keep the point iff `Det > 0` and `Tr²·r < (r+1)²·Det`.
//!
//! Integers only: `Dxx = c[1][2] + c[1][0] - 2c[1][1]` (and `Dyy` alike) need 18 bits; the cross
//! difference `4·Dxy = c[2][2] - c[2][0] - c[0][2] + c[0][0]` needs 18 bits. Scaling `Dxx`, `Dyy`
//! by 4 makes the test exact without a division: `Tr' = 4·Tr`, `Det' = 16·Det`, and every
//! product fits `i64` (`|Det'|` < 2^38, `Tr'²·r` < 2^48, `(r+1)²·|Det'|` < 2^54 for an 8-bit
//! `r`; `rtl/sc_edge.v` uses exactly these widths). Latency: one register, [`EDGE_LATENCY`].

/// Edge test register latency in enabled clocks.
pub const EDGE_LATENCY: u32 = 1;

/// Whether the 3x3 DoG neighbourhood `d[y][x]` passes the edge test with ratio `r`
/// (`r == 0` disables the test).
pub fn passes_edge_test(d: &[[i16; 3]; 3], r: u8) -> bool {
    if r == 0 {
        return true;
    }
    let v = |y: usize, x: usize| d[y][x] as i64;
    let dxx4 = 4 * (v(1, 2) + v(1, 0) - 2 * v(1, 1));
    let dyy4 = 4 * (v(2, 1) + v(0, 1) - 2 * v(1, 1));
    let dxy4 = v(2, 2) - v(2, 0) - v(0, 2) + v(0, 0);
    let tr = dxx4 + dyy4;
    let det = dxx4 * dyy4 - dxy4 * dxy4;
    let r = r as i64;
    det > 0 && tr * tr * r < (r + 1) * (r + 1) * det
}
