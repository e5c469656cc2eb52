//! Difference of Gaussians: `D_i = G_{i+1} - G_i` for i = 0, 1, 2.
//!
//! Width: the scale images are Q8.8 `u16`; their difference needs 17 bits, but a difference of
//! adjacent cascade levels never comes near ±128 grey levels, so the fabric stores DoG samples as
//! `i16` Q8.8 (saturating at ±127.996, which both implementations apply identically).
//! Latency: one register, [`DOG_LATENCY`].

/// DoG register latency in enabled clocks.
pub const DOG_LATENCY: u32 = 1;

/// `b - a` saturated to `i16` (Q8.8 grey levels).
#[inline]
pub fn dog(a: u16, b: u16) -> i16 {
    let d = b as i32 - a as i32;
    d.clamp(i16::MIN as i32, i16::MAX as i32) as i16
}

/// The three DoG samples of one pixel from its four scale samples `g = [G0, G1, G2, G3]`.
#[inline]
pub fn dog3(g: [u16; 4]) -> [i16; 3] {
    [dog(g[0], g[1]), dog(g[1], g[2]), dog(g[2], g[3])]
}
