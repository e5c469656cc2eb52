//! OpenCV's stereo calibration as `cv::FileStorage` writes it: `%YAML:1.0`, then the results of
//! `stereoCalibrate` as `!!opencv-matrix` maps (`rows`, `cols`, `dt`, `data`); its JSON (a
//! `.json` name) is the same maps with `"type_id": "opencv-matrix"`, and JSON is YAML. The keys are
//! `K1, D1, K2, D2, R, T`; OpenCV's own sample names the camera matrices `M1, M2` and some
//! scripts `cameraMatrix1, distCoeffs1`, which are read too. T is in the units of the object
//! points given to `stereoCalibrate`, here taken as metres.

use std::path::Path;

use nalgebra::{Matrix3, Vector3};

use super::rig::{self, Origin, StereoRig};
use super::yaml::{self, Node, Value};
use super::{CalibError, Calibration};

/// The names each matrix is read under, the first being the one errors use.
const K1: &[&str] = &["K1", "M1", "cameraMatrix1"];
const D1: &[&str] = &["D1", "distCoeffs1"];
const K2: &[&str] = &["K2", "M2", "cameraMatrix2"];
const D2: &[&str] = &["D2", "distCoeffs2"];

/// Reads a `cv::FileStorage` YAML calibration.
pub fn parse(text: &str, path: &Path) -> Result<Calibration, CalibError> {
    let root = yaml::parse(&without_header(text)).map_err(|message| CalibError::Parse {
        path: path.to_owned(),
        message,
    })?;
    if !matches!(root.value, Value::Map(_)) {
        return Err(CalibError::Parse {
            path: path.to_owned(),
            message: "is not a map of named matrices".into(),
        });
    }
    let left = camera(&root, K1, D1, path)?;
    let right = camera(&root, K2, D2, path)?;
    let r = matrix(&root, &["R"], path)?;
    let r_values = r.shaped(3, 3, path)?;
    let t = matrix(&root, &["T"], path)?;
    let t_values = t.vector(3, path)?;
    StereoRig {
        left,
        right,
        r: Matrix3::from_row_slice(r_values),
        r_at: r.at,
        t: Vector3::from_row_slice(t_values),
        t_at: t.at,
    }
    .into_calibration(path)
}

/// `%YAML:1.0` is OpenCV's, not a YAML directive: it becomes a comment, in place, so every
/// line keeps its number.
fn without_header(text: &str) -> String {
    let text = text.trim_start_matches('\u{feff}');
    match text.strip_prefix('%') {
        Some(rest) if rest.starts_with("YAML:") => format!("#{rest}"),
        _ => text.to_owned(),
    }
}

fn camera(
    root: &Node,
    k_names: &[&str],
    d_names: &[&str],
    path: &Path,
) -> Result<super::CameraIntrinsics, CalibError> {
    let k = matrix(root, k_names, path)?;
    let pinhole = rig::pinhole_from_k(k.shaped(3, 3, path)?, &k.at, path)?;
    let d = matrix(root, d_names, path)?;
    let coefficients = d.vector(d.values.len(), path)?;
    rig::camera(pinhole, coefficients, &d.at, path)
}

/// One `!!opencv-matrix`: its values row-major, its size and where it stands.
struct Matrix {
    values: Vec<f64>,
    rows: usize,
    cols: usize,
    at: Origin,
}

impl Matrix {
    /// The values of a `rows` x `cols` matrix.
    fn shaped(&self, rows: usize, cols: usize, path: &Path) -> Result<&[f64], CalibError> {
        if (self.rows, self.cols) == (rows, cols) {
            Ok(&self.values)
        } else {
            Err(self.at.error(
                path,
                format!("is {}x{}; expected {rows}x{cols}", self.rows, self.cols),
            ))
        }
    }

    /// The values of a row or column vector of length `n`.
    fn vector(&self, n: usize, path: &Path) -> Result<&[f64], CalibError> {
        if (self.rows == 1 || self.cols == 1) && self.values.len() == n {
            Ok(&self.values)
        } else {
            Err(self.at.error(
                path,
                format!(
                    "is {}x{}; expected a vector of {n} (1x{n} or {n}x1)",
                    self.rows, self.cols
                ),
            ))
        }
    }
}

/// The matrix stored under the first of `names` present.
fn matrix(root: &Node, names: &[&str], path: &Path) -> Result<Matrix, CalibError> {
    let Some(entry) = names.iter().find_map(|n| root.get(n)) else {
        let also = names[1..]
            .iter()
            .map(|n| format!("`{n}`"))
            .collect::<Vec<_>>()
            .join(", ");
        let reason = if also.is_empty() {
            "is missing (stereoCalibrate's K1, D1, K2, D2, R, T are needed)".to_owned()
        } else {
            format!("is missing (also read as {also})")
        };
        return Err(CalibError::key(path, names[0], None, reason));
    };
    let key = entry.key.as_str();
    let at = Origin::new(key, Some(entry.line));
    let field = |name: &str| {
        entry.node.get(name).ok_or_else(|| {
            at.error(
                path,
                format!("is not an !!opencv-matrix: it has no `{name}` (rows, cols, dt, data)"),
            )
        })
    };
    let dim = |name: &str| -> Result<usize, CalibError> {
        let f = field(name)?;
        let qualified = format!("{key}.{name}");
        let v = f.node.number(&qualified, path)?;
        if (1.0..=1e6).contains(&v) && v.fract() == 0.0 {
            Ok(v as usize)
        } else {
            Err(CalibError::key(
                path,
                &qualified,
                Some(f.line),
                format!("is {v}; it must be a whole number ≥ 1"),
            ))
        }
    };
    let (rows, cols) = (dim("rows")?, dim("cols")?);
    let dt = field("dt")?;
    if !matches!(dt.node.as_str(), Some("d" | "f")) {
        return Err(CalibError::key(
            path,
            &format!("{key}.dt"),
            Some(dt.line),
            format!(
                "is `{}`; a calibration matrix holds floating point (`d` or `f`)",
                dt.node.as_str().unwrap_or("a list or map")
            ),
        ));
    }
    let data = field("data")?;
    let data_key = format!("{key}.data");
    let values = data.node.numbers(&data_key, path)?;
    if values.len() != rows * cols {
        return Err(CalibError::key(
            path,
            &data_key,
            Some(data.line),
            format!("has {} values for {rows}x{cols}", values.len()),
        ));
    }
    Ok(Matrix {
        values,
        rows,
        cols,
        at,
    })
}
