//! Row and column stages: golden vectors and a property test against a direct 2-D convolution
//! with the outer product of the same quantized taps, rounded once.

use proptest::prelude::*;
use stereocal_firmware::fabric::convolver::{ColumnConvolver, RowConvolver};
use stereocal_firmware::fabric::taps::{GAUSS_LUTS, GAUSS_TAPS};

/// Runs `img` (Q8.8) through a row stage and a column stage of kernel `k`, flushing with
/// phantom clocks, and returns the `w·h` outputs in order.
fn stages(img: &[u16], w: u16, h: u16, k: usize) -> Vec<u16> {
    let mut row = RowConvolver::new(GAUSS_LUTS[k]);
    let mut col: ColumnConvolver<64> = ColumnConvolver::new(GAUSS_LUTS[k]);
    row.start(w, h);
    col.start(w, h);
    let mut out = Vec::new();
    let n = w as usize * h as usize;
    let mut i = 0;
    while out.len() < n {
        assert!(i < n + 4 * w as usize + 16, "stage did not drain");
        let inp = img.get(i).copied();
        if let Some(v) = col.clock(row.clock(inp)) {
            out.push(v);
        }
        i += 1;
    }
    out
}

/// Plain reference: a direct 2-D convolution with the 5x5 kernel `t[i]·t[j]` (Q0.20), replicated
/// border, rounded once (half up).
fn reference(img: &[u16], w: usize, h: usize, k: usize) -> Vec<u16> {
    let t = GAUSS_TAPS[k];
    let at = |x: isize, y: isize| {
        let (x, y) = (x.clamp(0, w as isize - 1), y.clamp(0, h as isize - 1));
        img[y as usize * w + x as usize] as u64
    };
    let mut out = vec![0u16; w * h];
    for y in 0..h {
        for x in 0..w {
            let mut s = 0u64;
            for (i, &ti) in t.iter().enumerate() {
                for (j, &tj) in t.iter().enumerate() {
                    let v = at(x as isize + j as isize - 2, y as isize + i as isize - 2);
                    s += ti as u64 * tj as u64 * v;
                }
            }
            out[y * w + x] = ((s + (1 << 19)) >> 20) as u16;
        }
    }
    out
}

#[test]
fn flat_image_stays_flat() {
    // Unity DC gain: every output of a flat 200.5 grey image is exactly 200.5 (0xC880).
    let img = vec![0xC880u16; 9 * 7];
    assert!(stages(&img, 9, 7, 0).iter().all(|&v| v == 0xC880));
}

#[test]
fn impulse_gives_the_outer_product_of_the_taps() {
    // A single 255.0 pixel in the middle of a 9x9 black image: output (x, y) is
    // round(255·256·t[x-2]·t[y-2] / 2^20), zero outside the 5x5 support.
    let mut img = vec![0u16; 81];
    img[4 * 9 + 4] = 255 << 8;
    let out = stages(&img, 9, 9, 1);
    let t = GAUSS_TAPS[1];
    for y in 0..9 {
        for x in 0..9 {
            let (dx, dy) = (x as isize - 4, y as isize - 4);
            let expect = if dx.abs() <= 2 && dy.abs() <= 2 {
                let p = (255u64 << 8) * t[(dx + 2) as usize] as u64 * t[(dy + 2) as usize] as u64;
                ((p + (1 << 19)) >> 20) as u16
            } else {
                0
            };
            assert_eq!(out[y * 9 + x], expect, "({x}, {y})");
        }
    }
    // Centre by hand for G1 (taps 18 229 530 229 18): 65280·530·530 / 2^20 = 17487.75 -> 17488.
    // (Rounding after each pass would give the same here: 33787.5 -> 33788, then 17487.8.)
    assert_eq!(out[40], 17488);
}

#[test]
fn border_is_replicated() {
    // A 1-pixel bright left column on a 6x5 image: with replication the output at x = 0 sees
    // the bright pixel under taps -2, -1 and 0: (t0 + t1 + t2) / 1024 of it.
    let mut img = vec![0u16; 30];
    for y in 0..5 {
        img[y * 6] = 100 << 8;
    }
    let out = stages(&img, 6, 5, 2);
    let t = GAUSS_TAPS[2];
    let frac = (t[0] + t[1] + t[2]) as u32;
    let expect = (((100u32 << 8) * frac + 512) >> 10) as u16; // column filter of a flat column
    for y in 0..5 {
        assert_eq!(out[y * 6], expect, "row {y}");
        assert_eq!(out[y * 6 + 3], 0, "x = 3 is outside the support");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn stages_equal_a_direct_2d_convolution(
        w in 1u16..40, h in 1u16..24, k in 0usize..4, seed in any::<u64>()
    ) {
        let n = w as usize * h as usize;
        let mut s = seed;
        let img: Vec<u16> = (0..n).map(|_| { s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407); (s >> 48) as u16 }).collect();
        prop_assert_eq!(stages(&img, w, h, k), reference(&img, w as usize, h as usize, k));
    }
}
