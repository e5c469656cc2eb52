//! The experiments end to end on a few frames: the per-octave counts the octave experiment
//! (thesis fig. 5.3) is built from add up to the match counts, and the experiments leave their
//! tables and figures.

use stereocal::session::SessionConfig;
use stereocal_hdl::regs::MAX_OCTAVES;
use stereocal_synth::{SceneKind, Sequence, SequenceConfig, TrajectoryKind};
use stereocal_tools::eval::evaluate;
use stereocal_tools::experiments::{Experiment, Outcome, Settings};

#[test]
fn per_octave_counts_sum_to_the_matches() {
    let mut config = SequenceConfig::for_scene(SceneKind::Road);
    config.frames = 3;
    config.trajectory = TrajectoryKind::Fixed;
    let sequence = Sequence::builtin(SceneKind::Road, config).unwrap();
    let (records, _) = evaluate(&sequence, SessionConfig::default(), &mut |_| {}).unwrap();
    let estimated: Vec<_> = records.iter().filter(|r| r.status.has_estimate()).collect();
    assert!(!estimated.is_empty());
    // Points from every octave: the coarser ones are not built for nothing.
    for octave in 1..MAX_OCTAVES as usize {
        let matched: usize = estimated.iter().map(|r| r.matches_per_octave[octave]).sum();
        assert!(
            matched > 0,
            "octave {octave} matched nothing: {estimated:?}"
        );
    }
    for r in estimated {
        assert_eq!(r.matches_per_octave.len(), MAX_OCTAVES as usize, "{r:?}");
        assert_eq!(
            r.matches_per_octave.iter().sum::<usize>(),
            r.matches,
            "{r:?}"
        );
        // Every match has a left keypoint: no octave can hold more matches than keypoints.
        for (m, k) in r.matches_per_octave.iter().zip(&r.keypoints_per_octave) {
            assert!(m <= k, "{r:?}");
        }
        assert!(r.matches_per_octave[0] > 0, "{r:?}");
    }
}

fn run(e: Experiment, frames: usize) -> (Outcome, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let settings = Settings {
        frames: Some(frames),
        seed: 0,
    };
    let outcome = e.run(settings, dir.path(), &mut |_| {}).unwrap();
    for path in &outcome.written {
        assert!(path.starts_with(dir.path()), "{}", path.display());
        assert!(
            std::fs::metadata(path).unwrap().len() > 0,
            "{}",
            path.display()
        );
    }
    (outcome, dir)
}

#[test]
fn octaves_experiment_shares_add_up() {
    let (outcome, dir) = run(Experiment::Octaves, 2);
    let table = &outcome.tables[0];
    assert_eq!(
        table.cell("all", 2),
        Some("100.0 %"),
        "{}",
        table.markdown()
    );
    for name in ["results.csv", "octaves.png"] {
        assert!(dir.path().join(name).is_file(), "{name}");
    }
}

#[test]
fn kernel_experiment_marks_the_fabric_size() {
    let (outcome, dir) = run(Experiment::Kernel, 1);
    let table = &outcome.tables[0];
    let max_err = |key: &str| -> f64 { table.cell(key, 6).unwrap().parse().unwrap() };
    // On a rendered road frame the cut-off tails dominate for 3 taps and vanish by 11, down to
    // the 10-bit floor; the fabric's own taps are no worse than sampled 5-tap ones.
    assert!(max_err("3") > max_err("5"), "{}", table.markdown());
    assert!(max_err("11") < 0.2, "{}", table.markdown());
    assert!(
        max_err("5, fabric taps") <= max_err("5"),
        "{}",
        table.markdown()
    );
    for name in ["results.csv", "sigma.csv", "kernel.png"] {
        assert!(dir.path().join(name).is_file(), "{name}");
    }
}
