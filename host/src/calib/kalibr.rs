//! Kalibr's `camchain.yaml`: `cam0` and `cam1`, each with `camera_model`, `intrinsics: [fu, fv,
//! pu, pv]`, `distortion_model` and `distortion_coeffs`, and `cam1.T_cn_cnm1`, the 4x4
//! transform from cam0 to cam1 coordinates (metres). cam0 is the left camera; further cameras
//! are not part of the pair and are not read.

use std::path::Path;

use nalgebra::{Matrix3, Vector3};

use super::rig::{self, Origin, StereoRig};
use super::yaml::{self, Entry, Node, Value};
use super::{CalibError, Calibration, CameraIntrinsics};

/// Reads a Kalibr camchain.
pub fn parse(text: &str, path: &Path) -> Result<Calibration, CalibError> {
    let root = yaml::parse(text).map_err(|message| CalibError::Parse {
        path: path.to_owned(),
        message,
    })?;
    let left = camera(&root, "cam0", path)?;
    let right = camera(&root, "cam1", path)?;
    let cam1 = entry(&root, "cam1", "cam1", path)?;
    let (r, t, at) = transform(cam1, path)?;
    StereoRig {
        left,
        right,
        r,
        r_at: at.clone(),
        t,
        t_at: at,
    }
    .into_calibration(path)
}

/// The entry `key` of `parent` (`name`: its full name for the error, which gives the line of
/// the parent's own key when there is one).
fn entry<'a>(
    parent: &'a Node,
    key: &str,
    name: &str,
    path: &Path,
) -> Result<&'a Entry, CalibError> {
    parent.get(key).ok_or_else(|| {
        let line = name.contains('.').then_some(parent.line);
        CalibError::key(path, name, line, "is missing")
    })
}

/// A string-valued key of a camera.
fn word<'a>(cam: &'a Node, key: &str, name: &str, path: &Path) -> Result<&'a str, CalibError> {
    let e = entry(cam, key, name, path)?;
    e.node
        .as_str()
        .ok_or_else(|| CalibError::key(path, name, Some(e.line), "must be a name"))
}

fn camera(root: &Node, cam: &str, path: &Path) -> Result<CameraIntrinsics, CalibError> {
    let node = &entry(root, cam, cam, path)?.node;
    let key = |k: &str| format!("{cam}.{k}");
    let model_key = key("camera_model");
    let model = word(node, "camera_model", &model_key, path)?;
    if model != "pinhole" {
        let line = node.get("camera_model").map(|e| e.line);
        return Err(CalibError::key(
            path,
            &model_key,
            line,
            format!("is `{model}`; only the `pinhole` camera model is supported"),
        ));
    }
    let intrinsics_key = key("intrinsics");
    let intrinsics = entry(node, "intrinsics", &intrinsics_key, path)?;
    let at = Origin::new(&intrinsics_key, Some(intrinsics.line));
    let &[fu, fv, pu, pv] = intrinsics.node.numbers(&intrinsics_key, path)?.as_slice() else {
        return Err(at.error(path, "must be the 4 numbers [fu, fv, pu, pv]"));
    };
    let pinhole = rig::pinhole(fu, fv, pu, pv, &at, path)?;
    let dist_key = key("distortion_model");
    let dist_model = word(node, "distortion_model", &dist_key, path)?;
    let coeffs_key = key("distortion_coeffs");
    let coeffs = entry(node, "distortion_coeffs", &coeffs_key, path)?;
    let values = coeffs.node.numbers(&coeffs_key, path)?;
    let coeffs_at = Origin::new(&coeffs_key, Some(coeffs.line));
    match dist_model {
        "radtan" if values.len() == 4 => rig::camera(pinhole, &values, &coeffs_at, path),
        "radtan" => Err(coeffs_at.error(
            path,
            format!("has {} values; radtan has 4 (k1, k2, r1, r2)", values.len()),
        )),
        "none" if values.iter().all(|v| *v == 0.0) => rig::camera(pinhole, &[], &coeffs_at, path),
        "none" => Err(coeffs_at.error(path, "must be empty or zero for distortion model `none`")),
        other => Err(CalibError::key(
            path,
            &dist_key,
            node.get("distortion_model").map(|e| e.line),
            format!("is `{other}`; only `radtan` and `none` are supported"),
        )),
    }
}

/// R and T of `cam1.T_cn_cnm1` (`x_cam1 = R x_cam0 + T`).
fn transform(
    cam1: &Entry,
    path: &Path,
) -> Result<(Matrix3<f64>, Vector3<f64>, Origin), CalibError> {
    const KEY: &str = "cam1.T_cn_cnm1";
    let e = entry(&cam1.node, "T_cn_cnm1", KEY, path)?;
    let at = Origin::new(KEY, Some(e.line));
    let Value::Seq(rows) = &e.node.value else {
        return Err(at.error(path, "must be a 4x4 matrix, a list of 4 rows"));
    };
    let rows = rows
        .iter()
        .enumerate()
        .map(|(i, row)| row.numbers(&format!("{KEY}[{i}]"), path))
        .collect::<Result<Vec<_>, _>>()?;
    if rows.len() != 4 || rows.iter().any(|r| r.len() != 4) {
        let shape: Vec<String> = rows.iter().map(|r| r.len().to_string()).collect();
        return Err(at.error(
            path,
            format!(
                "must be 4x4; it has {} rows of [{}] values",
                rows.len(),
                shape.join(", ")
            ),
        ));
    }
    if rows[3] != [0.0, 0.0, 0.0, 1.0] {
        return Err(at.error(path, "has a last row other than [0, 0, 0, 1]"));
    }
    let r = Matrix3::from_fn(|i, j| rows[i][j]);
    let t = Vector3::new(rows[0][3], rows[1][3], rows[2][3]);
    Ok((r, t, at))
}
