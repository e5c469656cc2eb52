//! The pose of the right camera relative to the left one at calibration time: the starting
//! verge, the fixed misalignments and the baseline direction that a rig's R and T give.
//!
//! Conventions (those of [`crate::essential`]): camera frames are x right, y down, z forward;
//! `R_01 = Ry(-verge) Rx(pitch) Rz(roll)` is the right camera's orientation in the left
//! camera's frame, and the right camera's centre in that frame is
//! `|c| (cos tilt cos left_yaw, sin tilt, cos tilt sin left_yaw)`. A rectified pair has all five
//! angles zero, which is what a calibration without them means.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Largest magnitude of any angle, degrees: a larger one means the two cameras do not form a
/// left-right pair facing one way (swapped, or R and T given in the other direction).
pub const MAX_ANGLE_DEG: f64 = 45.0;

/// Tolerance on `RᵀR = I` and `det R = 1`: calibration tools write R with 15+ digits.
const ROTATION_TOLERANCE: f64 = 1e-6;

/// The right camera's pose relative to the left camera at calibration time, in degrees.
///
/// The estimator starts from it where it needs a nominal head (the constrained model without
/// RANSAC, the general model's second start); the verge it measures is still the images'.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Extrinsics {
    /// Verge angle at calibration, toe-in positive: `-yaw` of `R_01`.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub verge_deg: f64,
    /// Fixed pitch of the right camera: the `Rx` angle of `R_01`.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub pitch_deg: f64,
    /// Fixed roll of the right camera: the `Rz` angle of `R_01`.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub roll_deg: f64,
    /// Yaw of the left camera toward the right one, measured from the baseline's normal: the
    /// azimuth of the right camera's centre in the left camera's frame (the constrained
    /// model's `alpha_l`).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub left_yaw_deg: f64,
    /// Elevation of the right camera's centre in the left camera's frame, positive when it
    /// sits lower (+y).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub baseline_tilt_deg: f64,
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// Why an R, T pair does not describe a left-right stereo pair.
#[derive(Debug, Clone, PartialEq)]
pub enum PoseError {
    /// R has a non-finite entry, is not orthonormal or is a reflection.
    NotARotation(String),
    /// T is not finite, zero, or does not put the second camera to the right of the first.
    BadTranslation(String),
}

impl Extrinsics {
    /// True for a rectified pair (every angle zero), the meaning of an absent table.
    pub fn is_zero(&self) -> bool {
        *self == Self::default()
    }

    /// From the rotation and translation that map left-camera coordinates to right-camera
    /// coordinates, `x_r = R x_l + T` (OpenCV's `stereoCalibrate` R, T and Kalibr's
    /// `T_cn_cnm1`); returns the pose and the baseline length `|T|`.
    pub fn from_rotation_translation(
        r: &Matrix3<f64>,
        t: &Vector3<f64>,
    ) -> Result<(Self, f64), PoseError> {
        if r.iter().any(|v| !v.is_finite()) {
            return Err(PoseError::NotARotation("has a non-finite entry".into()));
        }
        let off = (r.transpose() * r - Matrix3::identity()).abs().max();
        if off > ROTATION_TOLERANCE || (r.determinant() - 1.0).abs() > ROTATION_TOLERANCE {
            return Err(PoseError::NotARotation(format!(
                "is not a rotation (|RᵀR - I| = {off:.1e}, det = {:.6})",
                r.determinant()
            )));
        }
        let baseline = t.norm();
        if !(baseline.is_finite() && baseline > 0.0) {
            return Err(PoseError::BadTranslation(
                "must be finite and non-zero".into(),
            ));
        }
        // The right camera's centre in the left camera's frame.
        let c = -(r.transpose() * t);
        if c[0] <= 0.0 {
            return Err(PoseError::BadTranslation(format!(
                "puts the second camera's centre at x = {:.4} in the first camera's frame; \
                 the first camera must be the left one (x_right = R x_left + T)",
                c[0]
            )));
        }
        let r01 = r.transpose();
        // `+ 0.0` turns a -0.0 from an exactly rectified pair into 0.0, so it compares and
        // serialises as absent.
        let pose = Self {
            verge_deg: -r01[(0, 2)].atan2(r01[(2, 2)]).to_degrees() + 0.0,
            pitch_deg: (-r01[(1, 2)]).clamp(-1.0, 1.0).asin().to_degrees() + 0.0,
            roll_deg: r01[(1, 0)].atan2(r01[(1, 1)]).to_degrees() + 0.0,
            left_yaw_deg: c[2].atan2(c[0]).to_degrees() + 0.0,
            baseline_tilt_deg: (c[1] / baseline).clamp(-1.0, 1.0).asin().to_degrees() + 0.0,
        };
        if let Some((name, value)) = pose.too_large() {
            return Err(PoseError::NotARotation(format!(
                "gives {name} = {value:.3}°, beyond ±{MAX_ANGLE_DEG}°"
            )));
        }
        Ok((pose, baseline))
    }

    /// The first angle that is not finite or beyond ±[`MAX_ANGLE_DEG`], with its TOML key.
    pub fn too_large(&self) -> Option<(&'static str, f64)> {
        [
            ("extrinsics.verge_deg", self.verge_deg),
            ("extrinsics.pitch_deg", self.pitch_deg),
            ("extrinsics.roll_deg", self.roll_deg),
            ("extrinsics.left_yaw_deg", self.left_yaw_deg),
            ("extrinsics.baseline_tilt_deg", self.baseline_tilt_deg),
        ]
        .into_iter()
        .find(|(_, v)| !(v.is_finite() && v.abs() <= MAX_ANGLE_DEG))
    }

    /// The right camera's centre direction in the left camera's frame (unit length).
    pub fn centre_direction(&self) -> Vector3<f64> {
        let (st, ct) = self.baseline_tilt_deg.to_radians().sin_cos();
        let (sy, cy) = self.left_yaw_deg.to_radians().sin_cos();
        Vector3::new(ct * cy, st, ct * sy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::essential::{rot_x, rot_y, rot_z};

    /// R, T of a head with the given pose (degrees) and baseline, as a calibration tool
    /// reports them.
    fn r_t(
        verge: f64,
        pitch: f64,
        roll: f64,
        left_yaw: f64,
        b: f64,
    ) -> (Matrix3<f64>, Vector3<f64>) {
        let r01 = rot_y(-verge.to_radians()) * rot_x(pitch.to_radians()) * rot_z(roll.to_radians());
        let r = r01.transpose();
        let c = rot_y(left_yaw.to_radians()).transpose() * Vector3::new(b, 0.0, 0.0);
        (r, -(r * c))
    }

    #[test]
    fn a_rectified_pair_has_no_pose() {
        let (pose, b) = Extrinsics::from_rotation_translation(
            &Matrix3::identity(),
            &Vector3::new(-0.3, 0.0, 0.0),
        )
        .unwrap();
        assert!(pose.is_zero(), "{pose:?}");
        assert_eq!(b, 0.3);
    }

    #[test]
    fn the_pose_is_read_back_from_r_and_t() {
        let (r, t) = r_t(2.5, 0.3, -0.2, 1.5, 0.12);
        let (pose, b) = Extrinsics::from_rotation_translation(&r, &t).unwrap();
        for (got, want) in [
            (pose.verge_deg, 2.5),
            (pose.pitch_deg, 0.3),
            (pose.roll_deg, -0.2),
            (pose.left_yaw_deg, 1.5),
            (pose.baseline_tilt_deg, 0.0),
            (b, 0.12),
        ] {
            assert!((got - want).abs() < 1e-12, "{pose:?}: {got} vs {want}");
        }
        let c = pose.centre_direction() * b;
        assert!((c + r.transpose() * t).norm() < 1e-12, "{c}");
    }

    #[test]
    fn a_swapped_pair_and_a_non_rotation_are_refused() {
        let swapped = Extrinsics::from_rotation_translation(
            &Matrix3::identity(),
            &Vector3::new(0.3, 0.0, 0.0),
        );
        assert!(
            matches!(swapped, Err(PoseError::BadTranslation(_))),
            "{swapped:?}"
        );
        let sheared = Matrix3::new(1.0, 0.01, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
        let bad = Extrinsics::from_rotation_translation(&sheared, &Vector3::new(-0.3, 0.0, 0.0));
        assert!(matches!(bad, Err(PoseError::NotARotation(_))), "{bad:?}");
    }
}
