//! What a run leaves behind: `verge.csv` and `verge.png` in the output directory, with
//! `matches.csv` when asked (all or none), and the human-readable summary table.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::output::matches_csv::write_matches_csv;
use crate::output::output_dir::{OutputError, StagedOutput};
use crate::output::plot::{draw_verge_plot, PlotError};
use crate::output::record::FrameRecord;
use crate::output::summary::Summary;
use crate::output::verge_csv::write_verge_csv;

/// Output files that could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// The output directory could not be prepared, or the files not moved into place.
    #[error(transparent)]
    Output(#[from] OutputError),
    /// `verge.png` could not be drawn or written.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// A CSV (`verge.csv`, `matches.csv`) could not be written.
    #[error("{path}: cannot write the CSV: {source}")]
    Csv {
        /// Its destination in the output directory.
        path: PathBuf,
        /// The CSV writer's error.
        source: csv::Error,
    },
    /// A CSV could not be created in the staging directory.
    #[error("{path}: cannot create the CSV: {source}")]
    Create {
        /// Its destination in the output directory.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
}

/// Writes `verge.csv` and `verge.png` into `dir`, and `matches.csv` (each record's consistent
/// pairs) when `matches`; they appear together, or not at all.
pub fn write_outputs(
    dir: &Path,
    records: &[FrameRecord],
    title: &str,
    matches: bool,
) -> Result<Vec<PathBuf>, ReportError> {
    let mut staged = StagedOutput::new(dir)?;
    stage_csv(&mut staged, dir, "verge.csv", |f| {
        write_verge_csv(f, records)
    })?;
    if matches {
        stage_csv(&mut staged, dir, "matches.csv", |f| {
            write_matches_csv(f, records)
        })?;
    }
    let png_path = staged.path("verge.png");
    draw_verge_plot(&png_path, records, title).map_err(|e| PlotError {
        path: dir.join("verge.png"),
        ..e
    })?;
    Ok(staged.commit()?)
}

/// Writes the CSV `name` of `dir` into `staged` with `write`.
fn stage_csv(
    staged: &mut StagedOutput,
    dir: &Path,
    name: &str,
    write: impl FnOnce(std::io::BufWriter<std::fs::File>) -> Result<(), csv::Error>,
) -> Result<(), ReportError> {
    let file = std::fs::File::create(staged.path(name)).map_err(|source| ReportError::Create {
        path: dir.join(name),
        source,
    })?;
    write(std::io::BufWriter::new(file)).map_err(|source| ReportError::Csv {
        path: dir.join(name),
        source,
    })
}

/// Extra lines of the summary table that the JSON summary does not carry.
#[derive(Debug, Clone, Default)]
pub struct TableExtras {
    /// (label, value) rows printed after the standard ones.
    pub rows: Vec<(String, String)>,
}

/// The summary as an aligned two-column table.
pub fn summary_table(summary: &Summary, truth_known: bool, extras: &TableExtras) -> String {
    let deg = |v: Option<f64>| v.map_or("-".to_string(), |d| format!("{d:.4}°"));
    let mut rows: Vec<(String, String)> = vec![
        ("frames".into(), summary.frames.to_string()),
        (
            "estimated".into(),
            format!(
                "{} ({:.1}%)",
                summary.estimated_frames,
                100.0 * summary.estimated_fraction()
            ),
        ),
        ("dropped".into(), summary.dropped_frames.to_string()),
        (
            "median matches".into(),
            summary
                .median_matches
                .map_or("-".into(), |m| format!("{m:.0}")),
        ),
    ];
    if truth_known {
        rows.extend([
            (
                "raw |error| median / p95 / max".into(),
                format!(
                    "{} / {} / {}",
                    deg(summary.median_abs_err_deg),
                    deg(summary.p95_abs_err_deg),
                    deg(summary.max_abs_err_deg)
                ),
            ),
            (
                "filtered |error| median / max".into(),
                format!(
                    "{} / {}",
                    deg(summary.filtered_median_abs_err_deg),
                    deg(summary.filtered_max_abs_err_deg)
                ),
            ),
        ]);
        if summary.residual_removed_deg != 0.0 {
            rows.push((
                "constant residual removed".into(),
                format!("{:.4}°", summary.residual_removed_deg),
            ));
        }
    }
    rows.extend([
        (
            "filtered span (settled)".into(),
            deg(summary.filtered_span_deg),
        ),
        (
            "ms per frame pair".into(),
            format!("{:.2}", summary.ms_per_frame_pair),
        ),
        (
            "bytes on the wire per pair".into(),
            format!("{:.0}", summary.wire_bytes_per_pair),
        ),
    ]);
    rows.extend(extras.rows.iter().cloned());
    let width = rows
        .iter()
        .map(|(k, _)| k.chars().count())
        .max()
        .unwrap_or(0);
    let mut out = String::new();
    for (k, v) in rows {
        // Writing to a String cannot fail.
        let _ = writeln!(out, "  {k:<width$}  {v}");
    }
    out
}
