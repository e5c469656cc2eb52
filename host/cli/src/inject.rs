//! `stereocal inject`: a real rectified pair, or a recorded rectified sequence, turned into a
//! sequence with an exact verge per frame (pure-rotation homographies), for `stereocal run
//! --truth`.

use std::path::PathBuf;

use anyhow::Context;
use clap::{ArgGroup, Args, ValueEnum};
use image::GrayImage;
use stereocal::calib::Calibration;
use stereocal::image_sequence::{load_gray, SizeLimits, StereoSequence};
use stereocal_synth::injected::{write_injected, Motion, Source, Trajectory};
use stereocal_synth::yaw_warp::Resampling;

use crate::output::progress_bar;

/// Frames written from one pair when `--frames` is not given.
const PAIR_FRAMES: u32 = 60;

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MotionArg {
    /// Both cameras yaw on their own: the verge sweeps about ±3°.
    Moving,
    /// Verge fixed at 1.5° while the head turns (the view changes).
    Fixed,
    /// The verge swings ±10°, half of it on each camera.
    Swing,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ResampleArg {
    /// Keys' cubic convolution, 4x4 taps.
    Bicubic,
    /// Lanczos of radius 3, 6x6 taps.
    Lanczos3,
    /// Lanczos of radius 5, 10x10 taps (the closest to band-limited, the slowest).
    Lanczos5,
}

#[derive(Debug, Clone, Args)]
#[command(group(ArgGroup::new("input").required(true).args(["left_image", "left"])))]
pub struct InjectArgs {
    /// Left image of a rectified pair (with --right-image; or give a sequence with --left/--right).
    #[arg(long, requires = "right_image")]
    left_image: Option<PathBuf>,
    /// Right image of the pair.
    #[arg(long, requires = "left_image")]
    right_image: Option<PathBuf>,
    /// Directory of left-camera images of a rectified sequence, paired with the right by sorted
    /// name as for `run`; frame i of the output warps pair i.
    #[arg(long, requires = "right", conflicts_with_all = ["left_image", "right_image"])]
    left: Option<PathBuf>,
    /// Directory of right-camera images of the sequence.
    #[arg(long, requires = "left")]
    right: Option<PathBuf>,
    /// Calibration of the rectified pair, in any format `run` reads.
    #[arg(long)]
    calib: PathBuf,
    /// Frame pairs to write (default: 60 from a pair, every pair of a sequence; from a
    /// sequence, its first N).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    frames: Option<u32>,
    /// Head motion.
    #[arg(long, value_enum, default_value_t = MotionArg::Moving)]
    motion: MotionArg,
    /// Where in its period the head motion starts at frame 0 (degrees): the same motion from
    /// another instant, each frame with other yaws, to draw a figure measured on injected
    /// frames again (`bench/drives.py --phase`).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    phase: f64,
    /// The warp's interpolation kernel. No kernel is exact on real pixels, and each one draws
    /// a frame's resampling error anew: `bench/drives.py --resample` shows how much of the
    /// figures that is.
    #[arg(long, value_enum, default_value_t = ResampleArg::Bicubic)]
    resample: ResampleArg,
    /// Directory to create (must not exist or be empty): left/, right/, calib.toml, truth.csv.
    #[arg(long)]
    out: PathBuf,
}

/// The frames given on the command line.
enum Input {
    Pair(GrayImage, GrayImage),
    Sequence(StereoSequence),
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
    let motion = match args.motion {
        MotionArg::Moving => Motion::Moving,
        MotionArg::Fixed => Motion::Fixed,
        MotionArg::Swing => Motion::Swing,
    };
    let resampling = match args.resample {
        ResampleArg::Bicubic => Resampling::Bicubic,
        ResampleArg::Lanczos3 => Resampling::Lanczos3,
        ResampleArg::Lanczos5 => Resampling::Lanczos5,
    };
    // clap lets through one complete form: both images, or both directories.
    let input = match (&args.left_image, &args.right_image, &args.left, &args.right) {
        (Some(l), Some(r), _, _) => Input::Pair(image(l)?, image(r)?),
        (_, _, Some(l), Some(r)) => {
            // The fabric's limits, checked here so that a sequence `run` cannot take fails
            // before anything is written.
            let limits = SizeLimits::fabric();
            Input::Sequence(StereoSequence::open(l, r, limits)?)
        }
        _ => anyhow::bail!("give --left-image and --right-image, or --left and --right"),
    };
    let (source, frames) = match &input {
        Input::Pair(left, right) => (
            Source::Pair { left, right },
            args.frames.unwrap_or(PAIR_FRAMES) as usize,
        ),
        Input::Sequence(seq) => (
            Source::Sequence(seq),
            args.frames.map_or(seq.len(), |n| n as usize),
        ),
    };
    let bar = progress_bar(frames as u64, "warping");
    write_injected(
        &args.out,
        source,
        &calib,
        Trajectory {
            motion,
            phase_deg: args.phase,
        },
        frames,
        resampling,
        &|_| bar.inc(1),
    )?;
    bar.finish_and_clear();
    eprintln!(
        "wrote {frames} injected frame pairs, calib.toml and truth.csv to {}",
        args.out.display()
    );
    Ok(())
}
