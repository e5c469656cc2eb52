//! Sobel gradient (thesis 4.3.1) on a 3x3 window of a Q8.8 scale image, shifts and adds only:
//! `Sx = (p02 + 2p12 + p22) - (p00 + 2p10 + p20)`, `Sy = (p20 + 2p21 + p22) - (p00 + 2p01 + p02)`.
//! x to the right, y down (image rows). Width: 19-bit signed (|S| ≤ 4·65535), held in `i32`.
//! Latency: one register, [`SOBEL_LATENCY`].

/// Gradient register latency in enabled clocks.
pub const SOBEL_LATENCY: u32 = 1;

/// `(Sx, Sy)` of window `p[row][col]`.
#[inline]
pub fn sobel(p: &[[u16; 3]; 3]) -> (i32, i32) {
    let v = |r: usize, c: usize| p[r][c] as i32;
    let sx = (v(0, 2) + (v(1, 2) << 1) + v(2, 2)) - (v(0, 0) + (v(1, 0) << 1) + v(2, 0));
    let sy = (v(2, 0) + (v(2, 1) << 1) + v(2, 2)) - (v(0, 0) + (v(0, 1) << 1) + v(0, 2));
    (sx, sy)
}
