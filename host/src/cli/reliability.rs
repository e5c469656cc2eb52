//! `stereocal reliability`: the fault sweep of `stereocal::reliability`, written as
//! `docs/RELIABILITY.md`.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use stereocal::reliability::{markdown, passed, sweep, sweep_runs, SweepConfig};

/// Frame size of the sweep: small, so some thirty runs of the whole chain fit in minutes.
const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;

#[derive(Debug, Clone, Args)]
pub struct ReliabilityArgs {
    /// Frame pairs of each run (faults on for the middle two thirds).
    #[arg(long, default_value_t = 120, value_parser = clap::value_parser!(u32).range(6..=100_000))]
    frames: u32,
    /// Seed of the rendered sequence and of the faults.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Where the report goes.
    #[arg(long, default_value = "docs/RELIABILITY.md")]
    out: PathBuf,
}

pub fn reliability(args: &ReliabilityArgs) -> anyhow::Result<()> {
    let config = SweepConfig {
        frames: args.frames as usize,
        seed: args.seed,
        width: WIDTH,
        height: HEIGHT,
    };
    let bar = ProgressBar::new(sweep_runs() as u64);
    if let Ok(style) =
        ProgressStyle::with_template("fault sweep {bar:40} {pos}/{len} runs [{elapsed}]")
    {
        bar.set_style(style);
    }
    let result = sweep(config, &|| bar.inc(1));
    bar.finish_and_clear();
    let result = result?;
    let command = format!(
        "stereocal reliability --frames {} --seed {}",
        args.frames, args.seed
    );
    let text = markdown(&result, &command);
    std::fs::write(&args.out, &text)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    print!("{text}");
    eprintln!("wrote {}", args.out.display());
    anyhow::ensure!(
        passed(&result),
        "faults led to wrong estimates or to frames lost after the burst (see {})",
        args.out.display()
    );
    Ok(())
}
