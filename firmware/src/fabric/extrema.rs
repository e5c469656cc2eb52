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
    // The 26 neighbours are the flattened cube without its centre (index 13); their maximum
    // and minimum decide both tests at once, with no data-dependent branch.
    let all = c.as_flattened().as_flattened();
    let (before, after) = all.split_at(13.min(all.len()));
    let neighbours = before.iter().chain(after.iter().skip(1));
    let (hi, lo) = neighbours.fold((i16::MIN, i16::MAX), |(hi, lo), &n| (hi.max(n), lo.min(n)));
    (v as i32 > t && v > hi) || ((v as i32) < -t && v < lo)
}
