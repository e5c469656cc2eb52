//! The `stereocal` command line (the contract is in the architecture document).

mod options;
mod output;
mod real;
mod synthetic;

use clap::{Parser, Subcommand};

/// Online verge-angle calibration of an active stereo head.
#[derive(Debug, Parser)]
#[command(name = "stereocal", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// The main job on the built-in road sequence: fabric model → wire → host.
    Demo(synthetic::DemoArgs),
    /// Estimate the verge of a recorded stereo sequence.
    Run(real::RunArgs),
    /// Run a rendered ground-truth sequence and report the errors.
    Eval(synthetic::EvalArgs),
    /// Write a rendered sequence (images, calib.toml, truth.csv) to a directory.
    Synth(synthetic::SynthArgs),
}

impl Cli {
    pub fn run(&self) -> anyhow::Result<()> {
        match &self.command {
            Command::Demo(a) => synthetic::demo(a),
            Command::Run(a) => real::run(a),
            Command::Eval(a) => synthetic::eval(a),
            Command::Synth(a) => synthetic::synth(a),
        }
    }
}
