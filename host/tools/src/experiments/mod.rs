//! The thesis' experiments as reproducible runs on rendered ground truth, each leaving CSV
//! tables and PNG figures in its directory and a Markdown table for `docs/RESULTS.md`.
//!
//! | experiment | thesis | what it runs |
//! |---|---|---|
//! | [`Experiment::Moving`] | fig. 5.1 | road and lab scenes, cameras moved by hand |
//! | [`Experiment::Fixed`] | fig. 5.2 | road scene, cameras fixed, vehicle driving |
//! | [`Experiment::Ransac`] | 5.2.3 | the fig. 5.2 sequence with RANSAC on and off |
//! | [`Experiment::Octaves`] | fig. 5.3 | keypoints and matches per pyramid octave |
//! | [`Experiment::Kernel`] | fig. 4.8 | Gaussian kernel size vs cascade error, with our 10-bit taps |
//!
//! Every sequence goes through the whole chain (fabric model → wire → host, [`crate::eval`]),
//! so the numbers are the ones `stereocal eval` would print for the same scene and seed. The
//! tables carry the thesis' own figure beside ours where the thesis states one; where it only
//! shows a plot, the column quotes what its text says rather than a value read off the plot.

pub mod fixed;
pub mod kernel;
pub mod moving;
pub mod octaves;
pub mod ransac;

mod files;
mod run;
mod table;

use std::path::{Path, PathBuf};

pub use table::Table;

use crate::eval::EvalError;
use stereocal::output::output_dir::OutputError;
use stereocal::output::plot::PlotError;
use stereocal::output::report::ReportError;
use stereocal_synth::SynthError;

/// The experiments, in the order `all` runs them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Experiment {
    Moving,
    Fixed,
    Ransac,
    Octaves,
    Kernel,
}

impl Experiment {
    pub const ALL: [Experiment; 5] = [
        Self::Moving,
        Self::Fixed,
        Self::Ransac,
        Self::Octaves,
        Self::Kernel,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Self::Moving => "moving",
            Self::Fixed => "fixed",
            Self::Ransac => "ransac",
            Self::Octaves => "octaves",
            Self::Kernel => "kernel",
        }
    }

    /// Frames of each run (images filtered, for `kernel`) when `--frames` is not given: enough
    /// for stable statistics while `all` stays within a few minutes on two cores.
    pub fn default_frames(self) -> usize {
        match self {
            Self::Moving | Self::Fixed => 200,
            Self::Ransac => 150,
            Self::Octaves => 100,
            Self::Kernel => 3,
        }
    }

    /// Runs the experiment and writes its files into `out`.
    pub fn run(
        self,
        settings: Settings,
        out: &Path,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Outcome, ExperimentError> {
        let frames = settings.frames.unwrap_or(self.default_frames());
        let seed = settings.seed;
        match self {
            Self::Moving => moving::run(frames, seed, out, progress),
            Self::Fixed => fixed::run(frames, seed, out, progress),
            Self::Ransac => ransac::run(frames, seed, out, progress),
            Self::Octaves => octaves::run(frames, seed, out, progress),
            Self::Kernel => kernel::run(frames, seed, out, progress),
        }
    }
}

/// What the caller may change about a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Settings {
    /// Frames of each run; `None` takes [`Experiment::default_frames`].
    pub frames: Option<usize>,
    /// Seed of every rendered sequence (scene layout, trajectory, noise).
    pub seed: u64,
}

/// Progress of an experiment, for a progress bar.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Progress {
    /// A run of `steps` frames (or images) starts.
    Run { label: &'static str, steps: usize },
    /// One frame (or image) of the current run is done.
    Step,
}

/// What an experiment produced.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    pub title: String,
    pub tables: Vec<Table>,
    /// Every file written, in the order written.
    pub written: Vec<PathBuf>,
}

/// Why an experiment stopped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExperimentError {
    #[error("cannot build the sequence: {0}")]
    Synth(#[from] SynthError),
    #[error(transparent)]
    Eval(#[from] EvalError),
    #[error(transparent)]
    Report(#[from] ReportError),
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error(transparent)]
    Plot(#[from] PlotError),
    #[error("{path}: cannot write the table: {source}")]
    Csv { path: PathBuf, source: csv::Error },
    #[error("{experiment}: the run produced no {what}, so there is nothing to report")]
    Empty {
        experiment: &'static str,
        what: &'static str,
    },
}
