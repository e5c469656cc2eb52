//! Thesis fig. 5.1, moving cameras: each camera turned by hand, the verge estimate against the
//! encoders. Here the road scene (30 Hz, driving) and the lab scene (15 Hz, the thesis' lab
//! rate, standing) with the manual trajectory, the renderer's verge as the encoder.
//!
//! Files: `road/verge.{csv,png}`, `lab/verge.{csv,png}` (the fig. 5.1 layout) and `results.csv`.

use std::path::Path;

use super::files::Files;
use super::run::{p95, percent_below, RunSpec};
use super::table::fixed;
use super::{ExperimentError, Outcome, Progress, Table};
use stereocal::output::summary::median;
use stereocal::session::SessionConfig;
use stereocal_synth::{SceneKind, TrajectoryKind};

/// The thesis' accuracy statement for fig. 5.1 is about 1°.
const LIMIT_DEG: f64 = 1.0;

pub fn run(
    frames: usize,
    seed: u64,
    out: &Path,
    progress: &mut dyn FnMut(Progress),
) -> Result<Outcome, ExperimentError> {
    let scenes = [
        (SceneKind::Road, "road, manual verge moves"),
        (SceneKind::Lab, "lab, manual verge moves"),
    ];
    let mut table = Table::new(
        "results",
        format!("fig. 5.1, moving cameras: {frames} frames per scene, seed {seed}"),
        &["quantity", "road", "lab", "thesis (fig. 5.1, lab)"],
    );
    let mut columns = Vec::new();
    let mut written = Vec::new();
    for (scene, label) in scenes {
        let run = RunSpec {
            scene,
            trajectory: TrajectoryKind::Manual,
            frames,
            seed,
            config: SessionConfig::default(),
            label,
        }
        .run(progress)?;
        written.extend(run.write(
            &out.join(scene.name()),
            &format!("experiment moving (fig. 5.1): {label}, seed {seed}"),
        )?);
        let s = &run.summary;
        let raw = run.raw_errors();
        let filtered = run.filtered_errors();
        let truth = run.truth_range();
        columns.push(vec![
            s.frames.to_string(),
            fixed(Some(run.fps), 0),
            fixed(Some(100.0 * s.estimated_fraction()), 1),
            fixed(truth.map(|(lo, _)| lo), 2),
            fixed(truth.map(|(_, hi)| hi), 2),
            fixed(median(&raw), 4),
            fixed(p95(&raw), 4),
            fixed(s.max_abs_err_deg, 4),
            fixed(median(&filtered), 4),
            fixed(p95(&filtered), 4),
            fixed(s.filtered_max_abs_err_deg, 4),
            fixed(percent_below(&raw, s.frames, LIMIT_DEG), 1),
            fixed(percent_below(&filtered, s.frames, LIMIT_DEG), 1),
        ]);
    }
    let rows: [(&str, &str); 13] = [
        ("frames", "-"),
        ("frame rate (Hz)", "15"),
        ("frames estimated (%)", "-"),
        ("truth verge min (deg)", "-"),
        ("truth verge max (deg)", "-"),
        ("raw abs error median (deg)", "-"),
        ("raw abs error p95 (deg)", "-"),
        ("raw abs error max (deg)", "-"),
        ("filtered abs error median (deg)", "-"),
        ("filtered abs error p95 (deg)", "-"),
        ("filtered abs error max (deg)", "-"),
        ("raw error < 1 deg (% of frames)", "\"most of the time\""),
        ("filtered error < 1 deg (% of frames)", "-"),
    ];
    for (i, (quantity, thesis)) in rows.into_iter().enumerate() {
        table.push(vec![
            quantity.to_owned(),
            columns[0][i].clone(),
            columns[1][i].clone(),
            thesis.to_owned(),
        ]);
    }
    let mut files = Files::new(out)?;
    files.table(&table)?;
    written.extend(files.commit()?);
    Ok(Outcome {
        title: "moving cameras (thesis fig. 5.1)".into(),
        tables: vec![table],
        written,
    })
}
