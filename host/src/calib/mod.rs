//! The stereo head's calibration and the pixel ↔ calibrated-coordinate maps.
//!
//! The project's format is TOML (`docs/ARCHITECTURE.md`, "Calibration (TOML)"): top-level
//! `baseline_m`, and `[left]` / `[right]` tables with `fx, fy, cx, cy` in pixels.
//! **Extensions:** each camera table may also carry the OpenCV radial-tangential distortion
//! `k1, k2, p1, p2, k3` (all default to 0), which raw (unrectified) cameras such as EuRoC need,
//! and an `[extrinsics]` table with the pose of an unrectified pair (see [`Extrinsics`];
//! absent: a rectified pair). Any other key is an error that names it.
//!
//! [`Calibration::load`] also reads the files users already have, recognised by content (see
//! [`Format`]): OpenCV's `stereoCalibrate` results written by `cv::FileStorage` (YAML or JSON),
//! a Kalibr `camchain.yaml` and KITTI's `calib.txt`. Each maps into the same [`Calibration`],
//! so the TOML can say everything they can.

mod extrinsics;
mod format;
mod kalibr;
mod kitti;
mod opencv;
mod rig;
mod yaml;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use extrinsics::{Extrinsics, PoseError, MAX_ANGLE_DEG};
pub use format::Format;

/// Why a calibration could not be read or is not usable.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CalibError {
    /// The file could not be read or written.
    #[error("calibration {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The TOML is malformed, a key is unknown or missing, or a value has the wrong type (the
    /// TOML parser's message names the key, the expected type and the line); or the YAML of an
    /// OpenCV or Kalibr file is malformed (the YAML parser's message names the line).
    #[error("calibration {path}: {message}")]
    Parse {
        /// The file, or the origin the text was given under.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// A value parsed but is physically impossible (e.g. a focal length ≤ 0).
    #[error("calibration {path}: key `{key}` {reason}")]
    Invalid {
        /// The file, or the origin the text was given under.
        path: PathBuf,
        /// The offending key, dotted as in the TOML (`right.fy`, `extrinsics.pitch_deg`).
        key: &'static str,
        /// What the value must be, worded to follow the key (`must be a finite value > 0`).
        reason: &'static str,
    },
    /// A key of an OpenCV, Kalibr or KITTI file is missing, malformed or unsupported; `key`
    /// is the file's own name for it and `line` where it stands (when the format has lines).
    #[error(
        "calibration {path}: {}key `{key}` {reason}",
        .line.map(|l| format!("line {l}: ")).unwrap_or_default()
    )]
    Key {
        /// The file, or the origin the text was given under.
        path: PathBuf,
        /// The key as the file's own format names it.
        key: String,
        /// 1-based line of the key, when the format has lines.
        line: Option<usize>,
        /// What is wrong with it, worded to follow the key (`is missing`).
        reason: String,
    },
}

impl CalibError {
    /// The error for `key` at `line` of `path`.
    fn key(path: &Path, key: &str, line: Option<usize>, reason: impl Into<String>) -> Self {
        Self::Key {
            path: path.to_owned(),
            key: key.to_owned(),
            line,
            reason: reason.into(),
        }
    }
}

/// A finite number in the notations the calibration tools write (`1.`, `-2.5e-01`, `700`).
fn number(text: &str) -> Option<f64> {
    text.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

/// Pinhole intrinsics of one camera plus optional radial-tangential distortion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraIntrinsics {
    /// Horizontal focal length in pixels, > 0.
    pub fx: f64,
    /// Vertical focal length in pixels, > 0.
    pub fy: f64,
    /// Principal point's x in pixels (pixel centres at integers).
    pub cx: f64,
    /// Principal point's y in pixels (pixel centres at integers).
    pub cy: f64,
    /// Radial distortion, OpenCV `k1` (extension; 0 when absent).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub k1: f64,
    /// Radial distortion, OpenCV `k2` (extension; 0 when absent).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub k2: f64,
    /// Tangential distortion, OpenCV `p1` (extension; 0 when absent).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub p1: f64,
    /// Tangential distortion, OpenCV `p2` (extension; 0 when absent).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub p2: f64,
    /// Radial distortion, OpenCV `k3` (extension; 0 when absent): `stereoCalibrate` fits it
    /// unless told not to.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub k3: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// Fixed-point iterations used to invert the distortion; the EuRoC lenses (k1 ≈ -0.28) converge
/// to < 1e-6 px well inside the image within this budget.
const UNDISTORT_ITERATIONS: usize = 20;

impl CameraIntrinsics {
    /// An ideal pinhole camera without distortion.
    pub fn pinhole(fx: f64, fy: f64, cx: f64, cy: f64) -> Self {
        Self {
            fx,
            fy,
            cx,
            cy,
            k1: 0.0,
            k2: 0.0,
            p1: 0.0,
            p2: 0.0,
            k3: 0.0,
        }
    }

    /// True when any distortion coefficient is non-zero.
    pub fn has_distortion(&self) -> bool {
        self.k1 != 0.0 || self.k2 != 0.0 || self.p1 != 0.0 || self.p2 != 0.0 || self.k3 != 0.0
    }

    /// Applies the radial-tangential model to undistorted calibrated coordinates.
    pub fn distort_normalized(&self, x: f64, y: f64) -> (f64, f64) {
        let r2 = x * x + y * y;
        let radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3));
        let xd = x * radial + 2.0 * self.p1 * x * y + self.p2 * (r2 + 2.0 * x * x);
        let yd = y * radial + self.p1 * (r2 + 2.0 * y * y) + 2.0 * self.p2 * x * y;
        (xd, yd)
    }

    /// Projects calibrated (undistorted, z = 1) coordinates to pixels, applying distortion.
    pub fn project(&self, x: f64, y: f64) -> (f64, f64) {
        let (xd, yd) = self.distort_normalized(x, y);
        (self.fx * xd + self.cx, self.fy * yd + self.cy)
    }

    /// Maps a pixel to calibrated coordinates (the ray (x, y, 1)), removing distortion.
    pub fn normalize(&self, u: f64, v: f64) -> (f64, f64) {
        let xd = (u - self.cx) / self.fx;
        let yd = (v - self.cy) / self.fy;
        if !self.has_distortion() {
            return (xd, yd);
        }
        // Fixed-point inversion as in OpenCV's undistortPoints: x = (xd - tangential) / radial.
        let (mut x, mut y) = (xd, yd);
        for _ in 0..UNDISTORT_ITERATIONS {
            let r2 = x * x + y * y;
            let radial = 1.0 + r2 * (self.k1 + r2 * (self.k2 + r2 * self.k3));
            let dx = 2.0 * self.p1 * x * y + self.p2 * (r2 + 2.0 * x * x);
            let dy = self.p1 * (r2 + 2.0 * y * y) + 2.0 * self.p2 * x * y;
            x = (xd - dx) / radial;
            y = (yd - dy) / radial;
        }
        (x, y)
    }

    /// Mean focal length in pixels: converts calibrated-coordinate errors to pixels.
    pub fn focal_px(&self) -> f64 {
        0.5 * (self.fx + self.fy)
    }

    fn validate(&self, path: &Path, side: Side) -> Result<(), CalibError> {
        let checks: [(&'static str, &'static str, f64, bool); 9] = [
            (
                side.key("fx"),
                "must be a finite value > 0",
                self.fx,
                self.fx > 0.0,
            ),
            (
                side.key("fy"),
                "must be a finite value > 0",
                self.fy,
                self.fy > 0.0,
            ),
            (side.key("cx"), "must be finite", self.cx, true),
            (side.key("cy"), "must be finite", self.cy, true),
            (side.key("k1"), "must be finite", self.k1, true),
            (side.key("k2"), "must be finite", self.k2, true),
            (side.key("p1"), "must be finite", self.p1, true),
            (side.key("p2"), "must be finite", self.p2, true),
            (side.key("k3"), "must be finite", self.k3, true),
        ];
        for (key, reason, value, ok) in checks {
            if !value.is_finite() || !ok {
                return Err(CalibError::Invalid {
                    path: path.to_owned(),
                    key,
                    reason,
                });
            }
        }
        Ok(())
    }
}

#[derive(Clone, Copy)]
enum Side {
    Left,
    Right,
}

impl Side {
    fn key(self, name: &'static str) -> &'static str {
        match (self, name) {
            (Side::Left, "fx") => "left.fx",
            (Side::Left, "fy") => "left.fy",
            (Side::Left, "cx") => "left.cx",
            (Side::Left, "cy") => "left.cy",
            (Side::Left, "k1") => "left.k1",
            (Side::Left, "k2") => "left.k2",
            (Side::Left, "p1") => "left.p1",
            (Side::Left, "p2") => "left.p2",
            (Side::Left, "k3") => "left.k3",
            (Side::Right, "fx") => "right.fx",
            (Side::Right, "fy") => "right.fy",
            (Side::Right, "cx") => "right.cx",
            (Side::Right, "cy") => "right.cy",
            (Side::Right, "k1") => "right.k1",
            (Side::Right, "k2") => "right.k2",
            (Side::Right, "p1") => "right.p1",
            (Side::Right, "p2") => "right.p2",
            _ => "right.k3",
        }
    }
}

/// The calibration of the stereo head: both cameras' intrinsics, the baseline length and,
/// for an unrectified pair, the pose between the cameras.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    /// Distance between the optical centres in metres; the right camera sits at (+b, 0, 0).
    pub baseline_m: f64,
    /// The left camera, whose frame at zero yaw is the head frame.
    pub left: CameraIntrinsics,
    /// The right camera.
    pub right: CameraIntrinsics,
    /// The pose at calibration time (extension; all zero, and absent from the TOML, for a
    /// rectified pair).
    #[serde(default, skip_serializing_if = "Extrinsics::is_zero")]
    pub extrinsics: Extrinsics,
}

impl Calibration {
    /// Reads and validates a calibration file in any [`Format`], recognised by content.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, CalibError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| CalibError::Io {
            path: path.to_owned(),
            source,
        })?;
        Self::from_str_any(&text, path)
    }

    /// Parses and validates a calibration in any [`Format`]; `origin` names the source in
    /// errors.
    pub fn from_str_any(text: &str, origin: impl AsRef<Path>) -> Result<Self, CalibError> {
        let path = origin.as_ref();
        match Format::detect(text) {
            Format::Toml => Self::from_toml_str(text, path),
            Format::OpenCv => opencv::parse(text, path),
            Format::OpenCvXml => Err(CalibError::Parse {
                path: path.to_owned(),
                message: "is OpenCV's XML storage, which is not read: save it as YAML or JSON \
                          (cv::FileStorage with a .yml or .json name)"
                    .into(),
            }),
            Format::Kalibr => kalibr::parse(text, path),
            Format::Kitti => kitti::parse(text, path),
        }
    }

    /// Parses and validates calibration TOML; `origin` names the source in errors.
    pub fn from_toml_str(text: &str, origin: impl AsRef<Path>) -> Result<Self, CalibError> {
        let path = origin.as_ref();
        let calib: Calibration = toml::from_str(text).map_err(|e| CalibError::Parse {
            path: path.to_owned(),
            message: e.to_string(),
        })?;
        calib.validate(path)?;
        Ok(calib)
    }

    /// Checks every value for physical sense; `path` names the source in the error.
    pub fn validate(&self, path: &Path) -> Result<(), CalibError> {
        if !(self.baseline_m.is_finite() && self.baseline_m > 0.0) {
            return Err(CalibError::Invalid {
                path: path.to_owned(),
                key: "baseline_m",
                reason: "must be a finite value > 0",
            });
        }
        self.left.validate(path, Side::Left)?;
        self.right.validate(path, Side::Right)?;
        match self.extrinsics.too_large() {
            Some((key, _)) => Err(CalibError::Invalid {
                path: path.to_owned(),
                key,
                reason: "must be finite and within ±45°",
            }),
            None => Ok(()),
        }
    }

    /// Serialises to the TOML format `from_toml_str` reads (distortion keys only when non-zero).
    pub fn to_toml_string(&self) -> String {
        // Serialising plain f64 fields into a table cannot fail.
        toml::to_string(self).unwrap_or_default()
    }

    /// Writes the calibration file.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), CalibError> {
        let path = path.as_ref();
        std::fs::write(path, self.to_toml_string()).map_err(|source| CalibError::Io {
            path: path.to_owned(),
            source,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = "baseline_m = 0.3\n[left]\nfx = 500.0\nfy = 500.0\ncx = 320.0\ncy = 240.0\n\
                        [right]\nfx = 501.0\nfy = 502.0\ncx = 321.0\ncy = 239.0\nk1 = -0.28\n";

    #[test]
    fn parses_and_round_trips() {
        let c = Calibration::from_toml_str(GOOD, "good.toml").unwrap();
        assert_eq!(c.left.fx, 500.0);
        assert_eq!(c.right.k1, -0.28);
        assert_eq!(c.left.k1, 0.0);
        let back = Calibration::from_toml_str(&c.to_toml_string(), "x").unwrap();
        assert_eq!(back, c);
    }

    #[test]
    fn unknown_key_is_named() {
        let text = GOOD.replace("cy = 240.0", "cy = 240.0\nskew = 0.0");
        let err = Calibration::from_toml_str(&text, "bad.toml").unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("bad.toml") && msg.contains("skew"), "{msg}");
    }

    #[test]
    fn wrong_type_and_missing_key_are_named() {
        let text = GOOD.replace("fx = 500.0", "fx = \"big\"");
        let msg = Calibration::from_toml_str(&text, "t.toml")
            .unwrap_err()
            .to_string();
        assert!(msg.contains("fx") || msg.contains("string"), "{msg}");
        let text = GOOD.replace("baseline_m = 0.3\n", "");
        let msg = Calibration::from_toml_str(&text, "t.toml")
            .unwrap_err()
            .to_string();
        assert!(msg.contains("baseline_m"), "{msg}");
    }

    #[test]
    fn impossible_values_are_rejected() {
        let text = GOOD.replace("fy = 502.0", "fy = -1.0");
        let err = Calibration::from_toml_str(&text, "t.toml").unwrap_err();
        assert!(err.to_string().contains("right.fy"), "{err}");
        let text = GOOD.replace("baseline_m = 0.3", "baseline_m = nan");
        let err = Calibration::from_toml_str(&text, "t.toml").unwrap_err();
        assert!(err.to_string().contains("baseline_m"), "{err}");
    }

    #[test]
    fn undistortion_inverts_distortion() {
        let cam = CameraIntrinsics {
            k1: -0.28340811,
            k2: 0.07395907,
            p1: 0.00019359,
            p2: 1.76187114e-05,
            ..CameraIntrinsics::pinhole(458.654, 457.296, 367.215, 248.375)
        };
        for &(x, y) in &[(0.0, 0.0), (0.5, -0.4), (-0.7, 0.45), (0.2, 0.1)] {
            let (u, v) = cam.project(x, y);
            let (xb, yb) = cam.normalize(u, v);
            assert!(
                (xb - x).abs() < 1e-8 && (yb - y).abs() < 1e-8,
                "{x},{y} -> {xb},{yb}"
            );
        }
    }
}
