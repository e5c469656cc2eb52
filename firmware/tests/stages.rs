//! Window former, subsampler, Sobel and DoG: golden vectors and properties against indexing.

use proptest::prelude::*;
use stereocal_firmware::fabric::dog::{dog, dog3};
use stereocal_firmware::fabric::sobel::sobel;
use stereocal_firmware::fabric::subsample::Subsampler;
use stereocal_firmware::fabric::window::{Window3, WindowFormer};

fn windows(img: &[u16], w: u16, h: u16) -> Vec<Window3<u16>> {
    let mut f: WindowFormer<u16, 64> = WindowFormer::new(0);
    f.start(w, h);
    let mut out = Vec::new();
    let mut i = 0;
    while !f.done() {
        assert!(
            i < img.len() + 2 * w as usize + 8,
            "window former did not drain"
        );
        if let Some(win) = f.clock(img.get(i).copied()) {
            out.push(win);
        }
        i += 1;
    }
    out
}

#[test]
fn golden_corner_windows_replicate() {
    // 3x2 image with values 10·y + x. Top-left window: rows clamp(-1..=1) = 0,0,1 and columns
    // clamp(-1..=1) = 0,0,1.
    let img = [0u16, 1, 2, 10, 11, 12];
    let w = windows(&img, 3, 2);
    assert_eq!(w.len(), 6);
    assert_eq!((w[0].x, w[0].y), (0, 0));
    assert_eq!(w[0].w, [[0, 0, 1], [0, 0, 1], [10, 10, 11]]);
    // Bottom-right window (2, 1): rows 0,1,1; columns 1,2,2.
    assert_eq!((w[5].x, w[5].y), (2, 1));
    assert_eq!(w[5].w, [[1, 2, 2], [11, 12, 12], [11, 12, 12]]);
}

#[test]
fn golden_sobel_and_dog() {
    // A ramp of 1 grey level per pixel to the right (Q8.8: 256 per pixel): Sx = 8·256, Sy = 0.
    let p = [[0u16, 256, 512], [0, 256, 512], [0, 256, 512]];
    assert_eq!(sobel(&p), (2048, 0));
    // Downward ramp: Sy positive (y points down).
    let q = [[0u16; 3], [256; 3], [512; 3]];
    assert_eq!(sobel(&q), (0, 2048));
    assert_eq!(dog(1000, 900), -100);
    assert_eq!(dog(0, 65535), i16::MAX, "saturates");
    assert_eq!(dog3([10, 20, 15, 15]), [10, -5, 0]);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn windows_equal_clamped_indexing(w in 1u16..20, h in 1u16..12, seed in any::<u16>()) {
        let n = w as usize * h as usize;
        let img: Vec<u16> = (0..n).map(|i| (i as u16).wrapping_mul(31).wrapping_add(seed)).collect();
        let got = windows(&img, w, h);
        prop_assert_eq!(got.len(), n);
        for (i, win) in got.iter().enumerate() {
            let (x, y) = ((i % w as usize) as isize, (i / w as usize) as isize);
            prop_assert_eq!((win.x as isize, win.y as isize), (x, y));
            for r in 0..3 {
                for c in 0..3 {
                    let yy = (y + r as isize - 1).clamp(0, h as isize - 1) as usize;
                    let xx = (x + c as isize - 1).clamp(0, w as isize - 1) as usize;
                    prop_assert_eq!(win.w[r][c], img[yy * w as usize + xx]);
                }
            }
        }
    }

    #[test]
    fn subsampler_equals_indexing(w in 1u16..30, h in 1u16..20) {
        let n = w as usize * h as usize;
        let img: Vec<u16> = (0..n as u16).collect();
        let mut s = Subsampler::new();
        s.start(w, h);
        let mut got = Vec::new();
        for i in 0..n + 2 {
            if let Some(v) = s.clock(img.get(i).copied()) {
                got.push(v);
            }
        }
        prop_assert!(s.done());
        let want: Vec<u16> = (0..h as usize).step_by(2)
            .flat_map(|y| (0..w as usize).step_by(2).map(move |x| (y * w as usize + x) as u16))
            .collect();
        prop_assert_eq!(got, want);
    }
}
