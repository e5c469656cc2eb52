//! Thesis fig. 5.2, fixed cameras on a moving vehicle: the verge does not change, so the spread
//! of the estimate is the system's noise (the thesis: 1.43° to 1.86°, a span of 0.4°). Here the
//! road scene driven at the scene's own speed with the verge fixed at
//! [`stereocal_synth::FIXED_VERGE_DEG`], and the renderer's truth to measure the
//! error the thesis could not (its vehicle head had no encoders).
//!
//! Files: `verge.csv`, `verge.png` and `results.csv`.

use std::path::Path;

use super::files::Files;
use super::run::{range, RunSpec};
use super::table::fixed;
use super::{ExperimentError, Outcome, Progress, Table};
use stereocal::output::summary::median;
use stereocal::session::SessionConfig;
use stereocal_synth::{SceneKind, SequenceConfig, TrajectoryKind, FIXED_VERGE_DEG};

pub fn run(
    frames: usize,
    seed: u64,
    out: &Path,
    progress: &mut dyn FnMut(Progress),
) -> Result<Outcome, ExperimentError> {
    let spec = RunSpec {
        scene: SceneKind::Road,
        trajectory: TrajectoryKind::Fixed,
        frames,
        seed,
        config: SessionConfig::default(),
        label: "road, fixed verge, driving",
    };
    let run = spec.run(progress)?;
    let mut written = run.write(
        out,
        &format!("experiment fixed (fig. 5.2): road, fixed verge, driving, seed {seed}"),
    )?;
    let s = &run.summary;
    let raw = range(&run.raw());
    let filtered = range(&run.settled_filtered());
    let span = |r: Option<(f64, f64)>| r.map(|(lo, hi)| hi - lo);
    let speed = SequenceConfig::for_scene(SceneKind::Road).speed_mps;
    let mut table = Table::new(
        "results",
        format!("fig. 5.2, fixed cameras on a moving vehicle: {frames} frames, seed {seed}"),
        &["quantity", "ours", "thesis (fig. 5.2)"],
    );
    let rows = [
        ("frames", s.frames.to_string(), "-"),
        ("frame rate (Hz)", fixed(Some(run.fps), 0), "about 30"),
        (
            "vehicle speed (m/s)",
            fixed(Some(speed), 1),
            "- (city driving)",
        ),
        (
            "frames estimated (%)",
            fixed(Some(100.0 * s.estimated_fraction()), 1),
            "-",
        ),
        (
            "true verge (deg)",
            fixed(Some(FIXED_VERGE_DEG), 4),
            "- (no encoders)",
        ),
        ("raw verge min (deg)", fixed(raw.map(|r| r.0), 4), "-"),
        ("raw verge max (deg)", fixed(raw.map(|r| r.1), 4), "-"),
        ("raw verge span (deg)", fixed(span(raw), 4), "-"),
        (
            "filtered verge min (deg)",
            fixed(filtered.map(|r| r.0), 4),
            "1.43",
        ),
        (
            "filtered verge max (deg)",
            fixed(filtered.map(|r| r.1), 4),
            "1.86",
        ),
        ("filtered verge span (deg)", fixed(span(filtered), 4), "0.4"),
        (
            "raw abs error median (deg)",
            fixed(median(&run.raw_errors()), 4),
            "-",
        ),
        (
            "filtered abs error median (deg)",
            fixed(median(&run.filtered_errors()), 4),
            "-",
        ),
        (
            "filtered abs error max (deg)",
            fixed(s.filtered_max_abs_err_deg, 4),
            "-",
        ),
    ];
    for (quantity, ours, thesis) in rows {
        table.push(vec![quantity.to_owned(), ours, thesis.to_owned()]);
    }
    let mut files = Files::new(out)?;
    files.table(&table)?;
    written.extend(files.commit()?);
    Ok(Outcome {
        title: "fixed cameras on a moving vehicle (thesis fig. 5.2)".into(),
        tables: vec![table],
        written,
    })
}
