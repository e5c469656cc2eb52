//! The calibration the stereo tools write — each camera's K and distortion, and R, T with
//! `x_right = R x_left + T` — mapped into [`Calibration`]. OpenCV, Kalibr and KITTI readers
//! each gather these with the keys and lines of their own files, then share this conversion.

use std::path::Path;

use nalgebra::{Matrix3, Vector3};

use super::extrinsics::{Extrinsics, PoseError};
use super::{CalibError, Calibration, CameraIntrinsics};

/// Where a value came from: the file's own key name and its line, when the format has lines.
#[derive(Debug, Clone, PartialEq)]
pub struct Origin {
    pub key: String,
    pub line: Option<usize>,
}

impl Origin {
    pub fn new(key: impl Into<String>, line: Option<usize>) -> Self {
        Self {
            key: key.into(),
            line,
        }
    }

    /// The error naming this key and line in `path`.
    pub fn error(&self, path: &Path, reason: impl Into<String>) -> CalibError {
        CalibError::key(path, &self.key, self.line, reason)
    }
}

/// OpenCV's distortion coefficients in order; the model here is the first five.
const OPENCV_DISTORTION: [&str; 14] = [
    "k1", "k2", "p1", "p2", "k3", "k4", "k5", "k6", "s1", "s2", "s3", "s4", "tauX", "tauY",
];

/// The pinhole parameters `fx, fy, cx, cy` of a 3x3 camera matrix (row-major), which must have
/// zero skew and the last row `0 0 1`.
pub fn pinhole_from_k(k: &[f64], at: &Origin, path: &Path) -> Result<[f64; 4], CalibError> {
    let &[fx, skew, cx, r10, fy, cy, r20, r21, r22] = k else {
        return Err(at.error(
            path,
            format!("has {} values; a camera matrix has 9", k.len()),
        ));
    };
    if skew != 0.0 {
        return Err(at.error(
            path,
            format!("has skew {skew}; only cameras without skew are supported"),
        ));
    }
    if (r10, r20, r21, r22) != (0.0, 0.0, 0.0, 1.0) {
        return Err(at.error(path, "is not a camera matrix [fx 0 cx; 0 fy cy; 0 0 1]"));
    }
    pinhole(fx, fy, cx, cy, at, path)
}

/// Checks a pinhole camera's four parameters.
pub fn pinhole(
    fx: f64,
    fy: f64,
    cx: f64,
    cy: f64,
    at: &Origin,
    path: &Path,
) -> Result<[f64; 4], CalibError> {
    if !(fx.is_finite() && fx > 0.0 && fy.is_finite() && fy > 0.0) {
        return Err(at.error(
            path,
            format!("has focal lengths {fx}, {fy}; both must be finite and > 0"),
        ));
    }
    if !(cx.is_finite() && cy.is_finite()) {
        return Err(at.error(path, "has a non-finite principal point"));
    }
    Ok([fx, fy, cx, cy])
}

/// A camera from its pinhole parameters and OpenCV distortion coefficients `k1, k2, p1, p2
/// [, k3 [, k4, k5, k6 [, s1..s4 [, tauX, tauY]]]]` (none: no distortion). The model here is
/// the first five; any further coefficient must be zero, never silently dropped.
pub fn camera(
    [fx, fy, cx, cy]: [f64; 4],
    d: &[f64],
    at: &Origin,
    path: &Path,
) -> Result<CameraIntrinsics, CalibError> {
    if !matches!(d.len(), 0 | 4 | 5 | 8 | 12 | 14) {
        return Err(at.error(
            path,
            format!(
                "has {} coefficients; OpenCV's distortion has 4, 5, 8, 12 or 14",
                d.len()
            ),
        ));
    }
    if let Some(v) = d.iter().find(|v| !v.is_finite()) {
        return Err(at.error(path, format!("has the non-finite coefficient {v}")));
    }
    if let Some((name, v)) = OPENCV_DISTORTION
        .iter()
        .zip(d)
        .skip(5)
        .find(|(_, v)| **v != 0.0)
    {
        return Err(at.error(
            path,
            format!(
                "has {name} = {v}; the supported model is k1, k2, p1, p2, k3 (the others must be 0)"
            ),
        ));
    }
    let c = |i: usize| d.get(i).copied().unwrap_or(0.0);
    Ok(CameraIntrinsics {
        k1: c(0),
        k2: c(1),
        p1: c(2),
        p2: c(3),
        k3: c(4),
        ..CameraIntrinsics::pinhole(fx, fy, cx, cy)
    })
}

/// A stereo calibration as the tools hold it, with where R and T were read.
pub struct StereoRig {
    pub left: CameraIntrinsics,
    pub right: CameraIntrinsics,
    /// Rotation from left-camera to right-camera coordinates.
    pub r: Matrix3<f64>,
    pub r_at: Origin,
    /// Translation of `x_right = R x_left + T`, in metres.
    pub t: Vector3<f64>,
    pub t_at: Origin,
}

impl StereoRig {
    /// The project's calibration: the baseline is `|T|`, the pose comes from R and T.
    pub fn into_calibration(self, path: &Path) -> Result<Calibration, CalibError> {
        let (extrinsics, baseline_m) = Extrinsics::from_rotation_translation(&self.r, &self.t)
            .map_err(|e| match e {
                PoseError::NotARotation(reason) => self.r_at.error(path, reason),
                PoseError::BadTranslation(reason) => self.t_at.error(path, reason),
            })?;
        let calib = Calibration {
            baseline_m,
            left: self.left,
            right: self.right,
            extrinsics,
        };
        calib.validate(path)?;
        Ok(calib)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at() -> Origin {
        Origin::new("D1", Some(7))
    }

    #[test]
    fn k3_is_kept_and_higher_terms_must_be_zero() {
        let p = Path::new("c.yml");
        let cam = camera(
            [500.0, 500.0, 320.0, 240.0],
            &[-0.3, 0.1, 1e-3, 2e-3, 0.05],
            &at(),
            p,
        )
        .unwrap();
        assert_eq!((cam.k1, cam.p2, cam.k3), (-0.3, 2e-3, 0.05));
        let zeros = [-0.3, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        assert!(camera([500.0, 500.0, 320.0, 240.0], &zeros, &at(), p).is_ok());
        let mut rational = zeros;
        rational[6] = 0.01;
        let msg = camera([500.0, 500.0, 320.0, 240.0], &rational, &at(), p)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("c.yml")
                && msg.contains("line 7")
                && msg.contains("D1")
                && msg.contains("k5"),
            "{msg}"
        );
        let msg = camera([500.0, 500.0, 320.0, 240.0], &[0.1, 0.2, 0.3], &at(), p)
            .unwrap_err()
            .to_string();
        assert!(msg.contains("3 coefficients"), "{msg}");
    }

    #[test]
    fn a_camera_matrix_must_be_a_pinhole_without_skew() {
        let p = Path::new("c.yml");
        let k = [500.0, 0.0, 320.0, 0.0, 501.0, 240.0, 0.0, 0.0, 1.0];
        assert_eq!(
            pinhole_from_k(&k, &at(), p).unwrap(),
            [500.0, 501.0, 320.0, 240.0]
        );
        let mut skewed = k;
        skewed[1] = 0.5;
        assert!(pinhole_from_k(&skewed, &at(), p)
            .unwrap_err()
            .to_string()
            .contains("skew"));
        let mut negative = k;
        negative[0] = -500.0;
        assert!(pinhole_from_k(&negative, &at(), p).is_err());
        assert!(pinhole_from_k(&k[..8], &at(), p)
            .unwrap_err()
            .to_string()
            .contains("8 values"));
    }
}
