//! 3x3x3 extremum detector: the centre of the middle DoG image against its 26 neighbours
//! (8 in its own image, 9 in each adjacent one), with a contrast threshold.
//!
//! Only the middle DoG (scale index 1) can be tested: an octave has three DoG images. Border
//! pixels (first/last row and column) are never extrema: their neighbourhood is not real.
//! Comparisons are strict (a plateau is no extremum). Latency: one register, [`EXTREMA_LATENCY`].

/// Detector register latency in enabled clocks.
pub const EXTREMA_LATENCY: u32 = 1;

/// A DoG cube `c[s][y][x]`, `s` = DoG index 0..3, centre `c[1][1][1]`, Q8.8 grey levels.
pub type Cube = [[[i16; 3]; 3]; 3];

/// Whether the centre of `c` is a strict maximum above `threshold` or a strict minimum below
/// `-threshold` of the 27 samples.
pub fn is_extremum(c: &Cube, threshold: u16) -> bool {
    let v = c[1][1][1];
    let t = threshold as i32;
    let is_max = v as i32 > t;
    let is_min = (v as i32) < -t;
    if !is_max && !is_min {
        return false;
    }
    for (s, plane) in c.iter().enumerate() {
        for (y, row) in plane.iter().enumerate() {
            for (x, &n) in row.iter().enumerate() {
                if (s, y, x) == (1, 1, 1) {
                    continue;
                }
                if (is_max && n >= v) || (is_min && n <= v) {
                    return false;
                }
            }
        }
    }
    true
}
