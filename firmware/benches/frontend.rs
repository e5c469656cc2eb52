//! Whole 4-octave front end, both implementations, at 640x480 and 1264x372.
//! Criterion reports time per frame and, through `Throughput::Elements(pixels)`, pixels per
//! second; the ns/pixel figure for each is printed after the run.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::time::Instant;
use stereocal_firmware::fabric::{run_frame, Config, FastFrontEnd, FrontEnd, RegisterFrontEnd};

/// Smooth deterministic texture (no RNG dependency at bench time).
fn texture(w: usize, h: usize) -> Vec<u8> {
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            let v = 128.0
                + 60.0 * (x * 0.071).sin() * (y * 0.053).cos()
                + 40.0 * ((x + 2.0 * y) * 0.173).sin();
            v.clamp(0.0, 255.0) as u8
        })
        .collect()
}

fn frame<F: FrontEnd>(fe: &mut F, cfg: &Config, img: &[u8]) -> usize {
    let mut n = 0usize;
    let mut m = 0usize;
    // The consumer touches every item (as the stream engine would).
    run_frame(fe, cfg, img, &mut |p| n += p.len(), &mut |s| {
        m += s.magnitude.iter().map(|&m| m as usize).sum::<usize>()
    })
    .expect("frame");
    n + m
}

fn ns_per_pixel<F: FrontEnd>(fe: &mut F, cfg: &Config, img: &[u8], reps: u32) -> f64 {
    frame(fe, cfg, img);
    let t = Instant::now();
    for _ in 0..reps {
        std::hint::black_box(frame(fe, cfg, img));
    }
    t.elapsed().as_nanos() as f64 / reps as f64 / img.len() as f64
}

fn bench(c: &mut Criterion) {
    let mut fast = Box::new(FastFrontEnd::<1280, 640, 320, 160>::new());
    let mut reg = Box::new(RegisterFrontEnd::<1280, 640, 320, 160>::new());
    let mut g = c.benchmark_group("frontend");
    g.sample_size(10);
    let sizes = [(640u16, 480u16), (1264, 372)];
    for &(w, h) in &sizes {
        let cfg = Config::new(w, h);
        let img = texture(w as usize, h as usize);
        g.throughput(Throughput::Elements(img.len() as u64));
        g.bench_with_input(
            BenchmarkId::new("fast", format!("{w}x{h}")),
            &img,
            |b, img| b.iter(|| frame(&mut *fast, &cfg, img)),
        );
        g.bench_with_input(
            BenchmarkId::new("register", format!("{w}x{h}")),
            &img,
            |b, img| b.iter(|| frame(&mut *reg, &cfg, img)),
        );
    }
    g.finish();
    if std::env::args().any(|a| a == "--profile-time") {
        return;
    }
    for &(w, h) in &sizes {
        let cfg = Config::new(w, h);
        let img = texture(w as usize, h as usize);
        let f = ns_per_pixel(&mut *fast, &cfg, &img, 20);
        let r = ns_per_pixel(&mut *reg, &cfg, &img, 2);
        println!("ns/pixel {w}x{h}: fast {f:.2}, register-level {r:.1}");
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
