//! `stereocal inject`: a real rectified pair turned into a sequence with an exact verge per
//! frame (pure-rotation homographies), for `stereocal run --truth`.

use std::path::PathBuf;

use anyhow::Context;
use clap::{Args, ValueEnum};
use image::GrayImage;
use stereocal::calib::Calibration;
use stereocal::sequence::load_gray;
use stereocal::synth::injected::{write_injected, Motion};

use super::output::progress_bar;

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MotionArg {
    /// Both cameras yaw on their own: the verge sweeps about ±3°.
    Moving,
    /// Verge fixed at 1.5° while the head turns (the view changes).
    Fixed,
}

#[derive(Debug, Clone, Args)]
pub struct InjectArgs {
    /// Left image of a rectified pair.
    #[arg(long)]
    left_image: PathBuf,
    /// Right image of the pair.
    #[arg(long)]
    right_image: PathBuf,
    /// Calibration of the rectified pair, in any format `run` reads.
    #[arg(long)]
    calib: PathBuf,
    /// Frame pairs to write.
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    frames: u32,
    /// Head motion.
    #[arg(long, value_enum, default_value_t = MotionArg::Moving)]
    motion: MotionArg,
    /// Directory to create (must not exist or be empty): left/, right/, calib.toml, truth.csv.
    #[arg(long)]
    out: PathBuf,
}

pub fn inject(args: &InjectArgs) -> anyhow::Result<()> {
    let calib = Calibration::load(&args.calib)?;
    // The injected yaws are the truth only when they start from a parallel head.
    anyhow::ensure!(
        calib.extrinsics.is_zero(),
        "calibration {}: describes an unrectified pair (verge {:.4}°, pitch {:.4}°, roll {:.4}°); \
         inject needs a rectified one",
        args.calib.display(),
        calib.extrinsics.verge_deg,
        calib.extrinsics.pitch_deg,
        calib.extrinsics.roll_deg
    );
    let image = |path: &PathBuf| -> anyhow::Result<GrayImage> {
        let g = load_gray(path)?;
        GrayImage::from_raw(g.width as u32, g.height as u32, g.pixels)
            .with_context(|| format!("{}: decoded size does not match its pixels", path.display()))
    };
    let (left, right) = (image(&args.left_image)?, image(&args.right_image)?);
    let motion = match args.motion {
        MotionArg::Moving => Motion::Moving,
        MotionArg::Fixed => Motion::Fixed,
    };
    let bar = progress_bar(u64::from(args.frames), "warping");
    write_injected(
        &args.out,
        &left,
        &right,
        &calib,
        motion,
        args.frames as usize,
        &|_| bar.inc(1),
    )?;
    bar.finish_and_clear();
    eprintln!(
        "wrote {} injected frame pairs, calib.toml and truth.csv to {}",
        args.frames,
        args.out.display()
    );
    Ok(())
}
