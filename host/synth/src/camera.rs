//! The pinhole cameras of the synthetic head and their exact projection.
//!
//! Conventions (`docs/ARCHITECTURE.md`, "Frames and signs"): camera frame x right, y down, z forward; pixel coordinates
//! `u = fx * x / z + cx`, `v = fy * y / z + cy`, with integer coordinates at pixel *centres*
//! (pixel `i` covers `[i - 0.5, i + 0.5]`). The renderer casts its rays through exactly this
//! model, so projecting a scene point with [`CameraPose::project`] is the ground truth of where
//! it appears in the image.

use nalgebra::{Matrix3, Vector3};

/// Pinhole intrinsics in pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Intrinsics {
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
}

impl Intrinsics {
    /// Realistic intrinsics for a `width` x `height` sensor: a 56° horizontal field of view
    /// (fx = 600 at 640 px) and a principal point a few pixels off centre, different for the
    /// two cameras, so that downstream code that assumes a centred or shared principal point
    /// is caught by the ground truth.
    pub fn default_for(width: u32, height: u32, side: Side) -> Self {
        Self::for_sensor(width, height, None, side)
    }

    /// [`Intrinsics::default_for`] with the left camera's focal length `focal_px` (the right
    /// one's longer by the same 3.5/600 of it as at the default), or the default's when `None`.
    pub fn for_sensor(width: u32, height: u32, focal_px: Option<f64>, side: Side) -> Self {
        let scale = f64::from(width) / 640.0;
        let (df, dcx, dcy) = match side {
            Side::Left => (0.0, 2.4, -1.9),
            Side::Right => (3.5, -2.1, 1.6),
        };
        let f = match focal_px {
            Some(f) => f * (1.0 + df / 600.0),
            None => 600.0 * scale + df,
        };
        Intrinsics {
            fx: f,
            fy: f,
            cx: (f64::from(width) - 1.0) / 2.0 + dcx * scale,
            cy: (f64::from(height) - 1.0) / 2.0 + dcy * scale,
        }
    }

    /// The intrinsics of one interlaced field of a frame with these intrinsics: the field keeps
    /// rows `parity, parity + 2, …`, so row `r` of the field is frame row `2 r + parity`.
    pub fn field(&self, parity: u32) -> Self {
        Intrinsics {
            fy: self.fy / 2.0,
            cy: (self.cy - f64::from(parity)) / 2.0,
            ..*self
        }
    }
}

/// Which camera of the head.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    Left,
    Right,
}

/// A camera placed in the world: intrinsics, optical centre and orientation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraPose {
    pub intrinsics: Intrinsics,
    /// Optical centre in world coordinates (metres).
    pub center: Vector3<f64>,
    /// Camera-to-world rotation: its columns are the camera's x, y, z axes in the world.
    pub rotation: Matrix3<f64>,
}

impl CameraPose {
    /// Where the world point `p` lands in the image, or `None` if it is not in front of the
    /// camera (z ≤ 0 in the camera frame). Not clipped to the image bounds.
    pub fn project(&self, p: &Vector3<f64>) -> Option<[f64; 2]> {
        let c = self.rotation.transpose() * (p - self.center);
        if c.z <= 0.0 {
            return None;
        }
        let k = &self.intrinsics;
        Some([k.fx * c.x / c.z + k.cx, k.fy * c.y / c.z + k.cy])
    }

    /// The world direction of the ray through pixel coordinate (`u`, `v`), scaled so that its
    /// component along the optical axis is 1 (a ray parameter is then the depth).
    pub fn ray(&self, u: f64, v: f64) -> Vector3<f64> {
        let k = &self.intrinsics;
        self.rotation * Vector3::new((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0)
    }

    /// The camera-frame coordinates of a world point.
    pub fn to_camera(&self, p: &Vector3<f64>) -> Vector3<f64> {
        self.rotation.transpose() * (p - self.center)
    }
}

/// Rotation about the y (down) axis: positive angles turn +z toward +x.
pub(crate) fn yaw(angle_rad: f64) -> Matrix3<f64> {
    let (s, c) = angle_rad.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Rotation about the x (right) axis: positive angles turn +z toward +y (down).
pub(crate) fn pitch_down(angle_rad: f64) -> Matrix3<f64> {
    let (s, c) = angle_rad.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, s, 0.0, -s, c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rotation_senses() {
        let z = Vector3::new(0.0, 0.0, 1.0);
        assert!(
            (yaw(0.1) * z).x > 0.0,
            "positive yaw turns the axis toward +x"
        );
        assert!(
            (pitch_down(0.1) * z).y > 0.0,
            "positive pitch turns the axis down (+y)"
        );
    }

    #[test]
    fn project_and_ray_are_inverse() {
        let pose = CameraPose {
            intrinsics: Intrinsics::default_for(640, 480, Side::Right),
            center: Vector3::new(0.3, -1.2, 5.0),
            rotation: pitch_down(0.05) * yaw(-0.2),
        };
        let d = pose.ray(100.25, 400.75);
        let p = pose.center + 7.0 * d;
        let uv = pose.project(&p).expect("in front");
        assert!((uv[0] - 100.25).abs() < 1e-9 && (uv[1] - 400.75).abs() < 1e-9);
        assert!((pose.to_camera(&p).z - 7.0).abs() < 1e-9);
        assert!(pose.project(&(pose.center - d)).is_none());
    }
}
