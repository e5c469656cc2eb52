//! Where in the right image a left point's match can lie: the band of right-image rows that
//! the head's possible poses allow, derived from the calibration and the image size.
//!
//! A left point's match lies on its epipolar line, between the projection of the point at
//! infinity (the rotation homography `K_r R K_l⁻¹`, which only the verge, pitch and roll move)
//! and the epipole (the left centre seen from the right camera, where the nearest points go).
//! Over every pose in [`PoseRange`] the rows that segment covers inside the right image, plus
//! the keypoints' own localisation error, bound the row of the match: a band that follows the
//! focal length, the principal points, the image size and the verge instead of a number of
//! pixels. At the image centre it is a few pixels wide; toward the corners it widens as far as
//! the verge range and the near points' parallax demand.
//!
//! The band is computed at the nodes of a grid over the left image, as the rows' offsets from
//! the left point's row, which change slowly across the image; a point takes the lowest and
//! highest offset of its cell's four nodes. The lowest row over the poses is a minimum of
//! smooth, nearly linear functions of the position, so it has no minimum inside a cell that is
//! not at a corner (and the highest row likewise), and the cell's extremes hold the point's
//! own band.

use nalgebra::{Matrix3, Vector3};
use std::sync::OnceLock;

use crate::calib::{Calibration, CameraIntrinsics};
use crate::essential::constrained::VergeAngles;
use crate::essential::{rot_x, rot_y, rot_z};

/// The poses the head can be in (degrees; the yaws are the constrained model's, which include
/// the calibration's own verge and left yaw).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseRange {
    /// Verge angles (toe-in positive) the head can take: `[lowest, highest]`.
    pub verge_deg: [f64; 2],
    /// The left camera's yaws, `[lowest, highest]`: where the verge sits between the cameras
    /// moves the epipole, and with it the near points' rows.
    pub left_yaw_deg: [f64; 2],
    /// The right camera's yaws, `[lowest, highest]`.
    pub right_yaw_deg: [f64; 2],
    /// Relative pitch and roll beyond the calibration's own: the misalignment the calibration
    /// does not know.
    pub misalignment_deg: f64,
}

impl PoseRange {
    /// The head's whole mechanical range (verge and either camera's yaw within ±20°: issue
    /// 21's 0–20° of toe-in and the thesis' ±15° manual moves) with `misalignment_deg` of
    /// unknown pitch and roll.
    pub fn verge_head(misalignment_deg: f64) -> Self {
        let range = [-MAX_ANGLE_DEG, MAX_ANGLE_DEG];
        Self {
            verge_deg: range,
            left_yaw_deg: range,
            right_yaw_deg: range,
            misalignment_deg,
        }
    }

    /// The poses within `reach_deg` of the yaws `yaws` (a first fit's, brought into the
    /// head's whole range), inside that range.
    pub fn around(yaws: VergeAngles, reach_deg: f64, misalignment_deg: f64) -> Self {
        let near = |a: f64| {
            let a = a.to_degrees().clamp(-MAX_ANGLE_DEG, MAX_ANGLE_DEG);
            [
                (a - reach_deg).max(-MAX_ANGLE_DEG),
                (a + reach_deg).min(MAX_ANGLE_DEG),
            ]
        };
        let near_verge = near(yaws.verge());
        Self {
            verge_deg: near_verge,
            left_yaw_deg: near(yaws.alpha_l),
            right_yaw_deg: near(yaws.alpha_r),
            misalignment_deg,
        }
    }
}

/// The largest verge (either sign) and camera yaw of a verge head: issue 21 asks for 0–20° of
/// toe-in, and the thesis' manual moves reach ±15° of verge with either camera.
pub const MAX_ANGLE_DEG: f64 = 20.0;

/// Grid spacing in pixels: the band's offsets change by up to a few tenths of a pixel per
/// pixel (the vertical disparity's slope at a 20° verge), so taking a cell's extremes widens
/// the band by at most a quarter of its width and 4 px, and by nothing where it is flat
/// (`the_grid_holds_every_points_own_band`); a finer grid would cost more to build than the
/// candidates it saves.
const GRID_STEP_PX: f32 = 16.0;

/// The band of right-image rows, per left-image position, for one calibration, image size and
/// pose range.
///
/// A node is computed when a point first reads it: the whole range's band serves every
/// keypoint of every frame and fills in once, but the band near a first fit's pose only sorts
/// that fit's few hundred matches, which read a fraction of its nodes, and a moving head needs
/// a new one every few frames.
#[derive(Debug, Clone)]
pub struct EpipolarBand {
    /// Grid nodes per row and per column.
    nodes: [usize; 2],
    /// Node spacing in pixels, x and y.
    step: [f32; 2],
    /// Per node, `[lowest, highest]` right row minus the left row (pixels), once computed.
    offsets: Vec<OnceLock<[f32; 2]>>,
    /// What a node's band is computed from.
    calib: Calibration,
    poses: Vec<Pose>,
    bounds: ImageBounds,
}

impl EpipolarBand {
    /// The band of a `width` x `height` pair (both images the same size) for `calib` over
    /// `range`.
    pub fn new(calib: &Calibration, width: u32, height: u32, range: &PoseRange) -> Self {
        let along = |side: u32| ((side as f32 / GRID_STEP_PX).ceil() as usize).max(1) + 1;
        let nodes = [along(width), along(height)];
        let step = [
            (width.max(1) - 1) as f32 / (nodes[0] - 1) as f32,
            (height.max(1) - 1) as f32 / (nodes[1] - 1) as f32,
        ];
        Self {
            nodes,
            step,
            offsets: (0..nodes[0] * nodes[1]).map(|_| OnceLock::new()).collect(),
            calib: *calib,
            poses: poses(calib, range),
            bounds: ImageBounds::of(&calib.right, width, height),
        }
    }

    /// The offsets of node (`i`, `j`), computed on first use.
    fn node(&self, i: usize, j: usize) -> [f32; 2] {
        *self.offsets[j * self.nodes[0] + i].get_or_init(|| {
            let (u, v) = (
                f64::from(i as f32 * self.step[0]),
                f64::from(j as f32 * self.step[1]),
            );
            let [lo, hi] = rows(&self.calib, &self.poses, &self.bounds, u, v)
                .unwrap_or_else(|| far_rows(&self.calib, &self.poses, u, v));
            [(lo - v) as f32, (hi - v) as f32]
        })
    }

    /// The right rows `[lowest, highest]` where the match of the left point (`x`, `y`) can lie,
    /// widened by `allowance` pixels on each side for the two keypoints' localisation.
    pub fn rows(&self, x: f32, y: f32, allowance: f32) -> [f32; 2] {
        let cell = |p: f32, step: f32, n: usize| {
            let t = (p / step).clamp(0.0, (n - 1) as f32);
            (t.floor() as usize).min(n - 2)
        };
        let i = cell(x, self.step[0], self.nodes[0]);
        let j = cell(y, self.step[1], self.nodes[1]);
        let corners = [
            self.node(i, j),
            self.node(i + 1, j),
            self.node(i, j + 1),
            self.node(i + 1, j + 1),
        ];
        let lo = corners.iter().map(|c| c[0]).fold(f32::INFINITY, f32::min);
        let hi = corners
            .iter()
            .map(|c| c[1])
            .fold(f32::NEG_INFINITY, f32::max);
        [y + lo - allowance, y + hi + allowance]
    }
}

/// One pose: `x_r = rotation · x_l + translation` for camera coordinates (unit baseline).
#[derive(Debug, Clone)]
struct Pose {
    rotation: Matrix3<f64>,
    translation: Vector3<f64>,
}

/// The poses whose bands make up the range's: every combination of the ends and the middle of
/// the verge range and of the left yaw's, and of the ends of the pitch and roll allowances
/// (about the calibration's), the right yaw within its range. The rows move monotonically
/// with the pitch and the roll (a pitch shifts them, a roll turns them about the principal
/// point) and smoothly, almost monotonically with the yaws, so the extremes of the range lie
/// on these poses; the localisation allowance covers what lies between.
fn poses(calib: &Calibration, range: &PoseRange) -> Vec<Pose> {
    let e = &calib.extrinsics;
    let [v_lo, v_hi] = range.verge_deg;
    let verges = [v_lo, 0.5 * (v_lo + v_hi), v_hi];
    let [l_lo, l_hi] = range.left_yaw_deg;
    let left_yaws = [l_lo, 0.5 * (l_lo + l_hi), l_hi];
    let [r_lo, r_hi] = range.right_yaw_deg;
    let m = range.misalignment_deg;
    let mut out = Vec::new();
    for &verge in &verges {
        for &alpha_l in &left_yaws {
            // The nearest right yaw to this verge's that the range allows.
            let alpha_r = (alpha_l - verge).clamp(r_lo, r_hi);
            for dp in [-m, m] {
                for dr in [-m, m] {
                    let (p, r) = (
                        (e.pitch_deg + dp).to_radians(),
                        (e.roll_deg + dr).to_radians(),
                    );
                    let left = rot_y(alpha_l.to_radians());
                    let right = rot_y(alpha_r.to_radians()) * rot_x(p) * rot_z(r);
                    out.push(Pose {
                        rotation: right.transpose() * left,
                        translation: -(right.transpose() * Vector3::x()),
                    });
                }
            }
        }
    }
    out
}

/// The right image's columns in calibrated coordinates (the extent of its border).
#[derive(Debug, Clone)]
struct ImageBounds {
    x: [f64; 2],
}

impl ImageBounds {
    fn of(camera: &CameraIntrinsics, width: u32, height: u32) -> Self {
        let (w, h) = (f64::from(width) - 1.0, f64::from(height) - 1.0);
        let mut x = [f64::INFINITY, f64::NEG_INFINITY];
        // Points along each side, not just the corners: lens distortion bends the border, so
        // its extreme columns need not be at a corner. Eight steps make the corners and each
        // side's middle samples, where a barrel or pincushion bend has its extreme column; a
        // higher-order bend's extreme lies within 1/16 of the side of a sample, which misses
        // at most 1/64 of its sagitta (a parabola's fall that near its apex).
        for k in 0..=8 {
            let t = f64::from(k) / 8.0;
            for (u, v) in [(t * w, 0.0), (t * w, h), (0.0, t * h), (w, t * h)] {
                let (a, _) = camera.normalize(u, v);
                x = [x[0].min(a), x[1].max(a)];
            }
        }
        Self { x }
    }
}

/// The lowest and highest right-image row of the left pixel (`u`, `v`)'s match over `poses`,
/// or `None` when no pose puts any point of its ray inside the right image's columns.
fn rows(
    calib: &Calibration,
    poses: &[Pose],
    bounds: &ImageBounds,
    u: f64,
    v: f64,
) -> Option<[f64; 2]> {
    let (x, y) = calib.left.normalize(u, v);
    let ray = Vector3::new(x, y, 1.0);
    let mut band = [f64::INFINITY, f64::NEG_INFINITY];
    for pose in poses {
        let far = pose.rotation * ray;
        if far.z <= 0.0 {
            // The far end of the ray is behind the right camera: no bound from this pose, a
            // million rows each side, far beyond any frame's (`stereocal_hdl::regs::MAX_HEIGHT`).
            return Some([f64::NEG_INFINITY, f64::INFINITY].map(|r| r.clamp(-1e6, 1e6)));
        }
        let t = pose.translation;
        let p = [far.x / far.z, far.y / far.z];
        // The ray's image runs from `p` (infinity) along `dir` to the epipole (`s = far.z /
        // t.z`) when the left centre is in front of the right camera, without end otherwise.
        let dir = [t.x - p[0] * t.z, t.y - p[1] * t.z];
        let s_end = if t.z > 0.0 {
            far.z / t.z
        } else {
            f64::INFINITY
        };
        let Some([s0, s1]) = clip(p, dir, s_end, bounds.x) else {
            continue;
        };
        // The segment is straight in calibrated coordinates; the middle as well as the ends,
        // for the bend the right camera's distortion gives its image.
        for s in [s0, 0.5 * (s0 + s1), s1] {
            let (px, py) = (p[0] + s * dir[0], p[1] + s * dir[1]);
            let row = calib.right.project(px, py).1;
            band = [band[0].min(row), band[1].max(row)];
        }
    }
    (band[0] <= band[1]).then_some(band)
}

/// The rows of the points at infinity of the left pixel (`u`, `v`) over `poses`: the band of
/// a point no pose lets into the right image, so that the grid's nodes there continue the
/// band of their neighbours.
fn far_rows(calib: &Calibration, poses: &[Pose], u: f64, v: f64) -> [f64; 2] {
    let (x, y) = calib.left.normalize(u, v);
    let ray = Vector3::new(x, y, 1.0);
    poses.iter().fold([v, v], |band, pose| {
        let far = pose.rotation * ray;
        let row = calib.right.project(far.x / far.z, far.y / far.z).1;
        [band[0].min(row), band[1].max(row)]
    })
}

/// The parameter interval of `p + s·dir`, `s` in `[0, s_end]`, whose x lies in `[min, max]`.
/// Rows are not clipped: a band reaching past the image's top or bottom costs nothing, and
/// clipping would put kinks in it that the grid cannot interpolate.
fn clip(p: [f64; 2], dir: [f64; 2], s_end: f64, [min, max]: [f64; 2]) -> Option<[f64; 2]> {
    if dir[0] == 0.0 {
        return (min..=max).contains(&p[0]).then_some([0.0, 0.0]);
    }
    let (a, b) = ((min - p[0]) / dir[0], (max - p[0]) / dir[0]);
    let (lo, hi) = (a.min(b).max(0.0), a.max(b).min(s_end));
    (lo <= hi && hi.is_finite()).then_some([lo, hi])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calib::Extrinsics;
    use crate::essential::testutil::synthetic;

    fn calib(f: f64, width: u32, height: u32) -> Calibration {
        let cam = CameraIntrinsics::pinhole(
            f,
            f,
            f64::from(width) / 2.0 + 3.0,
            f64::from(height) / 2.0 - 2.0,
        );
        Calibration {
            baseline_m: 0.3,
            left: cam,
            right: CameraIntrinsics {
                fx: f * 1.006,
                fy: f * 1.006,
                ..cam
            },
            extrinsics: Extrinsics::default(),
        }
    }

    /// Every exact match of a head inside the range, at any depth from a baseline to far away,
    /// lies inside its left point's band, at focal lengths from 400 to 1400 px, at verges up to
    /// the range's ends, with the misalignment the range allows; and the band at the image
    /// centre stays narrow.
    #[test]
    fn every_match_of_a_head_in_range_lies_inside_its_band() {
        for (f, w, h) in [(400.0, 640, 480), (1400.0, 1280, 1024), (718.0, 1240, 376)] {
            let c = calib(f, w, h);
            let range = PoseRange::verge_head(3.0);
            let band = EpipolarBand::new(&c, w, h, &range);
            let mut checked = 0;
            for (al, ar, pitch, roll) in [
                (10.0, -10.0, 0.0, 0.0),
                (2.0, -17.0, 2.5, -1.0),
                (-8.0, 9.0, -2.0, 3.0),
                (0.3, -0.4, 0.0, 0.0),
                (19.0, 0.0, 1.0, 1.0),
            ] {
                let a = VergeAngles::new(f64::to_radians(al), f64::to_radians(ar));
                let right =
                    rot_y(a.alpha_r) * rot_x(f64::to_radians(pitch)) * rot_z(f64::to_radians(roll));
                for m in synthetic(rot_y(a.alpha_l), right, 0.3, 400, 0.0, f, 7) {
                    let (ul, vl) = c.left.project(m.left[0], m.left[1]);
                    let (ur, vr) = c.right.project(m.right[0], m.right[1]);
                    let inside = |u: f64, v: f64, side: u32, other: u32| {
                        u >= 0.0
                            && v >= 0.0
                            && u <= f64::from(side - 1)
                            && v <= f64::from(other - 1)
                    };
                    if !(inside(ul, vl, w, h) && inside(ur, vr, w, h)) {
                        continue;
                    }
                    let [lo, hi] = band.rows(ul as f32, vl as f32, 0.5);
                    assert!(
                        (lo..=hi).contains(&(vr as f32)),
                        "f {f}, ({al}, {ar}, {pitch}, {roll}): left ({ul:.1}, {vl:.1}) right row {vr:.2} outside [{lo:.2}, {hi:.2}]"
                    );
                    checked += 1;
                }
            }
            assert!(checked > 500, "only {checked} matches inside both images");
        }
    }

    /// Around a known pose the band narrows to what the reach and the misalignment allowance
    /// leave: at the image centre of a parallel head, the pitch allowance each way (f·tan m)
    /// and the roll's and the reach's fraction of a pixel, where the whole range is many times
    /// wider at the top row.
    #[test]
    fn around_a_pose_the_band_narrows() {
        let (w, h) = (640, 480);
        let c = calib(600.0, w, h);
        let whole = EpipolarBand::new(&c, w, h, &PoseRange::verge_head(1.0));
        let near = PoseRange::around(VergeAngles::new(0.0, 0.0), 5.0, 1.0);
        let around = EpipolarBand::new(&c, w, h, &near);
        let centre = around.rows(323.0, 238.0, 0.0);
        let pitch = 600.0 * 1f32.to_radians().tan();
        // A rolled right camera tilts the epipolar lines: the near points' rows drift by up to
        // the image width times the roll's sine.
        let roll = 640.0 * 1f32.to_radians().sin();
        assert!(
            centre[1] - centre[0] < 2.0 * pitch + roll + 2.0,
            "{centre:?}"
        );
        let width = |b: &EpipolarBand| {
            let [lo, hi] = b.rows(320.0, 10.0, 0.0);
            hi - lo
        };
        assert!(
            width(&whole) > 2.0 * width(&around),
            "{} vs {}",
            width(&whole),
            width(&around)
        );
    }

    /// The band read from the grid holds the band computed at the point itself, and widens it
    /// by no more than a quarter and 4 px: what the offsets change across a cell.
    #[test]
    fn the_grid_holds_every_points_own_band() {
        let (w, h) = (640, 480);
        let c = calib(600.0, w, h);
        let range = PoseRange::verge_head(1.0);
        let band = EpipolarBand::new(&c, w, h, &range);
        let poses = poses(&c, &range);
        let bounds = ImageBounds::of(&c.right, w, h);
        let mut worst = 0f64;
        for k in 0..400 {
            let (u, v) = ((k * 37 % 639) as f64 + 0.3, (k * 53 % 479) as f64 + 0.7);
            // Points no pose lets into the right image have no band to agree with.
            let Some(direct) = rows(&c, &poses, &bounds, u, v) else {
                continue;
            };
            let got = band.rows(u as f32, v as f32, 0.0);
            // The grid's band holds the point's own (to a quarter of a pixel: the rows are
            // nearly, not exactly, linear in the position; the keypoints' localisation
            // allowance is a pixel or more), and is at most a few pixels wider.
            assert!(
                got[0] <= direct[0] as f32 + 0.25 && got[1] >= direct[1] as f32 - 0.25,
                "({u}, {v}): {got:?} misses {direct:?}"
            );
            let own = direct[1] - direct[0];
            worst = worst.max((f64::from(got[1] - got[0]) - own) / (0.25 * own + 4.0));
        }
        assert!(
            worst <= 1.0,
            "widened by up to {worst} of a quarter plus 4 px"
        );
    }
}
