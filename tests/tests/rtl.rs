//! Co-simulation of the RTL front end (`hdl-interface/rtl`, top `sc_frontend`) against the
//! register-level model: every observation port on every clock and the clocks to `done` must
//! be identical (`stereocal_hil::rtl`). Run with `cargo test --release -p stereocal-hil rtl`.
//!
//! Without Verilator every test prints a loud SKIPPED line and passes, except under `CI=true`
//! (where the build already fails).

// Without the RTL model only the skip path is compiled.
#![cfg_attr(
    not(rtl_sim),
    allow(dead_code, unused_imports, clippy::needless_return)
)]

use stereocal_firmware::fabric::Config;
use stereocal_hil::rng::Rng;

/// Whether the RTL model exists; prints the loud skip line when it does not.
fn rtl_available(test: &str) -> bool {
    match stereocal_hil::rtl::SKIP {
        None => true,
        Some(why) => {
            stereocal_hil::skip(test, &format!("RTL co-simulation not built: {why}"));
            false
        }
    }
}

/// A co-simulation test: without the RTL model it prints the loud skip line and passes
/// (failing under `CI=true`); the body only exists where the model was built.
macro_rules! rtl_test {
    ($name:ident, $body:block) => {
        #[test]
        fn $name() {
            if !rtl_available(stringify!($name)) {
                return;
            }
            #[cfg(rtl_sim)]
            $body
        }
    };
}

fn noise(w: usize, h: usize, seed: u64) -> Vec<u8> {
    let mut r = Rng::new(seed);
    (0..w * h).map(|_| r.bits() as u8).collect()
}

/// Noise with structure ([`Rng::blob_image`]) from `seed`.
fn blobs(w: usize, h: usize, seed: u64) -> Vec<u8> {
    Rng::new(seed).blob_image(w, h)
}

fn checkerboard(w: usize, h: usize, cell: usize) -> Vec<u8> {
    (0..w * h)
        .map(|i| {
            if ((i % w) / cell + (i / w) / cell) % 2 == 0 {
                0
            } else {
                255
            }
        })
        .collect()
}

fn impulses(w: usize, h: usize, background: u8, step: usize) -> Vec<u8> {
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if x % step == step / 2 && y % step == step / 2 {
                255 - background
            } else {
                background
            }
        })
        .collect()
}

/// Even-sized bright squares on black: their centres fall between pixels, so DoG maxima are
/// plateaus of equal samples (no extremum by the strict comparison).
fn even_squares(w: usize, h: usize, side: usize, step: usize) -> Vec<u8> {
    (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            if x % step < side && y % step < side {
                200
            } else {
                20
            }
        })
        .collect()
}

fn config(w: u16, h: u16, octaves: u8) -> Config {
    Config {
        octaves,
        ..Config::new(w, h)
    }
}

#[cfg(rtl_sim)]
mod sim {
    use super::*;
    use stereocal_firmware::fabric::geometry::octave_dims;
    use stereocal_firmware::fabric::RegisterFrontEnd;
    use stereocal_hil::rtl::{
        back_to_back, cosim_clocks, cosim_frame, FrameRun, RtlFrontEnd, StreamCounts,
    };

    /// The two models, reused frame after frame (every frame starts with `start`).
    pub struct Bench {
        model: Box<RegisterFrontEnd>,
        rtl: RtlFrontEnd,
    }

    impl Bench {
        pub fn new() -> Self {
            Self::with_power_up(0)
        }

        /// The RTL's registers and memories at random power-up values from `seed` (0: zero).
        pub fn with_power_up(seed: u32) -> Self {
            Self {
                model: Box::new(RegisterFrontEnd::new()),
                rtl: RtlFrontEnd::with_power_up(seed),
            }
        }

        /// `start`, then exactly `stimulus.len()` clocks (a frame left unfinished).
        pub fn partial(&mut self, name: &str, cfg: &Config, stim: &[Option<u8>]) -> StreamCounts {
            cosim_clocks(&mut self.model, &mut self.rtl, cfg, stim)
                .unwrap_or_else(|m| panic!("rtl {name} (unfinished frame): first mismatch at {m}"))
        }

        /// One frame with pixels back to back, or with `stimulus` when given.
        pub fn frame(
            &mut self,
            name: &str,
            cfg: &Config,
            img: &[u8],
            stimulus: Option<Vec<Option<u8>>>,
        ) -> FrameRun {
            let stim = stimulus.unwrap_or_else(|| back_to_back(img));
            let t = std::time::Instant::now();
            match cosim_frame(&mut self.model, &mut self.rtl, cfg, &stim) {
                Ok(run) => {
                    eprintln!(
                        "rtl {name}: {}x{} octaves {} sobel_scale {} edge {} thr {} off {}: \
                         identical, done after {} clocks ({:.2} s); points {:?}, sobel {:?}",
                        cfg.width,
                        cfg.height,
                        cfg.octaves,
                        cfg.sobel_scale,
                        cfg.edge_ratio,
                        cfg.contrast_threshold,
                        cfg.max_offset,
                        run.clocks_to_done,
                        t.elapsed().as_secs_f64(),
                        run.counts.points,
                        run.counts.sobel,
                    );
                    // One G3, DoG and Sobel sample per pixel of every configured octave, one
                    // subsample per pixel of the next (both sides, as they are identical).
                    let c = &run.counts;
                    for k in 0..4u8 {
                        let (w, h) = octave_dims(cfg.width, cfg.height, k);
                        let on = k < cfg.octaves;
                        let n = if on { w as u64 * h as u64 } else { 0 };
                        let (w1, h1) = octave_dims(cfg.width, cfg.height, k + 1);
                        let next = if k + 1 < cfg.octaves {
                            w1 as u64 * h1 as u64
                        } else {
                            0
                        };
                        let k = k as usize;
                        assert_eq!(
                            [c.g3[k], c.dog[k], c.sobel[k]],
                            [n; 3],
                            "{name}: octave {k}"
                        );
                        if next > 0 {
                            assert_eq!(c.sub[k], next, "{name}: subsamples of octave {k}");
                        }
                    }
                    run
                }
                Err(m) => panic!(
                    "rtl {name} ({}x{} octaves {} sobel_scale {} edge {} thr {} off {}): \
                     first mismatch at {m}",
                    cfg.width,
                    cfg.height,
                    cfg.octaves,
                    cfg.sobel_scale,
                    cfg.edge_ratio,
                    cfg.contrast_threshold,
                    cfg.max_offset,
                ),
            }
        }
    }
}

rtl_test!(rtl_random_images, {
    let mut b = sim::Bench::new();
    // (w, h, octaves, sobel_scale, edge_ratio, threshold, max_offset), seed
    let cases = [
        ((64, 48, 4, 1, 10, 256, 4096), 1),
        ((37, 29, 4, 0, 0, 0, 8191), 2),
        ((50, 41, 3, 2, 10, 64, 2048), 3),
        ((23, 70, 2, 3, 0, 1024, 4096), 4),
        ((96, 64, 4, 3, 10, 128, 8191), 5),
        ((31, 17, 1, 1, 0, 256, 1000), 6),
        ((120, 33, 4, 2, 0, 256, 4096), 7),
        ((45, 45, 3, 0, 10, 512, 0), 8),
    ];
    let mut points = 0;
    for ((w, h, octaves, sobel_scale, edge_ratio, thr, off), seed) in cases {
        let cfg = Config {
            sobel_scale,
            edge_ratio,
            contrast_threshold: thr,
            max_offset: off,
            ..config(w, h, octaves)
        };
        let img = if seed % 2 == 0 {
            noise(w as usize, h as usize, seed)
        } else {
            blobs(w as usize, h as usize, seed)
        };
        let run = b.frame(&format!("random seed {seed}"), &cfg, &img, None);
        points += run.counts.points.iter().sum::<u64>();
    }
    assert!(points > 0, "no point in any random image");
});

rtl_test!(rtl_random_configurations, {
    // Sizes, octave counts and every other setting drawn at random (valid ones only).
    let mut b = sim::Bench::new();
    let mut r = Rng::new(0x5eed);
    let mut points = 0;
    let mut frames = 0;
    while frames < 40 {
        let (w, h) = (3 + r.below(160) as u16, 3 + r.below(90) as u16);
        let cfg = Config {
            octaves: 1 + r.below(4) as u8,
            contrast_threshold: [0, 32, 128, 256, 700, 4000][r.below(6) as usize],
            edge_ratio: [0, 1, 5, 10, 12, 255][r.below(6) as usize],
            sobel_scale: r.below(4) as u8,
            max_offset: r.below(8192) as u16,
            ..Config::new(w, h)
        };
        if cfg.validate([1280, 640, 320, 160]).is_err() {
            continue;
        }
        let seed = r.bits();
        let img = match seed % 3 {
            0 => noise(w as usize, h as usize, seed),
            _ => blobs(w as usize, h as usize, seed),
        };
        let run = b.frame(&format!("random configuration {frames}"), &cfg, &img, None);
        points += run.counts.points.iter().sum::<u64>();
        frames += 1;
    }
    assert!(points > 0, "no point in any random configuration");
});

rtl_test!(rtl_random_with_idle_clocks, {
    // Pixels with random gaps (clocks without a pixel) inside rows and between rows.
    let mut b = sim::Bench::new();
    for (w, h, octaves, seed) in [(40u16, 36u16, 4u8, 11u64), (29, 21, 3, 12)] {
        let img = blobs(w as usize, h as usize, seed);
        let mut r = Rng::new(seed);
        let mut stim = Vec::new();
        for &p in &img {
            for _ in 0..[0, 0, 0, 1, 2, 5][r.below(6) as usize] {
                stim.push(None);
            }
            stim.push(Some(p));
        }
        let cfg = config(w, h, octaves);
        let run = b.frame(&format!("idle clocks seed {seed}"), &cfg, &img, Some(stim));
        assert!(run.counts.points.iter().sum::<u64>() > 0, "no point");
    }
});

rtl_test!(rtl_configuration_sweep, {
    // Every octave count x Sobel scale x edge ratio, thresholds and offsets cycling.
    let mut b = sim::Bench::new();
    let thresholds = [0u16, 64, 256, 1024, 65535];
    let offsets = [0u16, 1000, 4096, 8191, 2048, 7000];
    let mut i = 0usize;
    let mut points = 0;
    for octaves in 1..=4u8 {
        for sobel_scale in 0..=3u8 {
            for edge_ratio in [0u8, 10] {
                let (w, h) = (40 + 7 * (i % 5) as u16, 34 + 5 * (i % 3) as u16);
                let cfg = Config {
                    sobel_scale,
                    edge_ratio,
                    contrast_threshold: thresholds[i % thresholds.len()],
                    max_offset: offsets[i % offsets.len()],
                    ..config(w, h, octaves)
                };
                let img = blobs(w as usize, h as usize, 100 + i as u64);
                let run = b.frame(&format!("sweep {i}"), &cfg, &img, None);
                points += run.counts.points.iter().sum::<u64>();
                i += 1;
            }
        }
    }
    assert!(points > 0, "no point in the sweep");
});

rtl_test!(rtl_aborted_frames_and_power_up, {
    // Registers and memories power up random; frames are abandoned part way (in the
    // middle of the image, during the flush) and restarted with another size: `start`
    // must leave nothing behind that reaches an output.
    for seed in [1u32, 77] {
        let mut b = sim::Bench::with_power_up(seed);
        let (w, h) = (52u16, 44u16);
        let img = blobs(w as usize, h as usize, seed as u64);
        let cfg = config(w, h, 4);
        for cut in [0usize, 1, 700, (w as usize * h as usize)] {
            let mut stim = back_to_back(&img[..cut]);
            stim.extend(std::iter::repeat_n(None, 150 * (seed as usize % 3)));
            b.partial("aborted", &cfg, &stim);
        }
        let cfg2 = Config {
            sobel_scale: 2,
            ..config(37, 61, 3)
        };
        let img2 = noise(37, 61, seed as u64 + 5);
        b.frame("after aborted frames", &cfg2, &img2, None);
        b.frame("random power-up", &cfg, &img, None);
    }
});

#[cfg(rtl_sim)]
use stereocal_hil::rtl::back_to_back;

rtl_test!(rtl_edge_cases, {
    let mut b = sim::Bench::new();
    let (w, h) = (48usize, 40usize);
    let cases: Vec<(&str, Vec<u8>, u8)> = vec![
        ("all black", vec![0; w * h], 1),
        ("all white", vec![255; w * h], 0),
        ("checkerboard 1", checkerboard(w, h, 1), 1),
        ("checkerboard 4", checkerboard(w, h, 4), 2),
        ("impulses on black", impulses(w, h, 0, 9), 1),
        ("impulses on white", impulses(w, h, 255, 9), 3),
        ("2x2 squares", even_squares(w, h, 2, 9), 1),
        ("4x4 squares", even_squares(w, h, 4, 12), 0),
    ];
    for (name, img, sobel_scale) in cases {
        for edge_ratio in [10, 0] {
            let cfg = Config {
                sobel_scale,
                edge_ratio,
                ..config(w as u16, h as u16, 4)
            };
            let run = b.frame(name, &cfg, &img, None);
            if name.starts_with("all") {
                assert_eq!(run.counts.points, [0; 4], "{name}: points on a flat image");
            }
            if name.starts_with("impulses") {
                // A one-pixel impulse is finer than octave 0's scales: its blobs are
                // octave 1 extrema (one per impulse at this spacing).
                assert!(run.counts.points[1] > 0, "{name}: no point at an impulse");
            }
        }
    }
});

rtl_test!(rtl_maximum_width, {
    let mut b = sim::Bench::new();
    let (w, h) = (1280u16, 20u16);
    let img = blobs(w as usize, h as usize, 21);
    let run = b.frame("maximum width", &config(w, h, 4), &img, None);
    assert!(run.counts.points.iter().sum::<u64>() > 0, "no point");
    let cfg = Config {
        sobel_scale: 0,
        ..config(w, 3, 1)
    };
    b.frame(
        "maximum width, 3 rows",
        &cfg,
        &noise(w as usize, 3, 22),
        None,
    );
});

rtl_test!(rtl_minimum_sizes, {
    let mut b = sim::Bench::new();
    // The smallest frames Config::validate accepts per octave count (last octave 3x3),
    // square and with one side at its minimum.
    for (octaves, min) in [(1u8, 3u16), (2, 5), (3, 9), (4, 17)] {
        for (w, h) in [(min, min), (min, 2 * min + 1), (2 * min + 3, min)] {
            let cfg = config(w, h, octaves);
            assert!(cfg.validate([1280, 640, 320, 160]).is_ok());
            let smaller = config(w - 1, h, octaves);
            if w == min {
                assert!(smaller.validate([1280, 640, 320, 160]).is_err());
            }
            for seed in [31u64, 32] {
                let img = noise(w as usize, h as usize, seed + w as u64 * 97 + h as u64);
                b.frame(&format!("minimum {octaves} octaves"), &cfg, &img, None);
            }
        }
    }
});

/// A centred `w` x `h` crop of a real photograph under ../shared/data/real, read at run time
/// (`None`, loudly, when the data set is absent outside CI).
fn real_crop(rel: &str, w: usize, h: usize) -> Option<Vec<u8>> {
    let path = stereocal_hil::real_data_or_skip("rtl_real_images")?.join(rel);
    if !path.exists() {
        stereocal_hil::skip("rtl_real_images", &format!("{} not found", path.display()));
        return None;
    }
    let path = path.display().to_string();
    let img = image::open(&path).expect("real image decodes").into_luma8();
    let (iw, ih) = (img.width() as usize, img.height() as usize);
    assert!(iw >= w && ih >= h, "{path} smaller than the crop");
    let (x0, y0) = ((iw - w) / 2, (ih - h) / 2);
    let raw = img.into_raw();
    Some(
        (0..h)
            .flat_map(|y| {
                raw[(y0 + y) * iw + x0..(y0 + y) * iw + x0 + w]
                    .iter()
                    .copied()
            })
            .collect(),
    )
}

#[test]
fn rtl_real_images() {
    if !rtl_available("rtl_real_images") {
        return;
    }
    // ETH3D two-view "terrace" (713x434) and a EuRoC frame (752x480).
    let cases = [
        ("eth3d_two_view/terrace/im0.png", 640usize, 400usize, 1u8),
        ("euroc_pairs/sf0_left.png", 752, 200, 0),
    ];
    for (rel, w, h, sobel_scale) in cases {
        let Some(img) = real_crop(rel, w, h) else {
            return;
        };
        #[cfg(rtl_sim)]
        {
            let mut b = sim::Bench::new();
            let cfg = Config {
                sobel_scale,
                ..config(w as u16, h as u16, 4)
            };
            let run = b.frame(rel, &cfg, &img, None);
            for k in 0..3 {
                assert!(run.counts.points[k] > 0, "no point in octave {k} of {rel}");
            }
            // Posterized to 4 grey levels: wide flat areas, equal DoG samples, plateaus.
            let (w2, h2) = (w.min(320), h.min(200));
            let crop: Vec<u8> = (0..h2)
                .flat_map(|y| img[y * w..y * w + w2].iter().map(|&p| (p & 0xc0) | 0x20))
                .collect();
            let cfg = Config {
                contrast_threshold: 64,
                ..config(w2 as u16, h2 as u16, 3)
            };
            let run = b.frame(&format!("{rel} posterized"), &cfg, &crop, None);
            assert!(run.counts.points[0] > 0, "no point in posterized {rel}");
        }
        #[cfg(not(rtl_sim))]
        let _ = (img, sobel_scale);
    }
}
