//! Row and column stages: golden vectors and a property test against a direct separable
//! convolution with the same quantized taps and the same rounding after each pass.

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

/// Plain reference: separable, replicated border, round after each pass.
fn reference(img: &[u16], w: usize, h: usize, k: usize) -> Vec<u16> {
    let t = GAUSS_TAPS[k];
    let pass = |get: &dyn Fn(isize) -> u16| -> u16 {
        let s: u32 = (0..5)
            .map(|j| t[j] as u32 * get(j as isize - 2) as u32)
            .sum();
        ((s + 512) >> 10) as u16
    };
    let mut r = vec![0u16; w * h];
    for y in 0..h {
        for x in 0..w {
            r[y * w + x] =
                pass(&|d| img[y * w + (x as isize + d).clamp(0, w as isize - 1) as usize]);
        }
    }
    let mut c = vec![0u16; w * h];
    for y in 0..h {
        for x in 0..w {
            c[y * w + x] = pass(&|d| r[(y as isize + d).clamp(0, h as isize - 1) as usize * w + x]);
        }
    }
    c
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
    // round(round(255·256·t[x-2] / 1024) · t[y-2] / 1024), zero outside the 5x5 support.
    let mut img = vec![0u16; 81];
    img[4 * 9 + 4] = 255 << 8;
    let out = stages(&img, 9, 9, 1);
    let t = GAUSS_TAPS[1];
    for y in 0..9 {
        for x in 0..9 {
            let (dx, dy) = (x as isize - 4, y as isize - 4);
            let expect = if dx.abs() <= 2 && dy.abs() <= 2 {
                let r = ((255u32 << 8) * t[(dx + 2) as usize] as u32 + 512) >> 10;
                ((r * t[(dy + 2) as usize] as u32 + 512) >> 10) as u16
            } else {
                0
            };
            assert_eq!(out[y * 9 + x], expect, "({x}, {y})");
        }
    }
    // Centre by hand for G1 (taps 18 229 530 229 18): 65280·530/1024 = 33787.5 -> 33788,
    // then 33788·530/1024 = 17487.8 -> 17488.
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
    fn stages_equal_direct_separable_convolution(
        w in 1u16..40, h in 1u16..24, k in 0usize..4, seed in any::<u64>()
    ) {
        let n = w as usize * h as usize;
        let mut s = seed;
        let img: Vec<u16> = (0..n).map(|_| { s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407); (s >> 48) as u16 }).collect();
        prop_assert_eq!(stages(&img, w, h, k), reference(&img, w as usize, h as usize, k));
    }
}
