//! `stereocal reliability`: the fault sweep of `stereocal_tools::reliability`, written as
//! `docs/RELIABILITY.md`; with `--soak N`, the soak of `stereocal_tools::soak` instead, written as
//! its own section of the same file (each rewrites only its own part).

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use stereocal::output::output_dir::write_atomically;
use stereocal_tools::reliability::{markdown, passed, sweep, sweep_runs, FaultKind, SweepConfig};
use stereocal_tools::soak::{self, SoakConfig};

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
    /// Instead of the sweep, soak this many frame pairs through a session with faults on
    /// all the time, and write the soak's section of the report.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=10_000_000))]
    soak: Option<u32>,
    /// Rate of every fault kind during the soak (per bit, byte or packet).
    #[arg(long, default_value_t = 1e-7, value_parser = parse_rate)]
    soak_rate: f64,
    /// Frame size of the soak, `WIDTHxHEIGHT`.
    #[arg(long, default_value = "320x240", value_parser = parse_size)]
    soak_size: (u32, u32),
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once('x')
        .ok_or_else(|| format!("{s:?} is not WIDTHxHEIGHT"))?;
    let parse = |v: &str| v.trim().parse::<u32>().map_err(|e| format!("{v:?}: {e}"));
    Ok((parse(w)?, parse(h)?))
}

fn parse_rate(s: &str) -> Result<f64, String> {
    let rate: f64 = s.parse().map_err(|e| format!("{e}"))?;
    if (0.0..=1.0).contains(&rate) {
        Ok(rate)
    } else {
        Err(format!("{rate} is not a probability in [0, 1]"))
    }
}

/// Rendered pairs the soak cycles through.
const SOAK_CYCLE: usize = 30;
/// Frames between two samples of the resident set.
const SOAK_SAMPLE_EVERY: usize = 500;

pub fn reliability(args: &ReliabilityArgs) -> anyhow::Result<()> {
    if let Some(frames) = args.soak {
        return run_soak(args, frames);
    }
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
    let mut text = markdown(&result, &command);
    // Keep the soak's section, which only `--soak` rewrites.
    if let Some(section) = std::fs::read_to_string(&args.out)
        .ok()
        .as_deref()
        .and_then(soak::section)
    {
        text = soak::splice(&text, section);
    }
    write_atomically(&args.out, text.as_bytes())?;
    print!("{text}");
    eprintln!("wrote {}", args.out.display());
    anyhow::ensure!(
        passed(&result),
        "faults led to wrong estimates or to frames lost after the burst (see {})",
        args.out.display()
    );
    Ok(())
}

fn run_soak(args: &ReliabilityArgs, frames: u32) -> anyhow::Result<()> {
    let config = SoakConfig {
        frames: frames as usize,
        cycle: SOAK_CYCLE,
        seed: args.seed,
        width: args.soak_size.0,
        height: args.soak_size.1,
        kind: FaultKind::All,
        rate: args.soak_rate,
        sample_every: SOAK_SAMPLE_EVERY,
    };
    let bar = ProgressBar::new(u64::from(frames));
    if let Ok(style) = ProgressStyle::with_template("soak {bar:40} {pos}/{len} frames [{elapsed}]")
    {
        bar.set_style(style);
    }
    let result = soak::soak(config, &|done| bar.set_position(done as u64));
    bar.finish_and_clear();
    let result = result?;
    let command = format!(
        "stereocal reliability --soak {frames} --soak-rate {:e} --soak-size {}x{} --seed {}",
        args.soak_rate, args.soak_size.0, args.soak_size.1, args.seed
    );
    let section = soak::markdown(&result, &command);
    let doc = match std::fs::read_to_string(&args.out) {
        Ok(doc) => doc,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
        Err(e) => {
            return Err(e).with_context(|| format!("cannot read {}", args.out.display()));
        }
    };
    write_atomically(&args.out, soak::splice(&doc, &section).as_bytes())?;
    print!("{section}");
    eprintln!("wrote the soak section of {}", args.out.display());
    anyhow::ensure!(
        result.passed(),
        "the soak gave wrong estimates, missed the accuracy bar or grew in memory (see {})",
        args.out.display()
    );
    Ok(())
}
