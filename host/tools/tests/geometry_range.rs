//! The estimator across the geometry a verge head can have (issue 21, items 3 and 4), end to
//! end on rendered truth (renderer → fabric model → wire → host): focal lengths of 400 and
//! 1400 px, a verge of 20°, a 2° pitch the calibration does not know (general model), and
//! fixed verges across ±15°. Every sequence is the road driven at 10 m/s, so each frame shows
//! a new view; the bounds are on the raw per-frame estimate against the renderer's exact verge.

use std::num::NonZeroU16;

use stereocal::estimator::Model;
use stereocal::output::record::FrameRecord;
use stereocal::session::SessionConfig;
use stereocal_synth::{SceneKind, Sequence, SequenceConfig, TrajectoryKind};
use stereocal_tools::eval::evaluate;

/// The share of frames that must carry an estimate (issue 21's target).
const MIN_ESTIMATED: f64 = 0.98;

/// The road's raw maximum error at the default 600 px focal length on 200 frames (README,
/// "Accuracy on rendered ground truth": 0.025°), the yardstick the bounds below scale from.
const ROAD_RAW_MAX_DEG: f64 = 0.025;

fn records(config: SequenceConfig, session: SessionConfig) -> Vec<FrameRecord> {
    let sequence = Sequence::builtin(SceneKind::Road, config).expect("sequence");
    let (records, _) = evaluate(&sequence, session, &mut |_| {}).expect("evaluation");
    records
}

/// The fraction of frames estimated and the largest |raw error| (degrees).
fn figures(records: &[FrameRecord]) -> (f64, f64) {
    let errors: Vec<f64> = records
        .iter()
        .filter_map(|r| Some((r.raw_verge_deg? - r.truth_deg?).abs()))
        .collect();
    let max = errors.iter().copied().fold(0.0, f64::max);
    (errors.len() as f64 / records.len() as f64, max)
}

fn fixed(verge_deg: f64, frames: usize, seed: u64) -> SequenceConfig {
    SequenceConfig {
        frames,
        seed,
        trajectory: TrajectoryKind::Fixed,
        fixed_verge_deg: verge_deg,
        ..SequenceConfig::for_scene(SceneKind::Road)
    }
}

fn check(name: &str, records: &[FrameRecord], bound_deg: f64) {
    let (estimated, max) = figures(records);
    eprintln!("{name}: estimated {estimated:.3}, max |error| {max:.4}°");
    assert!(estimated >= MIN_ESTIMATED, "{name}: estimated {estimated}");
    assert!(
        max <= bound_deg,
        "{name}: max |error| {max}° > {bound_deg}°"
    );
}

/// A short focal length: 400 px over 640 px (a 77° field of view). A pixel spans 1.5 times
/// the angle it does at 600 px, so the bound is the road's maximum scaled by 600/400.
#[test]
fn focal_length_400_px() {
    let config = SequenceConfig {
        focal_px: Some(400.0),
        ..fixed(1.6, 12, 3)
    };
    let bound = ROAD_RAW_MAX_DEG * 600.0 / 400.0;
    check(
        "f = 400 px",
        &records(config, SessionConfig::default()),
        bound,
    );
}

/// A long focal length: 1400 px over 1280 x 960 px (49°), where a fixed gate in pixels would
/// be a third as wide in angle as at 600 px. Finer pixels and more matches keep the error at
/// most the road's.
#[test]
fn focal_length_1400_px() {
    let config = SequenceConfig {
        width: 1280,
        height: 960,
        focal_px: Some(1400.0),
        ..fixed(1.6, 6, 3)
    };
    check(
        "f = 1400 px",
        &records(config, SessionConfig::default()),
        ROAD_RAW_MAX_DEG,
    );
}

/// A 20° verge, beyond the ±15° of the large-verge target: the views overlap less and the
/// matches halve against a parallel head's (about 100 against 210 a frame). Issue 21 sets no
/// accuracy there; the estimator reaches 0.036°, and the test holds it at 0.05° (named so).
#[test]
fn verge_of_20_deg_max_error_within_0_05_deg() {
    check(
        "20° verge",
        &records(fixed(20.0, 12, 3), SessionConfig::default()),
        0.05,
    );
}

/// A right camera pitched 2° that the calibration does not know, fitted by the general model
/// (`--model general`); the verge is the pose's. Five unknowns instead of two are noisier, so
/// the bound is the road's with the √(5/2) of the extra unknowns.
#[test]
fn pitch_of_2_deg_with_the_general_model() {
    let config = SequenceConfig {
        right_pitch_deg: 2.0,
        ..fixed(1.6, 12, 3)
    };
    let mut session = SessionConfig::default();
    session.estimator.model = Model::General;
    let bound = ROAD_RAW_MAX_DEG * (5.0f64 / 2.0).sqrt();
    check("2° pitch, general model", &records(config, session), bound);
}

/// The largest raw error over verges within ±15°: issue 21's bound. The estimator reaches
/// 0.029° (at -10°): at ±15° about two thirds of a parallel head's matches remain, the
/// descriptors losing those where the verge stretches the image's edges.
const LARGE_VERGE_MAX_DEG: f64 = 0.03;

/// The largest raw error over fixed verges across ±15° (8 frames each) with `session`.
fn worst_over_large_verges(session: SessionConfig) -> f64 {
    let mut worst = 0f64;
    for verge in [-15.0, -10.0, -5.0, 5.0, 10.0, 15.0] {
        let records = records(fixed(verge, 8, 3), session);
        let (estimated, max) = figures(&records);
        eprintln!("verge {verge}°: estimated {estimated:.3}, max |error| {max:.4}°");
        assert!(estimated >= MIN_ESTIMATED, "verge {verge}°: {estimated}");
        worst = worst.max(max);
    }
    worst
}

/// Fixed verges across ±15°: the error does not grow with the verge (no scale error).
#[test]
fn large_verge_max_error_within_0_03_deg() {
    let worst = worst_over_large_verges(SessionConfig::default());
    assert!(
        worst <= LARGE_VERGE_MAX_DEG,
        "max |error| {worst}° over ±15°"
    );
}

/// Issue 21's bound over ±15°, 0.03°, with grid points every 12 px (`--grid 12`): on the
/// rendered road the verge's error follows the matches' sub-pixel noise, and the grid's
/// points add to the matches, which takes the worst frame from 0.029° to 0.027° (README,
/// "Grid points").
#[test]
fn large_verge_with_grid_points_max_error_within_0_03_deg() {
    let mut session = SessionConfig::default();
    if let Some(guided) = &mut session.estimator.guided {
        guided.grid_px = NonZeroU16::new(12);
    }
    let worst = worst_over_large_verges(session);
    assert!(
        worst <= 0.03,
        "max |error| {worst}° over ±15° with grid points"
    );
}
