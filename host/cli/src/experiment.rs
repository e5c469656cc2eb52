//! `stereocal experiment NAME`: the thesis' experiments (`stereocal_tools::experiments`), each
//! writing its CSV tables and PNG figures and printing its Markdown tables, the form
//! `docs/RESULTS.md` quotes them in.

use std::io::Write;
use std::path::PathBuf;

use clap::{Args, ValueEnum};
use indicatif::ProgressBar;
use stereocal_tools::experiments::{Experiment, Progress, Settings};

use crate::output::progress_bar;

/// Which experiment (`NAME`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ExperimentArg {
    /// Fig. 5.1: cameras moved by hand, road and lab scenes.
    Moving,
    /// Fig. 5.2: cameras fixed on a moving vehicle.
    Fixed,
    /// 5.2.3: the fig. 5.2 sequence with RANSAC on and off.
    Ransac,
    /// Fig. 5.3: keypoints and matches per pyramid octave.
    Octaves,
    /// Fig. 4.8: Gaussian kernel size against error.
    Kernel,
    /// Every experiment, each in its own directory.
    All,
}

#[derive(Debug, Clone, Args)]
pub struct ExperimentArgs {
    #[arg(value_enum)]
    name: ExperimentArg,
    /// Frame pairs of each run (kernel: frames filtered); default: the experiment's own.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    frames: Option<u32>,
    /// Seed of every rendered sequence.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Output directory (default out/experiments/NAME; with `all`, one NAME directory in it
    /// per experiment, default out/experiments).
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn experiment(args: &ExperimentArgs) -> anyhow::Result<()> {
    let selected = match args.name {
        ExperimentArg::Moving => vec![Experiment::Moving],
        ExperimentArg::Fixed => vec![Experiment::Fixed],
        ExperimentArg::Ransac => vec![Experiment::Ransac],
        ExperimentArg::Octaves => vec![Experiment::Octaves],
        ExperimentArg::Kernel => vec![Experiment::Kernel],
        ExperimentArg::All => Experiment::ALL.to_vec(),
    };
    let settings = Settings {
        frames: args.frames.map(|f| f as usize),
        seed: args.seed,
    };
    for e in selected {
        let dir = match (&args.out, args.name) {
            (Some(out), ExperimentArg::All) => out.join(e.name()),
            (Some(out), _) => out.clone(),
            (None, _) => PathBuf::from("out/experiments").join(e.name()),
        };
        let mut bar: Option<ProgressBar> = None;
        let outcome = e.run(settings, &dir, &mut |p| match p {
            Progress::Run { label, steps } => {
                if let Some(done) = bar.take() {
                    done.finish_and_clear();
                }
                let b = progress_bar(steps as u64, label);
                bar = Some(b);
            }
            Progress::Step => {
                if let Some(b) = &bar {
                    b.inc(1);
                }
            }
        });
        if let Some(done) = bar.take() {
            done.finish_and_clear();
        }
        let outcome = outcome?;
        let mut stdout = std::io::stdout().lock();
        writeln!(stdout, "## {}: {}\n", e.name(), outcome.title)?;
        for table in &outcome.tables {
            writeln!(stdout, "{}\n\n{}", table.caption, table.markdown())?;
        }
        stdout.flush()?;
        drop(stdout);
        for path in &outcome.written {
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}
