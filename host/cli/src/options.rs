//! Flags shared by every command that estimates: the estimator's knobs and the output mode.
//!
//! The defaults are the estimator's defaults, the most accurate settings for a verge head on
//! the real drive at full speed; each flag only moves away from them.

use std::num::NonZeroU16;

use clap::{Args, ValueEnum};
use stereocal::descriptor::DescriptorMode;
use stereocal::estimator::Model;
use stereocal::link::LinkProtection;
use stereocal::matching::{Gate, MatchConfig};
use stereocal::misalignment::WindowConfig;
use stereocal::session::SessionConfig;
use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_synth::SequenceConfig;

/// Essential-matrix model (`--model`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ModelArg {
    /// Both cameras only yaw (the thesis' 4-unknown model).
    Constrained,
    /// Free relative rotation (5 DOF), for heads that also tilt.
    General,
}

/// The head's fixed misalignments (`--misalignment`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum MisalignmentArg {
    /// Each frame alone: the verge absorbs the head's fixed pitch and roll.
    Off,
    /// Learn the right camera's pitch and roll over a sliding window of frames and refit
    /// each frame's verge with them held.
    Window,
    /// As `window`, and the baseline's tilt too.
    WindowTilt,
    /// As `window`, the roll alone: the pitch held at the calibration's (the default).
    WindowRoll,
    /// As `window-roll`, and each frame's own pitch, held to the frames' mean by their
    /// learned spread.
    WindowFramePitch,
}

/// What the fabric streams besides the points (`--sobel`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum SobelArg {
    /// Every Sobel pixel of octave 0 (the thesis' mode; enables sub-pixel refinement).
    Rows,
    /// 16x16 patches around each point (low bandwidth).
    Patches,
}

/// Descriptor layout (`--descriptor`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DescriptorArg {
    /// 4x4 cells x 8 orientation bins = 128 elements (Lowe, thesis 4.4.2).
    Full,
    /// 2x2 cells x 4 orientation bins = 16 elements (thesis 6.3; less to compare, less
    /// distinctive).
    Reduced16,
}

#[derive(Debug, Clone, Args)]
pub struct EstimateArgs {
    /// Robust RANSAC start for the refinement (the default; `--no-ransac` turns it off).
    #[arg(long, overrides_with = "no_ransac")]
    ransac: bool,
    /// Start the refinement from parallel cameras instead of a RANSAC hypothesis.
    #[arg(long, overrides_with = "ransac")]
    no_ransac: bool,
    /// Lowe's ratio test: best distance < RATIO x second best, in (0, 1).
    #[arg(long, default_value_t = MatchConfig::default().ratio, value_parser = parse_ratio)]
    ratio: f32,
    /// Keep only the N best matches (default: every match that passes the tests).
    #[arg(long, value_parser = parse_best)]
    best: Option<usize>,
    /// Left-right consistency off: a left point's best right match need not choose it back.
    #[arg(long)]
    no_cross_check: bool,
    /// Vertical-disparity gate of a fixed width: right candidates within this many pixels of
    /// the left point's row (full resolution). Default: the epipolar band the calibration, the
    /// image size and the head's range of poses allow.
    #[arg(long, value_parser = parse_pixels)]
    max_vertical_px: Option<f32>,
    /// No vertical-disparity gate: every right point is a candidate.
    #[arg(long, conflicts_with = "max_vertical_px")]
    no_vertical_gate: bool,
    /// Descriptor layout.
    #[arg(long, value_enum, default_value_t = DescriptorArg::Full)]
    descriptor: DescriptorArg,
    /// Rotate each descriptor window to the keypoint's dominant gradient orientation (off:
    /// the unrotated mode, right for a head whose cameras do not roll).
    #[arg(long)]
    rotate: bool,
    /// Essential-matrix model.
    #[arg(long, value_enum, default_value_t = ModelArg::Constrained)]
    model: ModelArg,
    /// The head's fixed misalignments: each frame alone, or learned over a window
    /// (constrained model only; the general model frees them in every frame). The default
    /// learns the roll alone, which no view trades for the verge; `window` adds the pitch,
    /// which a road view does trade for it (README, "The head's fixed misalignments").
    #[arg(long, value_enum, default_value_t = MisalignmentArg::WindowRoll)]
    misalignment: MisalignmentArg,
    /// Also match the strongest Sobel pixel of every PX x PX cell of the left image, beside
    /// the keypoints: lowers the verge's noise where the matches' sub-pixel noise limits it,
    /// at a refinement per point (README, "Grid points"). Default: keypoints only.
    #[arg(long, value_name = "PX")]
    grid: Option<NonZeroU16>,
    /// Fit each refinement window's horizontal scale and shear beside its translation: the
    /// disparity gradient of a slanted surface, which shears the right window against the
    /// left one. Lowers the rendered road's errors at large verges, raises the KITTI
    /// drive's (README, "Disparity gradient"). Default: translation only.
    #[arg(long)]
    disparity_gradient: bool,
    /// Sobel output mode of the fabric.
    #[arg(long, value_enum, default_value_t = SobelArg::Rows)]
    sobel: SobelArg,
    /// Guard a link that damages bytes: forward error correction, 64-pixel row segments and
    /// 8-point batches, so that a damaged packet costs little and most are repaired (7.7 %
    /// more bytes for the parity, about 20 % for the smaller packets; docs/RELIABILITY.md).
    #[arg(long)]
    noisy_link: bool,
}

impl EstimateArgs {
    pub fn session_config(&self) -> SessionConfig {
        let mut config = SessionConfig::default();
        let e = &mut config.estimator;
        if self.no_ransac {
            e.ransac = None;
        }
        e.matching.ratio = self.ratio;
        e.matching.best_n = self.best;
        e.matching.cross_check = !self.no_cross_check;
        e.matching.gate = match (self.no_vertical_gate, self.max_vertical_px) {
            (true, _) => Gate::Off,
            (false, Some(px)) => Gate::Rows(px),
            (false, None) => Gate::Epipolar,
        };
        e.descriptor.mode = match self.descriptor {
            DescriptorArg::Full => DescriptorMode::Full128,
            DescriptorArg::Reduced16 => DescriptorMode::Reduced16,
        };
        e.descriptor.rotate = self.rotate;
        if let Some(guided) = &mut e.guided {
            guided.grid_px = self.grid;
        }
        if let Some(subpixel) = &mut e.subpixel {
            subpixel.disparity_gradient = self.disparity_gradient;
        }
        e.model = match self.model {
            ModelArg::Constrained => Model::Constrained,
            ModelArg::General => Model::General,
        };
        if self.noisy_link {
            config.link = LinkProtection::noisy();
        }
        config.misalignment = match self.misalignment {
            MisalignmentArg::Off => None,
            MisalignmentArg::Window => Some(WindowConfig::default()),
            MisalignmentArg::WindowTilt => Some(WindowConfig {
                tilt: true,
                ..WindowConfig::default()
            }),
            MisalignmentArg::WindowRoll => Some(WindowConfig::roll()),
            MisalignmentArg::WindowFramePitch => Some(WindowConfig::roll_and_frame_pitch()),
        };
        config.sobel_output = match self.sobel {
            SobelArg::Rows => SobelOutput::Rows,
            SobelArg::Patches => SobelOutput::Patches,
        };
        config
    }
}

fn parse_ratio(s: &str) -> Result<f32, String> {
    let r: f32 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if r > 0.0 && r < 1.0 {
        Ok(r)
    } else {
        Err(format!("{r} is outside (0, 1)"))
    }
}

fn parse_pixels(s: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("{v} is not a distance in pixels"))
    }
}

fn parse_best(s: &str) -> Result<usize, String> {
    let n: usize = s
        .parse()
        .map_err(|_| format!("`{s}` is not a whole number"))?;
    if n == 0 {
        Err("must be at least 1".into())
    } else {
        Ok(n)
    }
}

/// The rendered frame size (`--width`, `--height`), for the commands that render.
#[derive(Debug, Clone, Copy, Default, Args)]
pub struct SizeArgs {
    /// Rendered frame width in pixels (default: the scene's, 640).
    #[arg(long, value_parser = clap::value_parser!(u32).range(16..=8192))]
    width: Option<u32>,
    /// Rendered frame height in pixels (default: the scene's, 480).
    #[arg(long, value_parser = clap::value_parser!(u32).range(16..=8192))]
    height: Option<u32>,
}

impl SizeArgs {
    /// Sets the size in `config` where a flag gave one.
    pub fn apply(&self, config: &mut SequenceConfig) {
        config.width = self.width.unwrap_or(config.width);
        config.height = self.height.unwrap_or(config.height);
    }
}
