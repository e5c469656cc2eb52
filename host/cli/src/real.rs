//! `stereocal run`: a recorded stereo sequence (a directory per camera) through the chain.

use std::path::PathBuf;
use std::sync::mpsc;

use anyhow::Context;
use clap::Args;
use stereocal::calib::Calibration;
use stereocal::encoders::read_encoders_csv;
use stereocal::image_sequence::{GrayFrame, SizeLimits, StereoSequence};
use stereocal::output::record::FrameRecord;
use stereocal::output::summary::{Residual, Summary};
use stereocal::output::verge_csv::read_truth_csv;
use stereocal::session::{tuned_fabric_config, Session, SessionConfig};
use stereocal_hdl::regs::MAX_HEIGHT;

use crate::options::EstimateArgs;
use crate::output::{finish, keep, progress_bar, Finish};

/// Pairs decoded ahead of the chain.
const LOOKAHEAD: usize = 3;

#[derive(Debug, Clone, Args)]
pub struct RunArgs {
    /// Directory of left-camera images (PNG, PGM, JPEG), paired with the right by sorted name.
    #[arg(long)]
    left: PathBuf,
    /// Directory of right-camera images.
    #[arg(long)]
    right: PathBuf,
    /// Calibration file, recognised by content: the project's TOML (baseline_m, [left] and
    /// [right] fx, fy, cx, cy, optional k1, k2, p1, p2, k3 and [extrinsics]), OpenCV's
    /// stereoCalibrate results written by cv::FileStorage (K1, D1, K2, D2, R, T; T in metres),
    /// a Kalibr camchain.yaml (cam0, cam1) or KITTI's calib.txt (P0, P1 or P_rect_00, P_rect_01).
    #[arg(long)]
    calib: PathBuf,
    /// Ground truth `frame,verge_deg`: the error statistics are reported against it. A real
    /// rig's own constant residual verge is removed first.
    #[arg(long)]
    truth: Option<PathBuf>,
    /// The head's own verge per frame, from its joint encoders or commanded angles:
    /// `frame,left_yaw_deg,right_yaw_deg` or `frame,verge_deg` (frames without a row have no
    /// reading). The filter predicts each frame's verge change from it instead of detecting it.
    #[arg(long)]
    encoders: Option<PathBuf>,
    /// Where verge.csv and verge.png (and matches.csv) go.
    #[arg(long, default_value = "out/run")]
    out: PathBuf,
    /// Frame rate of the sequence (the filter's time step).
    #[arg(long, default_value_t = 30.0, value_parser = parse_fps)]
    fps: f64,
    /// Also write matches.csv into --out: every frame's point pairs consistent with its
    /// estimate (pixels, weights), to compare two runs match by match.
    #[arg(long)]
    matches: bool,
    #[command(flatten)]
    estimate: EstimateArgs,
    /// Print the summary as one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &RunArgs) -> anyhow::Result<()> {
    // Everything that can be checked before the first frame is, so a bad call writes nothing.
    let calib = Calibration::load(&args.calib)?;
    let limits = SizeLimits::fabric();
    let sequence = StereoSequence::open(&args.left, &args.right, limits)?;
    let truth = match &args.truth {
        Some(path) => {
            let truth = read_truth_csv(path)?;
            anyhow::ensure!(
                truth.len() >= sequence.len(),
                "{}: has {} frames, the sequence {}",
                path.display(),
                truth.len(),
                sequence.len()
            );
            Some(truth)
        }
        None => None,
    };
    let encoders = match &args.encoders {
        Some(path) => Some(read_encoders_csv(path, sequence.len())?),
        None => None,
    };
    let first = sequence.pair(0, None)?;
    let size = (first.0.width, first.0.height);
    anyhow::ensure!(
        size.1 <= MAX_HEIGHT as usize,
        "frame 0: image is {}x{}; the fabric takes at most {MAX_HEIGHT} lines",
        size.0,
        size.1
    );
    // Every octave must have whole pixels, so the fabric's window is a multiple of
    // 2^(octaves-1) on each side; like a grabber's region of interest it starts at the
    // top-left corner, which keeps the intrinsics valid.
    let config = SessionConfig {
        keep_pairs: args.matches,
        ..args.estimate.session_config()
    };
    let step = 1usize << (tuned_fabric_config(16, 16, config.sobel_output).octaves - 1);
    let window = (size.0 / step * step, size.1 / step * step);
    if window != size {
        eprintln!(
            "note: the fabric takes {}x{} windows of these {}x{} images (sides must be multiples of {step})",
            window.0, window.1, size.0, size.1
        );
    }
    let mut session = Session::new(calib, window.0 as u16, window.1 as u16, config)
        .context("cannot start the device")?;

    let bar = progress_bar(sequence.len() as u64, "estimating");
    let period_us = 1e6 / args.fps;
    let records = std::thread::scope(|scope| -> anyhow::Result<Vec<FrameRecord>> {
        let (tx, rx) = mpsc::sync_channel::<anyhow::Result<(GrayFrame, GrayFrame)>>(LOOKAHEAD);
        let sequence = &sequence;
        scope.spawn(move || {
            // Frame 0 is decoded already (for the size); the others are decoded here, ahead.
            let mut first = Some(first);
            for frame in 0..sequence.len() {
                let pair = first
                    .take()
                    .map_or_else(|| sequence.pair(frame, Some(size)), Ok)
                    .map_err(anyhow::Error::from)
                    .and_then(|(l, r)| {
                        l.cropped(window.0, window.1)
                            .zip(r.cropped(window.0, window.1))
                            .context("window larger than the frame")
                    });
                let stop = pair.is_err();
                if tx.send(pair).is_err() || stop {
                    break;
                }
            }
        });
        let mut records = Vec::with_capacity(sequence.len());
        for (frame, pair) in rx.into_iter().enumerate() {
            let (l, r) = pair?;
            if let Some(verge) = encoders.as_ref().and_then(|e| e[frame]) {
                session.encoder_reading(verge);
            }
            let record = session.submit(
                frame,
                Some((&l.pixels, &r.pixels)),
                window,
                (frame as f64 * period_us).round() as u64,
                truth.as_ref().map(|t| t[frame]),
            )?;
            if let Some(record) = record {
                keep(&mut records, record, &bar);
            }
        }
        while let Some(record) = session.flush()? {
            keep(&mut records, record, &bar);
        }
        Ok(records)
    })?;
    bar.finish_and_clear();
    let cost = session.cost();
    let summary = Summary::from_records(&records, Residual::Remove, cost.into());
    let title = format!("stereocal run: {}", args.left.display());
    finish(
        &records,
        &summary,
        truth.is_some(),
        (window.0 as u32, window.1 as u32),
        Finish {
            out: Some(&args.out),
            matches: args.matches,
            json: args.json,
            title: &title,
            json_extra: Default::default(),
        },
    )
}

fn parse_fps(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if v.is_finite() && v > 0.0 && v <= 10_000.0 {
        Ok(v)
    } else {
        Err(format!("{v} is outside (0, 10000]"))
    }
}
