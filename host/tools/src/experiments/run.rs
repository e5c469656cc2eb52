//! One rendered sequence through the whole chain, and the error figures the experiments
//! derive from its records beyond the standard [`Summary`].

use std::path::{Path, PathBuf};

use super::{ExperimentError, Progress};
use crate::eval::evaluate;
use stereocal::output::record::FrameRecord;
use stereocal::output::report::write_outputs;
use stereocal::output::summary::{percentile, settled_from, Residual, Summary};
use stereocal::session::{SessionConfig, SessionCost};
use stereocal_synth::{SceneKind, Sequence, SequenceConfig, TrajectoryKind};

/// Which sequence, with which settings.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RunSpec {
    pub scene: SceneKind,
    pub trajectory: TrajectoryKind,
    pub frames: usize,
    pub seed: u64,
    pub config: SessionConfig,
    /// Progress-bar label.
    pub label: &'static str,
}

/// The records of one run and what they cost.
pub(crate) struct Run {
    /// Frames per second of the sequence.
    pub fps: f64,
    pub records: Vec<FrameRecord>,
    pub cost: SessionCost,
    /// Truth is the renderer's exact verge, so no residual is removed.
    pub summary: Summary,
}

impl RunSpec {
    /// The scene's own sequence settings (frame rate, vehicle speed, tilt) with this spec's
    /// trajectory, length and seed.
    fn sequence(&self) -> Result<Sequence, ExperimentError> {
        let mut config = SequenceConfig::for_scene(self.scene);
        config.frames = self.frames;
        config.seed = self.seed;
        config.trajectory = self.trajectory;
        Ok(Sequence::builtin(self.scene, config)?)
    }

    pub(crate) fn run(&self, progress: &mut dyn FnMut(Progress)) -> Result<Run, ExperimentError> {
        let sequence = self.sequence()?;
        progress(Progress::Run {
            label: self.label,
            steps: sequence.len(),
        });
        let (records, cost) = evaluate(&sequence, self.config, &mut |_| progress(Progress::Step))?;
        let summary = Summary::from_records(&records, Residual::Keep, cost.into());
        Ok(Run {
            fps: sequence.config().fps,
            records,
            cost,
            summary,
        })
    }
}

impl Run {
    /// `verge.csv` and `verge.png` (fig. 5.1 style) of this run into `dir`.
    pub(crate) fn write(&self, dir: &Path, title: &str) -> Result<Vec<PathBuf>, ExperimentError> {
        Ok(write_outputs(dir, &self.records, title, false)?)
    }

    /// |raw − truth| of every estimated frame.
    pub(crate) fn raw_errors(&self) -> Vec<f64> {
        self.errors(|r| r.raw_verge_deg)
    }

    /// |filtered − truth| of every estimated frame.
    pub(crate) fn filtered_errors(&self) -> Vec<f64> {
        self.errors(|r| r.filtered_verge_deg)
    }

    fn errors(&self, value: impl Fn(&FrameRecord) -> Option<f64>) -> Vec<f64> {
        self.records
            .iter()
            .filter(|r| r.status.has_estimate())
            .filter_map(|r| Some((value(r)? - r.truth_deg?).abs()))
            .collect()
    }

    /// (min, max) of the truth over the run.
    pub(crate) fn truth_range(&self) -> Option<(f64, f64)> {
        range(
            &self
                .records
                .iter()
                .filter_map(|r| r.truth_deg)
                .collect::<Vec<_>>(),
        )
    }

    /// The filtered estimates of the estimated frames once the filter has settled, the same
    /// frames the summary's `filtered_span_deg` covers (its range is that span).
    pub(crate) fn settled_filtered(&self) -> Vec<f64> {
        let settled_from = settled_from(self.records.len());
        self.records
            .iter()
            .filter(|r| r.status.has_estimate() && r.frame >= settled_from)
            .filter_map(|r| r.filtered_verge_deg)
            .collect()
    }

    /// The raw estimates of the estimated frames.
    pub(crate) fn raw(&self) -> Vec<f64> {
        self.records
            .iter()
            .filter(|r| r.status.has_estimate())
            .filter_map(|r| r.raw_verge_deg)
            .collect()
    }
}

/// 95th percentile, `None` for no values.
pub(crate) fn p95(values: &[f64]) -> Option<f64> {
    percentile(values, 0.95)
}

/// Percentage of all `frames` whose error is below `limit` (frames without an estimate count
/// as misses), the form of the thesis' "smaller than 1 degree most of the time".
pub(crate) fn percent_below(errors: &[f64], frames: usize, limit: f64) -> Option<f64> {
    (frames > 0)
        .then(|| 100.0 * errors.iter().filter(|e| **e < limit).count() as f64 / frames as f64)
}

/// (min, max) of `values`.
pub(crate) fn range(values: &[f64]) -> Option<(f64, f64)> {
    values.iter().fold(None, |acc, &v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn misses_count_against_the_percentage() {
        assert_eq!(percent_below(&[0.1, 0.5, 2.0], 4, 1.0), Some(50.0));
        assert_eq!(percent_below(&[], 0, 1.0), None);
        assert_eq!(range(&[2.0, -1.0, 0.5]), Some((-1.0, 2.0)));
        assert_eq!(range(&[]), None);
    }
}
