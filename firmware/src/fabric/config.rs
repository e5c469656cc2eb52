//! Run-time configuration of the front end: what the soft-core writes into the register map
//! before a frame. The fabric latches [`Config`] from its registers (a driver's validated
//! [`FabricConfig`] converts with `From`); the model checks it against the register map's
//! ranges and the memories it was built with ([`Config::validate`]).

use stereocal_hdl::regs::{self, max_offset, octaves, output_mode};
use stereocal_hdl::FabricConfig;

use crate::fabric::geometry::octave_dims;

/// Number of octaves the fabric has memories for: the register map's `max_octaves`.
pub const MAX_OCTAVES: usize = regs::MAX_OCTAVES as usize;

/// Front-end configuration (one register each in the register map).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Config {
    /// Input width in pixels (octave 0).
    pub width: u16,
    /// Input height in rows (octave 0).
    pub height: u16,
    /// Number of octaves computed, 1..=4.
    pub octaves: u8,
    /// An extremum needs `|DoG| > contrast_threshold`; DoG units are grey levels in Q8.8.
    pub contrast_threshold: u16,
    /// Edge rejection ratio `r` (Lowe uses 10): keep iff `Tr²·r < (r+1)²·Det`. 0 disables.
    pub edge_ratio: u8,
    /// Scale image the Sobel stage reads in every octave: 0 = G0 .. 3 = G3 (default 1 = G1).
    pub sobel_scale: u8,
    /// Largest accepted refinement offset per axis, raw Q2.13 (4096 = 0.5 sample).
    pub max_offset: u16,
}

impl Config {
    /// Defaults for a `width` x `height` frame: 4 octaves, contrast 1.0 grey level,
    /// edge ratio 10, Sobel on G1, offsets up to 0.5.
    pub const fn new(width: u16, height: u16) -> Self {
        Self {
            width,
            height,
            octaves: 4,
            contrast_threshold: 1 << 8,
            edge_ratio: 10,
            sobel_scale: 1,
            max_offset: 4096,
        }
    }

    /// Checks the configuration against the register map's ranges (OCTAVES.COUNT,
    /// OUTPUT_MODE.SOBEL_SCALE, MAX_OFFSET.VALUE) and a front end whose octave `k` has
    /// memories for `max_widths[k]` pixels per row.
    pub fn validate(&self, max_widths: [usize; MAX_OCTAVES]) -> Result<(), ConfigError> {
        if octaves::COUNT.check(self.octaves.into()).is_err() {
            return Err(ConfigError::Octaves(self.octaves));
        }
        if output_mode::SOBEL_SCALE
            .check(self.sobel_scale.into())
            .is_err()
        {
            return Err(ConfigError::SobelScale(self.sobel_scale));
        }
        if max_offset::VALUE.check(self.max_offset.into()).is_err() {
            return Err(ConfigError::MaxOffset(self.max_offset));
        }
        if self.width as usize > max_widths[0] {
            return Err(ConfigError::TooWide {
                width: self.width,
                max: max_widths[0] as u16,
            });
        }
        let (w, h) = octave_dims(self.width, self.height, self.octaves - 1);
        if w < 3 || h < 3 {
            return Err(ConfigError::TooSmall {
                width: self.width,
                height: self.height,
                octaves: self.octaves,
            });
        }
        Ok(())
    }
}

/// The configuration the registers describe, in the model's terms: every register holds the
/// model's value as is (CONTRAST_THRESHOLD in Q8.8, MAX_OFFSET in raw Q2.13).
impl From<&FabricConfig> for Config {
    fn from(registers: &FabricConfig) -> Self {
        Self {
            width: registers.width,
            height: registers.height,
            octaves: registers.octaves,
            contrast_threshold: registers.contrast_threshold,
            edge_ratio: registers.edge_ratio,
            sobel_scale: registers.sobel_scale,
            max_offset: registers.max_offset,
        }
    }
}

/// Why a [`Config`] was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigError {
    /// `octaves` is not in 1..=4.
    Octaves(u8),
    /// `sobel_scale` is not in 0..=3.
    SobelScale(u8),
    /// `max_offset` is not below 1.0 (8192 raw Q2.13).
    MaxOffset(u16),
    /// `width` exceeds the line-buffer length.
    TooWide { width: u16, max: u16 },
    /// The smallest octave would be narrower or shorter than 3 pixels.
    TooSmall {
        width: u16,
        height: u16,
        octaves: u8,
    },
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Octaves(n) => write!(f, "octave count {n} is not in 1..=4"),
            Self::SobelScale(s) => write!(f, "sobel_scale {s} is not in 0..=3"),
            Self::MaxOffset(m) => write!(f, "max_offset {m} is not below 8192 (1.0 in Q2.13)"),
            Self::TooWide { width, max } => {
                write!(f, "width {width} exceeds the line buffers ({max})")
            }
            Self::TooSmall {
                width,
                height,
                octaves,
            } => {
                write!(
                    f,
                    "{width}x{height} is too small for {octaves} octaves (last octave < 3x3)"
                )
            }
        }
    }
}

impl core::error::Error for ConfigError {}
