//! The encoders CSV (`run --encoders`): the head's own verge per frame, from its joint encoders
//! or the angles it was commanded to, in the format of `docs/ARCHITECTURE.md` ("Encoders CSV").
//! The filter takes its change between frames as a control input (`crate::kalman`).

use std::path::{Path, PathBuf};

/// The two accepted headers: the camera yaws (verge = left − right, toe-in positive, as the
/// synthetic `frames.csv`), or the verge itself (a head that reports only that).
pub const YAW_HEADER: [&str; 3] = ["frame", "left_yaw_deg", "right_yaw_deg"];
pub const VERGE_HEADER: [&str; 2] = ["frame", "verge_deg"];

/// An encoders file that could not be used, naming the file, the line and the field at fault.
#[derive(Debug, thiserror::Error)]
pub enum EncodersError {
    #[error("{path}: cannot read encoders file: {source}")]
    Read { path: PathBuf, source: csv::Error },
    #[error(
        "{path}: header must be `frame,left_yaw_deg,right_yaw_deg` or `frame,verge_deg`, found `{found}`"
    )]
    Header { path: PathBuf, found: String },
    #[error("{path}:{line}: field `{field}`: `{value}` is not {expected}")]
    Field {
        path: PathBuf,
        line: u64,
        field: &'static str,
        value: String,
        expected: &'static str,
    },
    #[error("{path}:{line}: frame {found} does not follow frame {previous}; frames must increase")]
    Order {
        path: PathBuf,
        line: u64,
        found: usize,
        previous: usize,
    },
    #[error("{path}:{line}: frame {found} is beyond the sequence's {frames} frames")]
    Beyond {
        path: PathBuf,
        line: u64,
        found: usize,
        frames: usize,
    },
}

/// Reads an encoders file for a sequence of `frames` frames: the head's verge (deg) per frame,
/// `None` for a frame without a row (a reading the head did not send).
pub fn read_encoders_csv(path: &Path, frames: usize) -> Result<Vec<Option<f64>>, EncodersError> {
    let read = |source| EncodersError::Read {
        path: path.to_owned(),
        source,
    };
    let mut r = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(read)?;
    let header: Vec<String> = r
        .headers()
        .map_err(read)?
        .iter()
        .map(String::from)
        .collect();
    let fields: &[&'static str] = if header == YAW_HEADER {
        &YAW_HEADER
    } else if header == VERGE_HEADER {
        &VERGE_HEADER
    } else {
        return Err(EncodersError::Header {
            path: path.to_owned(),
            found: header.join(","),
        });
    };
    let mut verge = vec![None; frames];
    let mut previous: Option<usize> = None;
    for row in r.records() {
        let row = row.map_err(read)?;
        let line = row.position().map_or(0, |p| p.line());
        let bad = |i: usize, expected: &'static str| EncodersError::Field {
            path: path.to_owned(),
            line,
            field: fields[i],
            value: row[i].to_owned(),
            expected,
        };
        let frame: usize = row[0]
            .parse()
            .map_err(|_| bad(0, "a non-negative integer"))?;
        let angle = |i: usize| {
            row[i]
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| bad(i, "a finite number of degrees"))
        };
        let value = if fields.len() == 3 {
            angle(1)? - angle(2)?
        } else {
            angle(1)?
        };
        if let Some(previous) = previous.filter(|&p| frame <= p) {
            return Err(EncodersError::Order {
                path: path.to_owned(),
                line,
                found: frame,
                previous,
            });
        }
        let slot = verge.get_mut(frame).ok_or_else(|| EncodersError::Beyond {
            path: path.to_owned(),
            line,
            found: frame,
            frames,
        })?;
        *slot = Some(value);
        previous = Some(frame);
    }
    Ok(verge)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str, frames: usize) -> (Result<Vec<Option<f64>>, EncodersError>, String) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("encoders.csv");
        std::fs::write(&path, text).unwrap();
        let result = read_encoders_csv(&path, frames);
        let message = result
            .as_ref()
            .err()
            .map(ToString::to_string)
            .unwrap_or_default();
        (result, message)
    }

    #[test]
    fn yaws_give_the_verge_and_missing_frames_have_none() {
        let (v, _) = read(
            "frame,left_yaw_deg,right_yaw_deg\n0,1.5,-0.5\n2,2.0,0.25\n",
            4,
        );
        assert_eq!(v.unwrap(), vec![Some(2.0), None, Some(1.75), None]);
        let (v, _) = read("frame,verge_deg\n1, 3.25\n", 2);
        assert_eq!(v.unwrap(), vec![None, Some(3.25)]);
    }

    #[test]
    fn bad_files_name_the_line_and_field() {
        let (r, m) = read(
            "frame,left_yaw_deg,right_yaw_deg\n0,1.5,-0.5\n1,1.5,abc\n",
            4,
        );
        assert!(
            matches!(r, Err(EncodersError::Field { line: 3, .. })),
            "{m}"
        );
        assert!(
            m.contains("encoders.csv:3") && m.contains("right_yaw_deg") && m.contains("abc"),
            "{m}"
        );
        let (r, m) = read("frame,verge_deg\n-1,0.5\n", 4);
        assert!(
            matches!(
                r,
                Err(EncodersError::Field {
                    line: 2,
                    field: "frame",
                    ..
                })
            ),
            "{m}"
        );
        let (r, m) = read("frame,verge_deg\n0,inf\n", 4);
        assert!(m.contains("verge_deg") && r.is_err(), "{m}");
        let (r, _) = read("frame,yaw\n0,0.5\n", 4);
        assert!(matches!(r, Err(EncodersError::Header { .. })));
        let (r, _) = read("frame,verge_deg\n2,0.5\n1,0.5\n", 4);
        assert!(matches!(
            r,
            Err(EncodersError::Order {
                line: 3,
                found: 1,
                previous: 2,
                ..
            })
        ));
        let (r, m) = read("frame,verge_deg\n0,0.5\n4,0.5\n", 4);
        assert!(
            matches!(
                r,
                Err(EncodersError::Beyond {
                    line: 3,
                    found: 4,
                    ..
                })
            ),
            "{m}"
        );
        let (r, m) = read("frame,verge_deg\n0,0.5,7\n", 4);
        assert!(matches!(r, Err(EncodersError::Read { .. })), "{m}");
    }
}
