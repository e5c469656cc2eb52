//! The subcommands and what each runs (their contract: `docs/ARCHITECTURE.md`, "The command
//! line").

use anyhow::Context;
use clap::{Parser, Subcommand};
use stereocal::output::output_dir::remove_staged_on_interrupt;

use crate::{experiment, hil, inject, live, real, reliability, synthetic};

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
    /// The `eval` run with the firmware ELF on the emulated soft-core (QEMU).
    Hil(hil::HilArgs),
    /// Listen to a head that grabs its own frames (serial port, TCP or Unix socket).
    Live(live::LiveArgs),
    /// Turn a real rectified pair into a sequence with an exactly injected verge per frame.
    Inject(inject::InjectArgs),
    /// Reproduce one of the thesis' experiments (or all) as CSV tables and PNG figures.
    Experiment(experiment::ExperimentArgs),
    /// Sweep link faults over a rendered sequence and write docs/RELIABILITY.md.
    Reliability(reliability::ReliabilityArgs),
}

impl Cli {
    pub fn run(&self) -> anyhow::Result<()> {
        // `live` stops at Ctrl-C and writes what it received; every other command ends there,
        // taking its staged files with it.
        if !matches!(self.command, Command::Live(_)) {
            remove_staged_on_interrupt().context("cannot install the Ctrl-C handler")?;
        }
        match &self.command {
            Command::Demo(a) => synthetic::demo(a),
            Command::Run(a) => real::run(a),
            Command::Eval(a) => synthetic::eval(a),
            Command::Synth(a) => synthetic::synth(a),
            Command::Hil(a) => hil::hil(a),
            Command::Live(a) => live::live(a),
            Command::Inject(a) => inject::inject(a),
            Command::Experiment(a) => experiment::experiment(a),
            Command::Reliability(a) => reliability::reliability(a),
        }
    }
}
