//! Octave geometry: the size of each octave's image, which a receiver needs to place the
//! octave-local coordinates of points, Sobel rows and patches.
//!
//! `FrameStart` carries only octave 0's size and the octave count; every other size follows
//! from this rule, so sender and receiver share it here rather than on the wire.

/// Size of octave `k` for a `width` x `height` octave 0: each octave keeps the even columns
/// and the even rows of the one before, so sizes round up (`(n + 1) / 2`).
pub const fn octave_dims(width: u16, height: u16, k: u8) -> (u16, u16) {
    let (mut w, mut h, mut i) = (width, height, 0);
    while i < k {
        w = w.div_ceil(2);
        h = h.div_ceil(2);
        i += 1;
    }
    (w, h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_round_up() {
        assert_eq!(octave_dims(640, 480, 0), (640, 480));
        assert_eq!(octave_dims(640, 480, 3), (80, 60));
        assert_eq!(octave_dims(1241, 376, 1), (621, 188));
        assert_eq!(octave_dims(1241, 376, 3), (156, 47));
        assert_eq!(octave_dims(1, 1, 5), (1, 1));
    }
}
