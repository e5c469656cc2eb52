//! `stereocal eval`, `stereocal demo` and `stereocal synth`: rendered sequences with exact
//! ground truth.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use stereocal::output::summary::{Residual, Summary};
use stereocal::session::SessionConfig;
use stereocal_synth::{SceneKind, Sequence, SequenceConfig, TrajectoryKind};
use stereocal_tools::eval::evaluate;

use crate::options::{EstimateArgs, SizeArgs};
use crate::output::{finish, progress_bar, Finish};

/// The sequence to render.
#[derive(Debug, Clone, Args)]
pub struct SceneArgs {
    /// Built-in scene: road, lab or sparse.
    #[arg(long, default_value = "road")]
    scene: SceneKind,
    /// Frame pairs to render.
    #[arg(long, default_value_t = 200, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    frames: u32,
    /// Seed of the scene layout, trajectory, noise and drops.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Head motion (default: the scene's own: fixed on the road, manual moves elsewhere).
    #[arg(long)]
    trajectory: Option<TrajectoryKind>,
    #[command(flatten)]
    size: SizeArgs,
    /// The verge the `fixed` trajectory holds, degrees (toe-in positive).
    #[arg(long, default_value_t = stereocal_synth::FIXED_VERGE_DEG, allow_negative_numbers = true)]
    verge: f64,
    /// The left camera's focal length in pixels (default: a 56° horizontal field of view).
    #[arg(long)]
    focal: Option<f64>,
    /// Distance between the optical centres, metres.
    #[arg(long, default_value_t = stereocal_synth::BASELINE_M)]
    baseline: f64,
    /// The right camera's fixed pitch, degrees, not written into calib.toml (a misalignment
    /// for `--model general` to find).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pitch: f64,
}

impl SceneArgs {
    fn sequence(&self) -> anyhow::Result<Sequence> {
        let mut config = SequenceConfig::for_scene(self.scene);
        config.frames = self.frames as usize;
        config.seed = self.seed;
        if let Some(t) = self.trajectory {
            config.trajectory = t;
        }
        self.size.apply(&mut config);
        config.fixed_verge_deg = self.verge;
        config.focal_px = self.focal;
        config.baseline_m = self.baseline;
        config.right_pitch_deg = self.pitch;
        Sequence::builtin(self.scene, config)
            .with_context(|| format!("cannot build the `{}` sequence", self.scene))
    }
}

#[derive(Debug, Clone, Args)]
pub struct EvalArgs {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    estimate: EstimateArgs,
    /// Also write verge.csv and verge.png here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print the summary as one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Clone, Args)]
pub struct DemoArgs {
    /// Frame pairs of the demo sequence.
    #[arg(long, default_value_t = 300, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    frames: u32,
    /// Seed of the demo sequence.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Where verge.csv and verge.png go.
    #[arg(long, default_value = "out/demo")]
    out: PathBuf,
    /// Print the summary as one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

#[derive(Debug, Clone, Args)]
pub struct SynthArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Directory to create (must not exist or be empty): left/, right/, calib.toml,
    /// truth.csv, frames.csv, encoders.csv.
    #[arg(long)]
    out: PathBuf,
}

pub fn eval(args: &EvalArgs) -> anyhow::Result<()> {
    let sequence = args.scene.sequence()?;
    let title = format!(
        "stereocal eval: {} ({}), seed {}",
        args.scene.scene,
        sequence.config().trajectory,
        args.scene.seed
    );
    run_sequence(
        &sequence,
        args.estimate.session_config(),
        Finish {
            out: args.out.as_deref(),
            matches: false,
            json: args.json,
            title: &title,
            json_extra: Default::default(),
        },
    )
}

/// The demo: the road scene with fig. 5.1's manual verge moves, default settings.
pub fn demo(args: &DemoArgs) -> anyhow::Result<()> {
    let scene = SceneArgs {
        scene: SceneKind::Road,
        frames: args.frames,
        seed: args.seed,
        trajectory: Some(TrajectoryKind::Manual),
        size: SizeArgs::default(),
        verge: stereocal_synth::FIXED_VERGE_DEG,
        focal: None,
        baseline: stereocal_synth::BASELINE_M,
        pitch: 0.0,
    };
    let sequence = scene.sequence()?;
    let title = format!(
        "stereocal demo: road, manual verge moves, seed {}",
        args.seed
    );
    run_sequence(
        &sequence,
        SessionConfig::default(),
        Finish {
            out: Some(&args.out),
            matches: false,
            json: args.json,
            title: &title,
            json_extra: Default::default(),
        },
    )
}

fn run_sequence(
    sequence: &Sequence,
    config: SessionConfig,
    finish_with: Finish<'_>,
) -> anyhow::Result<()> {
    let bar = progress_bar(sequence.len() as u64, "rendering and estimating");
    let (records, cost) = evaluate(sequence, config, &mut |_| bar.inc(1))?;
    bar.finish_and_clear();
    let (w, h) = sequence.image_size();
    let summary = Summary::from_records(&records, Residual::Keep, cost.into());
    finish(&records, &summary, true, (w, h), finish_with)
}

pub fn synth(args: &SynthArgs) -> anyhow::Result<()> {
    let sequence = args.scene.sequence()?;
    let bar = progress_bar(sequence.len() as u64, "rendering");
    sequence.write_sequence_with(&args.out, &|_| bar.inc(1))?;
    bar.finish_and_clear();
    eprintln!(
        "wrote {} frame pairs, calib.toml and truth.csv to {}",
        sequence.len(),
        args.out.display()
    );
    Ok(())
}
