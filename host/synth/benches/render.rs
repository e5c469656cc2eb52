//! Render speed of the ground-truth renderer: one 640x480 camera image of the road scene with
//! the default adaptive 4x4 supersampling and sensor noise (target ≤ 30 ms on 2 cores), a
//! whole stereo pair, and the other frame sizes the demo and real data use.

use criterion::{criterion_group, criterion_main, Criterion};
use stereocal_synth::{SceneKind, Sequence, SequenceConfig};

fn road(width: u32, height: u32) -> Sequence {
    let config = SequenceConfig {
        width,
        height,
        frames: 300,
        ..SequenceConfig::for_scene(SceneKind::Road)
    };
    match Sequence::builtin(SceneKind::Road, config) {
        Ok(seq) => seq,
        Err(e) => panic!("bench sequence: {e}"),
    }
}

fn render(c: &mut Criterion) {
    let mut group = c.benchmark_group("synth");
    group.sample_size(20);
    for (w, h) in [(640, 480), (752, 480), (1264, 372)] {
        let seq = road(w, h);
        let mut i = 0usize;
        // A stereo pair per iteration, cycling through the sequence so every kind of view counts.
        group.bench_function(format!("road_pair_{w}x{h}"), |b| {
            b.iter(|| {
                i = (i + 37) % seq.len();
                seq.frame(i).map(|f| f.images.is_some())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, render);
criterion_main!(benches);
