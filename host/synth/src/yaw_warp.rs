//! Exact verge injection into a real (rectified) stereo pair.
//!
//! Turning a camera about its optical centre changes its image by a homography, independent
//! of the scene: a camera whose orientation becomes `Ry(alpha)` (signs as in
//! `docs/ARCHITECTURE.md`, "Frames and signs": `alpha > 0` turns the optical axis toward +x)
//! sees the head-frame ray `X` at `x' ~ K Ry(alpha)ᵀ X`, where the unturned camera saw
//! `x ~ K X`. So the new image is `I'(x') = I(H⁻¹ x')` with `H = K Ry(alpha)ᵀ K⁻¹` — exactly
//! the `verge_injection` note of the real data sets' `geometry.json` ("Real data" in the same
//! document: `warpPerspective(img, K Ry(θ)ᵀ K⁻¹)` gives yaw = +θ). Applying `alpha_l` to the
//! left and `alpha_r` to the right image of a rectified pair yields a pair with
//! verge `alpha_l - alpha_r` plus whatever residual the rectification left.
//!
//! Resampling is bicubic by default (Keys, a = -0.5): it reproduces quadratics and does not
//! smooth the image as much as bilinear would at half-pixel phases, so that the warp does not
//! blur some image regions more than others. No kernel is exact on a real image, whose pixels
//! are not band-limited; the Lanczos kernels ([`Resampling`]) come closer to the band-limited
//! ideal at more taps (`host/synth/tests/resampling.rs` measures each on the KITTI drive: a
//! warp and its inverse, against the original). Pixels whose source falls outside the input take
//! the nearest border value; callers should ignore features within a few pixels of
//! [`YawWarp::source_inside`]'s boundary.

use image::GrayImage;
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

use stereocal::calib::CameraIntrinsics;
use stereocal::essential::rot_y;

/// The pure-rotation homography of one camera yawing by `alpha` (radians).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct YawWarp {
    /// Maps input pixels to output pixels (`H = K Ry(alpha)ᵀ K⁻¹`).
    forward: Matrix3<f64>,
    /// Maps output pixels to input pixels.
    inverse: Matrix3<f64>,
}

fn k_matrix(c: &CameraIntrinsics) -> Matrix3<f64> {
    Matrix3::new(c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0)
}

fn k_inverse(c: &CameraIntrinsics) -> Matrix3<f64> {
    Matrix3::new(
        1.0 / c.fx,
        0.0,
        -c.cx / c.fx,
        0.0,
        1.0 / c.fy,
        -c.cy / c.fy,
        0.0,
        0.0,
        1.0,
    )
}

fn apply_h(h: &Matrix3<f64>, x: f64, y: f64) -> (f64, f64) {
    let p = h * Vector3::new(x, y, 1.0);
    (p[0] / p[2], p[1] / p[2])
}

impl YawWarp {
    /// The warp of a pinhole camera (distortion coefficients are ignored: inject into
    /// rectified, undistorted images).
    pub fn new(camera: &CameraIntrinsics, alpha: f64) -> Self {
        let k = k_matrix(camera);
        let ki = k_inverse(camera);
        Self {
            forward: k * rot_y(alpha).transpose() * ki,
            inverse: k * rot_y(alpha) * ki,
        }
    }

    /// The homography input → output (OpenCV `warpPerspective` convention).
    pub fn matrix(&self) -> Matrix3<f64> {
        self.forward
    }

    /// Where output pixel `(x, y)` comes from in the input.
    pub fn source_of(&self, x: f64, y: f64) -> (f64, f64) {
        apply_h(&self.inverse, x, y)
    }

    /// Where input pixel `(x, y)` lands in the output.
    pub fn destination_of(&self, x: f64, y: f64) -> (f64, f64) {
        apply_h(&self.forward, x, y)
    }

    /// True when output pixel `(x, y)` samples the input at least `margin` pixels inside it.
    pub fn source_inside(&self, x: f64, y: f64, width: u32, height: u32, margin: f64) -> bool {
        let (sx, sy) = self.source_of(x, y);
        sx >= margin
            && sy >= margin
            && sx <= width as f64 - 1.0 - margin
            && sy <= height as f64 - 1.0 - margin
    }

    /// Warps `src` (same size out), bicubic, border replicated.
    pub fn apply(&self, src: &GrayImage) -> GrayImage {
        self.apply_with(src, Resampling::Bicubic)
    }

    /// Warps `src` (same size out) with `resampling`, border replicated.
    pub fn apply_with(&self, src: &GrayImage, resampling: Resampling) -> GrayImage {
        let (w, h) = src.dimensions();
        let mut out = vec![0u8; w as usize * h as usize];
        out.par_chunks_mut(w as usize)
            .enumerate()
            .for_each(|(y, row)| {
                for (x, px) in row.iter_mut().enumerate() {
                    let (sx, sy) = self.source_of(x as f64, y as f64);
                    *px = sample(src, sx, sy, resampling);
                }
            });
        // The buffer has exactly w·h bytes.
        GrayImage::from_raw(w, h, out).unwrap_or_else(|| GrayImage::new(w, h))
    }
}

/// The interpolation kernel of a warp.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Resampling {
    /// Keys' cubic convolution (a = -0.5), 4x4 taps.
    #[default]
    Bicubic,
    /// Lanczos, radius 3 (sinc windowed by a sinc three times as wide), 6x6 taps.
    Lanczos3,
    /// Lanczos, radius 5, 10x10 taps.
    Lanczos5,
}

/// The widest kernel's taps per axis.
const MAX_TAPS: usize = 10;

impl Resampling {
    /// Taps per axis each side of the sample point.
    fn radius(self) -> usize {
        match self {
            Self::Bicubic => 2,
            Self::Lanczos3 => 3,
            Self::Lanczos5 => 5,
        }
    }

    /// The kernel's weight at distance `t` (pixels).
    fn weight(self, t: f64) -> f64 {
        match self {
            Self::Bicubic => keys(t),
            Self::Lanczos3 => lanczos(t, 3.0),
            Self::Lanczos5 => lanczos(t, 5.0),
        }
    }
}

/// Keys' cubic convolution kernel (a = -0.5).
fn keys(t: f64) -> f64 {
    let t = t.abs();
    if t < 1.0 {
        (1.5 * t - 2.5) * t * t + 1.0
    } else if t < 2.0 {
        ((-0.5 * t + 2.5) * t - 4.0) * t + 2.0
    } else {
        0.0
    }
}

/// The Lanczos kernel of radius `a`: `sinc(t)·sinc(t/a)` inside it.
fn lanczos(t: f64, a: f64) -> f64 {
    let t = t.abs();
    if t < 1e-12 {
        1.0
    } else if t < a {
        let pt = std::f64::consts::PI * t;
        a * pt.sin() * (pt / a).sin() / (pt * pt)
    } else {
        0.0
    }
}

/// `img` at (`x`, `y`) through `resampling`'s separable kernel, border replicated. Keys'
/// weights sum to one at every phase; the Lanczos weights do not quite, so they are divided by
/// their sum (a flat image stays flat).
fn sample(img: &GrayImage, x: f64, y: f64, resampling: Resampling) -> u8 {
    let (w, h) = img.dimensions();
    let x = x.clamp(0.0, (w - 1) as f64);
    let y = y.clamp(0.0, (h - 1) as f64);
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let r = resampling.radius();
    // Tap i lies at offset i - (r - 1) from the pixel at or left of (above) the point.
    let offset = |i: usize| i as f64 - (r - 1) as f64;
    let (mut wx, mut wy) = ([0.0; MAX_TAPS], [0.0; MAX_TAPS]);
    for i in 0..2 * r {
        wx[i] = resampling.weight(fx - offset(i));
        wy[i] = resampling.weight(fy - offset(i));
    }
    let (wx, wy) = (&mut wx[..2 * r], &mut wy[..2 * r]);
    if resampling != Resampling::Bicubic {
        for weights in [&mut *wx, &mut *wy] {
            let sum: f64 = weights.iter().sum();
            weights.iter_mut().for_each(|v| *v /= sum);
        }
    }
    let mut acc = 0.0;
    for (j, wyj) in wy.iter().enumerate() {
        let yy = (y0 as i64 + j as i64 + 1 - r as i64).clamp(0, h as i64 - 1) as u32;
        for (i, wxi) in wx.iter().enumerate() {
            let xx = (x0 as i64 + i as i64 + 1 - r as i64).clamp(0, w as i64 - 1) as u32;
            acc += wyj * wxi * img.get_pixel(xx, yy)[0] as f64;
        }
    }
    acc.round().clamp(0.0, 255.0) as u8
}

/// Injects yaws `alpha_l` / `alpha_r` (radians) into a rectified pair.
pub fn inject_verge(
    left: &GrayImage,
    right: &GrayImage,
    left_camera: &CameraIntrinsics,
    right_camera: &CameraIntrinsics,
    alpha_l: f64,
    alpha_r: f64,
) -> (GrayImage, GrayImage) {
    (
        YawWarp::new(left_camera, alpha_l).apply(left),
        YawWarp::new(right_camera, alpha_r).apply(right),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> CameraIntrinsics {
        CameraIntrinsics::pinhole(711.5, 711.5, 376.1, 227.4)
    }

    #[test]
    fn warp_moves_pixels_as_a_turned_camera_sees_them() {
        let c = cam();
        let alpha = 2.5f64.to_radians();
        let warp = YawWarp::new(&c, alpha);
        for p in [
            Vector3::new(1.0, -0.5, 6.0),
            Vector3::new(-3.0, 1.0, 9.0),
            Vector3::new(0.2, 0.3, 2.0),
        ] {
            let (u0, v0) = c.project(p[0] / p[2], p[1] / p[2]);
            let q = rot_y(alpha).transpose() * p; // the turned camera's coordinates
            let (u1, v1) = c.project(q[0] / q[2], q[1] / q[2]);
            let (su, sv) = warp.source_of(u1, v1);
            assert!((su - u0).abs() < 1e-9 && (sv - v0).abs() < 1e-9);
            let (du, dv) = warp.destination_of(u0, v0);
            assert!((du - u1).abs() < 1e-9 && (dv - v1).abs() < 1e-9);
        }
        // Turning toward +x moves the scene toward -x in the image.
        let (du, _) = warp.destination_of(c.cx, c.cy);
        assert!(du < c.cx - 30.0);
    }

    #[test]
    fn every_kernel_reproduces_a_smooth_ramp_and_a_flat_image() {
        let img = GrayImage::from_fn(120, 80, |x, y| image::Luma([(x + y) as u8]));
        let flat = GrayImage::from_pixel(120, 80, image::Luma([77]));
        let warp = YawWarp::new(&CameraIntrinsics::pinhole(500.0, 500.0, 60.0, 40.0), 0.01);
        for resampling in [
            Resampling::Bicubic,
            Resampling::Lanczos3,
            Resampling::Lanczos5,
        ] {
            let out = warp.apply_with(&img, resampling);
            for (x, y) in [(30u32, 20u32), (60, 40), (90, 60)] {
                let (sx, sy) = warp.source_of(x as f64, y as f64);
                let want = (sx + sy).round();
                let got = out.get_pixel(x, y)[0] as f64;
                assert!((got - want).abs() <= 1.0, "{resampling:?}: {got} vs {want}");
            }
            let out = warp.apply_with(&flat, resampling);
            assert!(
                out.pixels().all(|p| p[0] == 77),
                "{resampling:?}: flat image"
            );
        }
        assert!(warp.source_inside(60.0, 40.0, 120, 80, 3.0));
        assert!(!warp.source_inside(119.0, 40.0, 120, 80, 3.0));
    }
}
