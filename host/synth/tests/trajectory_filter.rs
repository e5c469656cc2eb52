//! The filter and the encoder reader against the renderer's head trajectories: the truth
//! here comes from `stereocal-synth`, which the library itself does not link.

use stereocal::encoders::read_encoders_csv;
use stereocal::kalman::{FilterStatus, KalmanConfig, Measurement, VergeFilter};
use stereocal_synth::{SceneKind, Sequence, SequenceConfig, Trajectory, TrajectoryKind};

fn meas(v: f64) -> Option<Measurement> {
    Some(Measurement {
        verge_deg: v,
        sigma_deg: 0.02,
    })
}

/// Filtered max |error| and restarts over 60 s of the `motor` trajectory at 30 fps,
/// measurements the truth plus deterministic ±0.01° noise; with `encoder_offset_deg`, the
/// filter also gets encoder readings of the truth plus that offset and ±0.005° of noise.
fn motor_run(seed: u64, encoder_offset_deg: Option<f64>) -> (f64, usize) {
    let t = Trajectory::new(
        TrajectoryKind::Motor,
        seed,
        60.0,
        nalgebra::Vector3::zeros(),
        0.0,
        0.0,
        stereocal_synth::FIXED_VERGE_DEG,
    );
    let mut f = VergeFilter::new(KalmanConfig::default());
    let (mut worst, mut restarts) = (0f64, 0);
    for i in 0..1800u64 {
        let truth = t.state(i as f64 / 30.0).verge_deg();
        let noise = 0.01 * ((i * 7919 % 101) as f64 / 50.0 - 1.0);
        let encoder = encoder_offset_deg
            .map(|offset| truth + offset + 0.005 * ((i * 104_729 % 97) as f64 / 48.0 - 1.0));
        let o = f
            .step_with_encoders(i * 33_333, meas(truth + noise), encoder)
            .unwrap()
            .unwrap();
        worst = worst.max((o.verge_deg - truth).abs());
        restarts += usize::from(i > 0 && o.status == FilterStatus::Restarted);
    }
    (worst, restarts)
}

#[test]
fn motor_moves_are_followed_from_their_first_frame() {
    for seed in 1..=3 {
        // Holding the old value for one frame would be off by up to 5° here (the
        // trajectory's own test): the bound leaves no room for a frame of lag.
        let (worst, _) = motor_run(seed, None);
        assert!(worst <= 0.1, "seed {seed}: filtered max error {worst}°");
    }
}

#[test]
fn encoders_predict_motor_moves_so_nothing_restarts() {
    for seed in 1..=3 {
        let (worst, restarts) = motor_run(seed, Some(0.7));
        assert!(worst <= 0.03, "seed {seed}: filtered max error {worst}°");
        assert_eq!(restarts, 0, "seed {seed}");
        // Without encoders the same moves restart the filter at their onsets.
        assert!(motor_run(seed, None).1 > 0, "seed {seed}");
    }
}

#[test]
fn synth_writes_the_truth_as_run_reads_it() {
    let config = SequenceConfig {
        frames: 40,
        seed: 10,
        trajectory: TrajectoryKind::Motor,
        ..SequenceConfig::for_scene(SceneKind::Road)
    };
    let sequence = Sequence::builtin(SceneKind::Road, config).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("encoders.csv");
    std::fs::write(&path, sequence.encoders_csv()).unwrap();
    let verge = read_encoders_csv(&path, 40);
    for (i, v) in verge.unwrap().into_iter().enumerate() {
        let truth = sequence.truth(i).unwrap().verge_deg;
        assert!(
            (v.unwrap() - truth).abs() < 1e-8,
            "frame {i}: {v:?} vs {truth}"
        );
    }
}
