//! The fast path equals the register-level model bit for bit: same points, same Sobel pixels,
//! in the same FIFO order, on random and real images of several sizes.

mod common;

use common::{fit, noise_image, random_image, real_image, run};
use stereocal_firmware::fabric::{Config, FastFrontEnd, RegisterFrontEnd};

type Reg = RegisterFrontEnd<1280, 640, 320, 160>;
type Fast = FastFrontEnd<1280, 640, 320, 160>;

fn check(img: &[u8], cfg: &Config, reg: &mut Reg, fast: &mut Fast) -> usize {
    let a = run(reg, cfg, img);
    let b = run(fast, cfg, img);
    assert_eq!(reg.align_errors(), 0, "alignment FIFO fault");
    assert_eq!(fast.overruns(), 0, "fast path items without room to wait");
    assert_eq!(
        a.overflow.points + a.overflow.sobel,
        0,
        "register model overflowed"
    );
    assert_eq!(
        b.overflow.points + b.overflow.sobel,
        0,
        "fast path overflowed"
    );
    let (w, h) = (cfg.width as usize, cfg.height as usize);
    let expect_sobel: usize = (0..cfg.octaves)
        .map(|k| {
            let (w, h) = stereocal_firmware::fabric::geometry::octave_dims(w as u16, h as u16, k);
            w as usize * h as usize
        })
        .sum();
    assert_eq!(a.sobel.len(), expect_sobel, "register model Sobel count");
    assert_eq!(b.sobel.len(), expect_sobel, "fast path Sobel count");
    assert!(a.sobel == b.sobel, "Sobel streams differ ({w}x{h})");
    assert_eq!(a.points, b.points, "point streams differ ({w}x{h})");
    a.points.len()
}

fn boxed() -> (Box<Reg>, Box<Fast>) {
    (Box::new(Reg::new()), Box::new(Fast::new()))
}

#[test]
fn small_and_odd_sizes_random() {
    let (mut reg, mut fast) = boxed();
    let sizes = [
        (24, 24, 1),
        (37, 23, 2),
        (45, 31, 3),
        (64, 48, 4),
        (99, 61, 4),
        (26, 26, 3),
        (130, 7, 1),
    ];
    for (i, &(w, h, oct)) in sizes.iter().enumerate() {
        for seed in 0..2 {
            let mut cfg = Config::new(w, h);
            cfg.octaves = oct;
            cfg.sobel_scale = (i as u8 + seed as u8) % 4;
            let img = if seed == 0 {
                random_image(w as usize, h as usize, i as u64)
            } else {
                noise_image(w as usize, h as usize, i as u64)
            };
            check(&img, &cfg, &mut reg, &mut fast);
        }
    }
}

#[test]
fn medium_random_finds_points() {
    let (mut reg, mut fast) = boxed();
    let cfg = Config::new(160, 120);
    let n = check(&random_image(160, 120, 7), &cfg, &mut reg, &mut fast);
    assert!(n > 5, "only {n} points on a textured 160x120 image");
}

/// Real-size frames: 640x480, 752x480 and 1264x372, each on random texture and on a real
/// image (when `../shared/data` is present; a loud skip otherwise, a failure under CI=true).
/// All three sizes run in every build profile.
#[test]
fn real_sizes_random_and_real_images() {
    let (mut reg, mut fast) = boxed();
    let src = real_image();
    for &(w, h) in &[(640u16, 480u16), (752, 480), (1264, 372)] {
        let (wu, hu) = (w as usize, h as usize);
        let mut images = vec![("random", random_image(wu, hu, w as u64))];
        if let Some((img, iw, ih)) = &src {
            images.push(("real", fit(img, *iw, *ih, wu, hu)));
        }
        for (kind, img) in images {
            let n = check(&img, &Config::new(w, h), &mut reg, &mut fast);
            eprintln!("{w}x{h} {kind}: {n} points, streams identical");
            assert!(n > 20, "{w}x{h} {kind}: only {n} points");
        }
    }
}
