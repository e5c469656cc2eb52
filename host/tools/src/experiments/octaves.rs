//! Thesis fig. 5.3, distribution of matched keypoints over the pyramid octaves: how much the
//! coarse octaves contribute, i.e. whether their fabric area is worth it. Three series as in
//! the thesis: the keypoints detected ("input data"), the matches used ("matched points") and
//! the thesis' own setting of keeping the 20 best matches ("top of sorted"), all counted at
//! the left keypoint of each match, over the estimated frames of the fig. 5.2 sequence.
//!
//! Octaves are numbered from 0 (full resolution) as everywhere in stereocal; the thesis counts
//! from 1.
//!
//! Files: `results.csv` and `octaves.png`.

use std::path::Path;

use plotters::prelude::*;

use super::files::Files;
use super::run::{Run, RunSpec};
use super::table::fixed;
use super::{ExperimentError, Outcome, Progress, Table};
use stereocal::estimator::EstimatorConfig;
use stereocal::matching::MatchConfig;
use stereocal::output::plot::FAMILY;
use stereocal::output::record::FrameRecord;
use stereocal::session::SessionConfig;
use stereocal_synth::{SceneKind, TrajectoryKind};

/// The thesis kept the best 20 matches of each frame.
const THESIS_BEST: usize = 20;

/// Counts per octave, summed over frames.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct OctaveTally {
    pub counts: Vec<usize>,
}

impl OctaveTally {
    /// Sums `per_octave(r)` over the estimated frames of `records`.
    pub fn over(records: &[FrameRecord], per_octave: impl Fn(&FrameRecord) -> &[usize]) -> Self {
        let mut counts = Vec::new();
        for r in records.iter().filter(|r| r.status.has_estimate()) {
            let frame = per_octave(r);
            if frame.len() > counts.len() {
                counts.resize(frame.len(), 0);
            }
            for (total, n) in counts.iter_mut().zip(frame) {
                *total += n;
            }
        }
        Self { counts }
    }

    pub fn total(&self) -> usize {
        self.counts.iter().sum()
    }

    /// The share of `octaves`, `None` when nothing was counted.
    pub fn share(&self, octaves: impl IntoIterator<Item = usize>) -> Option<f64> {
        let total = self.total();
        (total > 0).then(|| {
            octaves
                .into_iter()
                .filter_map(|o| self.counts.get(o))
                .sum::<usize>() as f64
                / total as f64
        })
    }

    fn count(&self, octave: usize) -> usize {
        self.counts.get(octave).copied().unwrap_or(0)
    }
}

pub fn run(
    frames: usize,
    seed: u64,
    out: &Path,
    progress: &mut dyn FnMut(Progress),
) -> Result<Outcome, ExperimentError> {
    let all = SessionConfig::default();
    let best = SessionConfig {
        estimator: EstimatorConfig {
            matching: MatchConfig {
                best_n: Some(THESIS_BEST),
                ..all.estimator.matching
            },
            ..all.estimator
        },
        ..all
    };
    let spec = |config, label| RunSpec {
        scene: SceneKind::Road,
        trajectory: TrajectoryKind::Fixed,
        frames,
        seed,
        config,
        label,
    };
    let every = spec(all, "road, fixed verge, all matches").run(progress)?;
    let top = spec(best, "road, fixed verge, best 20 matches").run(progress)?;
    let series = [
        (
            "keypoints (input data)",
            OctaveTally::over(&every.records, |r| &r.keypoints_per_octave),
        ),
        (
            "matched points",
            OctaveTally::over(&every.records, |r| &r.matches_per_octave),
        ),
        (
            "best 20 (top of sorted)",
            OctaveTally::over(&top.records, |r| &r.matches_per_octave),
        ),
    ];
    if series.iter().any(|(_, t)| t.total() == 0) {
        return Err(ExperimentError::Empty {
            experiment: "octaves",
            what: "estimated frame",
        });
    }
    let table = distribution_table(&series, frames, seed, [&every, &top]);
    let mut files = Files::new(out)?;
    files.table(&table)?;
    files.figure("octaves.png", |path| draw(path, &series, frames, seed))?;
    Ok(Outcome {
        title: "matched keypoints per octave (thesis fig. 5.3)".into(),
        tables: vec![table],
        written: files.commit()?,
    })
}

fn distribution_table(
    series: &[(&str, OctaveTally)],
    frames: usize,
    seed: u64,
    [every, top]: [&Run; 2],
) -> Table {
    let mut table = Table::new(
        "results",
        format!(
            "fig. 5.3, share of points per octave over the estimated frames ({} and {} of {frames}) \
             of the fig. 5.2 sequence, seed {seed}",
            every.summary.estimated_frames, top.summary.estimated_frames
        ),
        &[
            "octave",
            "keypoints",
            "share",
            "matched",
            "share",
            "best 20",
            "share",
            "thesis (fig. 5.3)",
        ],
    );
    let octaves = series
        .iter()
        .map(|(_, t)| t.counts.len())
        .max()
        .unwrap_or(0);
    let thesis = |o: usize| match o {
        0 => "\"dominance of the first octave\"",
        3 => "\"a few percent\" of the points",
        _ => "-",
    };
    let row = |name: String, counts: Vec<usize>, shares: Vec<Option<f64>>, thesis: &str| {
        let mut row = vec![name];
        for (c, s) in counts.into_iter().zip(shares) {
            row.push(c.to_string());
            row.push(fixed(s.map(|s| 100.0 * s), 1) + " %");
        }
        row.push(thesis.to_owned());
        row
    };
    for o in 0..octaves {
        table.push(row(
            format!("{o} (thesis {})", o + 1),
            series.iter().map(|(_, t)| t.count(o)).collect(),
            series.iter().map(|(_, t)| t.share([o])).collect(),
            thesis(o),
        ));
    }
    if octaves > 2 {
        let coarse = 2..octaves;
        table.push(row(
            format!("{} and up (thesis 3 and 4)", coarse.start),
            series
                .iter()
                .map(|(_, t)| coarse.clone().map(|o| t.count(o)).sum())
                .collect(),
            series
                .iter()
                .map(|(_, t)| t.share(coarse.clone()))
                .collect(),
            "\"not more than about 10-15%\" of the matched points",
        ));
    }
    table.push(row(
        "all".to_owned(),
        series.iter().map(|(_, t)| t.total()).collect(),
        series.iter().map(|(_, t)| t.share(0..octaves)).collect(),
        "-",
    ));
    table
}

/// Grouped bars of each series' share per octave, like fig. 5.3.
fn draw(
    path: &Path,
    series: &[(&str, OctaveTally)],
    frames: usize,
    seed: u64,
) -> Result<(), Box<dyn std::error::Error>> {
    let root = BitMapBackend::new(path, (1000, 650)).into_drawing_area();
    root.fill(&WHITE)?;
    let octaves = series
        .iter()
        .map(|(_, t)| t.counts.len())
        .max()
        .unwrap_or(1);
    let top = series
        .iter()
        .flat_map(|(_, t)| (0..octaves).filter_map(|o| t.share([o])))
        .fold(0.0f64, f64::max);
    let mut chart = ChartBuilder::on(&root)
        .caption(
            format!(
                "points per octave (fig. 5.3): road, fixed verge, {frames} frames, seed {seed}"
            ),
            (FAMILY, 22),
        )
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(70)
        .build_cartesian_2d(-0.5f64..octaves as f64 - 0.5, 0f64..(top * 1.15).max(0.1))?;
    chart
        .configure_mesh()
        .x_labels(octaves)
        .x_label_formatter(&|x| format!("{x:.0}"))
        .x_desc("octave (0 = full resolution; the thesis' octave 1)")
        .y_desc("share of points")
        .label_style((FAMILY, 14))
        .disable_x_mesh()
        .draw()?;
    let colours = [BLUE, RED, GREEN];
    let width = 0.8 / series.len() as f64;
    for (s, ((name, tally), colour)) in series.iter().zip(colours).enumerate() {
        let left = |o: usize| o as f64 - 0.4 + s as f64 * width;
        chart
            .draw_series((0..octaves).map(|o| {
                Rectangle::new(
                    [
                        (left(o), 0.0),
                        (left(o) + width * 0.9, tally.share([o]).unwrap_or(0.0)),
                    ],
                    colour.filled(),
                )
            }))?
            .label(*name)
            .legend(move |(x, y)| Rectangle::new([(x, y - 6), (x + 14, y + 6)], colour.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FAMILY, 15))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use stereocal::output::record::FrameStatus;

    fn record(status: FrameStatus, matches: Vec<usize>) -> FrameRecord {
        FrameRecord {
            matches: matches.iter().sum(),
            matches_per_octave: matches,
            status,
            ..FrameRecord::dropped(0, None)
        }
    }

    #[test]
    fn tally_sums_estimated_frames_of_any_length() {
        let records = [
            record(FrameStatus::Ok, vec![6, 3, 1, 0]),
            record(FrameStatus::Ok, vec![4, 1, 0, 0, 1]),
            record(FrameStatus::NoEstimate, vec![100]),
        ];
        let t = OctaveTally::over(&records, |r| &r.matches_per_octave);
        assert_eq!(t.counts, vec![10, 4, 1, 0, 1]);
        assert_eq!(t.total(), 16);
        assert_eq!(t.share([0]), Some(10.0 / 16.0));
        assert_eq!(t.share(2..5), Some(2.0 / 16.0));
        assert_eq!(OctaveTally::default().share([0]), None);
    }
}
