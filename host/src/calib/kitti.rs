//! KITTI's calibration text: one `KEY: v v v …` per line. The odometry and object `calib.txt`
//! hold the rectified 3x4 projections `P0` … `P3`, the pair being the grey cameras `P0`, `P1`;
//! the raw data's `calib_cam_to_cam.txt` holds them as `P_rect_00`, `P_rect_01` (the images of
//! its rectified download). A rectified pair has R = I, no distortion, and `P_i = K_i [I | t_i]`
//! with `t_i` the camera's offset in the rectified frame of camera 0 (metres), so
//! `T = t_1 - t_0` and the baseline is `-P1[0,3] / P1[0,0]` for KITTI's own files. Other keys
//! (`Tr`, `calib_time`, the unrectified `K_xx`, `D_xx`, …) are not part of the pair.

use std::path::Path;

use nalgebra::{Matrix3, Vector3};

use super::rig::{self, Origin, StereoRig};
use super::{CalibError, Calibration, CameraIntrinsics};

/// The key pairs of the left and right projection, by file kind.
const PAIRS: [(&str, &str); 2] = [("P0", "P1"), ("P_rect_00", "P_rect_01")];

/// Reads a KITTI calibration text.
pub fn parse(text: &str, path: &Path) -> Result<Calibration, CalibError> {
    let mut lines = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let at = i + 1;
        if line.trim().is_empty() {
            continue;
        }
        let Some((key, values)) = line.split_once(':') else {
            return Err(CalibError::key(
                path,
                line.trim(),
                Some(at),
                "is not a `KEY: values` line",
            ));
        };
        lines.push((key.trim(), values, at));
    }
    let (left_key, right_key) = PAIRS
        .into_iter()
        .find(|(l, _)| lines.iter().any(|(k, ..)| k == l))
        .unwrap_or(PAIRS[0]);
    let projection = |key: &str| -> Result<(CameraIntrinsics, Vector3<f64>, Origin), CalibError> {
        let Some(&(_, values, line)) = lines.iter().find(|(k, ..)| *k == key) else {
            return Err(CalibError::key(path, key, None, "is missing"));
        };
        let at = Origin::new(key, Some(line));
        let values = values
            .split_whitespace()
            .map(|v| {
                super::number(v)
                    .ok_or_else(|| at.error(path, format!("has `{v}`, not a finite number")))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let &[p00, p01, p02, p03, p10, p11, p12, p13, p20, p21, p22, p23] = values.as_slice()
        else {
            return Err(at.error(
                path,
                format!("has {} values; a 3x4 projection has 12", values.len()),
            ));
        };
        let k = [p00, p01, p02, p10, p11, p12, p20, p21, p22];
        let [fx, fy, cx, cy] = rig::pinhole_from_k(&k, &at, path)?;
        // t = K⁻¹ p₄ for K = [fx 0 cx; 0 fy cy; 0 0 1].
        let tz = p23;
        let ty = (p13 - cy * tz) / fy;
        let tx = (p03 - cx * tz) / fx;
        let camera = rig::camera([fx, fy, cx, cy], &[], &at, path)?;
        Ok((camera, Vector3::new(tx, ty, tz), at))
    };
    let (left, t0, _) = projection(left_key)?;
    let (right, t1, at) = projection(right_key)?;
    StereoRig {
        left,
        right,
        r: Matrix3::identity(),
        r_at: at.clone(),
        t: t1 - t0,
        t_at: at,
    }
    .into_calibration(path)
}
