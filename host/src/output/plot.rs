//! `verge.png`, drawn like the thesis' figure 5.1: the per-frame estimates as dots, the Kalman
//! estimate as a thin line, the truth (when known) as a thick line, and below it a panel of
//! truth minus estimate.

use std::path::Path;
use std::sync::Once;

use plotters::prelude::*;
use plotters::style::{register_font, FontStyle};

use crate::output::record::FrameRecord;

/// The font is embedded so the figure has labels on a machine without fonts (see assets/).
const FONT: &[u8] = include_bytes!("../../assets/DejaVuSansMono.ttf");
/// The family name the embedded font is registered under; every figure (the run's and the tools') draws
/// its text with it (after [`ensure_font`]).
pub const FAMILY: &str = "sans-serif";

/// A figure that could not be drawn or written.
#[derive(Debug, thiserror::Error)]
#[error("{path}: cannot draw the verge plot: {message}")]
pub struct PlotError {
    /// The figure's file.
    pub path: std::path::PathBuf,
    /// The plotting library's message.
    pub message: String,
}

/// Registers the embedded font once per process.
pub fn ensure_font() {
    static REGISTER: Once = Once::new();
    REGISTER.call_once(|| {
        // The bytes are a known-good TTF compiled into the binary; failure here is a build defect,
        // and plotters then falls back to drawing without text rather than failing the run.
        let _ = register_font(FAMILY, FontStyle::Normal, FONT);
    });
}

/// Draws the figure into `path` (PNG, 1200x800).
pub fn draw_verge_plot(path: &Path, records: &[FrameRecord], title: &str) -> Result<(), PlotError> {
    ensure_font();
    draw(path, records, title).map_err(|e| PlotError {
        path: path.to_owned(),
        message: e.to_string(),
    })
}

fn draw(
    path: &Path,
    records: &[FrameRecord],
    title: &str,
) -> Result<(), Box<dyn std::error::Error>> {
    let root = BitMapBackend::new(path, (1200, 800)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, bottom) = root.split_vertically(520);

    let frames = records.len().max(1) as f64;
    let values = records.iter().flat_map(|r| {
        [r.raw_verge_deg, r.filtered_verge_deg, r.truth_deg]
            .into_iter()
            .flatten()
    });
    let (lo, hi) = bounds(values, 1.0);
    let mut chart = ChartBuilder::on(&top)
        .caption(title, (FAMILY, 24))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(70)
        .build_cartesian_2d(0f64..frames, lo..hi)?;
    chart
        .configure_mesh()
        .y_desc("verge angle (deg)")
        .label_style((FAMILY, 14))
        .draw()?;

    let truth: Vec<(f64, f64)> = records
        .iter()
        .filter_map(|r| Some((r.frame as f64, r.truth_deg?)))
        .collect();
    if !truth.is_empty() {
        chart
            .draw_series(LineSeries::new(truth, BLACK.stroke_width(4)))?
            .label("truth")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLACK.stroke_width(4)));
    }
    chart
        .draw_series(
            records
                .iter()
                .filter_map(|r| Some((r.frame as f64, r.raw_verge_deg?)))
                .map(|p| Circle::new(p, 2, BLUE.filled())),
        )?
        .label("per-frame estimate")
        .legend(|(x, y)| Circle::new((x + 10, y), 3, BLUE.filled()));
    for run in segments(records, |r| r.filtered_verge_deg) {
        chart.draw_series(LineSeries::new(run, RED.stroke_width(1)))?;
    }
    chart
        .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())?
        .label("Kalman filtered")
        .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], RED));
    chart
        .configure_series_labels()
        .label_font((FAMILY, 14))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;

    let diff: Vec<(f64, f64)> = records
        .iter()
        .filter_map(|r| Some((r.frame as f64, r.truth_deg? - r.raw_verge_deg?)))
        .collect();
    let (dlo, dhi) = bounds(diff.iter().map(|d| d.1), 0.01);
    let mut lower = ChartBuilder::on(&bottom)
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(70)
        .build_cartesian_2d(0f64..frames, dlo..dhi)?;
    lower
        .configure_mesh()
        .x_desc("frame")
        .y_desc("truth - estimate (deg)")
        .label_style((FAMILY, 14))
        .draw()?;
    lower.draw_series(LineSeries::new([(0.0, 0.0), (frames, 0.0)], BLACK))?;
    lower.draw_series(diff.into_iter().map(|p| Circle::new(p, 2, BLUE.filled())))?;
    root.present()?;
    Ok(())
}

/// Range covering all values with a margin; at least `min_span` wide, symmetric when empty.
fn bounds(values: impl Iterator<Item = f64>, min_span: f64) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if lo > hi {
        return (-min_span, min_span);
    }
    let mid = 0.5 * (lo + hi);
    let half = (0.5 * (hi - lo)).max(0.5 * min_span) * 1.1;
    (mid - half, mid + half)
}

/// Consecutive runs of frames that have a value, so gaps (dropped frames) stay gaps.
fn segments(
    records: &[FrameRecord],
    value: impl Fn(&FrameRecord) -> Option<f64>,
) -> Vec<Vec<(f64, f64)>> {
    let mut runs = vec![Vec::new()];
    for r in records {
        match value(r) {
            Some(v) => runs.last_mut().into_iter().for_each(|run| {
                run.push((r.frame as f64, v));
            }),
            None => runs.push(Vec::new()),
        }
    }
    runs.retain(|run| !run.is_empty());
    runs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::record::FrameStatus;

    #[test]
    fn draws_a_png_with_gaps() {
        let records: Vec<FrameRecord> = (0..50)
            .map(|i| {
                let ok = i % 7 != 3;
                let v = (i as f64 * 0.1).sin() * 10.0;
                FrameRecord {
                    raw_verge_deg: ok.then_some(v + 0.01),
                    filtered_verge_deg: ok.then_some(v),
                    filtered_sigma_deg: ok.then_some(0.01),
                    matches: 30,
                    inliers: 28,
                    status: if ok {
                        FrameStatus::Ok
                    } else {
                        FrameStatus::Dropped
                    },
                    ..FrameRecord::dropped(i, Some(v))
                }
            })
            .collect();
        assert_eq!(segments(&records, |r| r.filtered_verge_deg).len(), 8);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("verge.png");
        draw_verge_plot(&path, &records, "test").unwrap();
        let img = image::open(&path).unwrap();
        assert_eq!((img.width(), img.height()), (1200, 800));
    }
}
