//! The encoders CSV (`run --encoders`): the head's own verge per frame, from its joint encoders
//! or the angles it was commanded to, in the format of `docs/ARCHITECTURE.md` ("Encoders CSV").
//! The filter takes its change between frames as a control input (`crate::kalman`).

use std::io::Write;
use std::path::{Path, PathBuf};

/// Header of the first accepted form: the camera yaws in degrees (verge = left − right,
/// toe-in positive, as the synthetic `frames.csv`).
pub(crate) const YAW_HEADER: [&str; 3] = ["frame", "left_yaw_deg", "right_yaw_deg"];
/// Header of the second: the verge itself, for a head that reports only that.
pub(crate) const VERGE_HEADER: [&str; 2] = ["frame", "verge_deg"];

/// An encoders file that could not be used, naming the file, the line and the field at fault.
#[derive(Debug, thiserror::Error)]
pub enum EncodersError {
    /// The file could not be opened or read, or a row is not CSV.
    #[error("{path}: cannot read encoders file: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The CSV reader's error.
        source: csv::Error,
    },
    /// The header is neither of the two accepted forms.
    #[error(
        "{path}: header must be `frame,left_yaw_deg,right_yaw_deg` or `frame,verge_deg`, found `{found}`"
    )]
    Header {
        /// The file.
        path: PathBuf,
        /// The header found, fields joined by commas.
        found: String,
    },
    /// A field does not parse: a frame that is not a non-negative integer, or an angle that is
    /// not a finite number.
    #[error("{path}:{line}: field `{field}`: `{value}` is not {expected}")]
    Field {
        /// The file.
        path: PathBuf,
        /// 1-based line of the row.
        line: u64,
        /// The column's name in the header.
        field: &'static str,
        /// The field's text.
        value: String,
        /// What the field must be (`a finite number of degrees`).
        expected: &'static str,
    },
    /// A frame index that does not increase on the row before.
    #[error("{path}:{line}: frame {found} does not follow frame {previous}; frames must increase")]
    Order {
        /// The file.
        path: PathBuf,
        /// 1-based line of the row.
        line: u64,
        /// The row's frame index.
        found: usize,
        /// The frame index of the row before.
        previous: usize,
    },
    /// A frame index past the end of the sequence.
    #[error("{path}:{line}: frame {found} is beyond the sequence's {frames} frames")]
    Beyond {
        /// The file.
        path: PathBuf,
        /// 1-based line of the row.
        line: u64,
        /// The row's frame index.
        found: usize,
        /// Frames in the sequence.
        frames: usize,
    },
}

/// Writes an encoders file of the first form: each frame's (left, right) yaws in degrees, with
/// 9 decimals (a nano-degree, far below any estimate's noise), frames numbered from 0.
pub fn write_encoders_csv<W: Write>(out: W, yaws_deg: &[(f64, f64)]) -> Result<(), csv::Error> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(YAW_HEADER)?;
    for (i, (l, r)) in yaws_deg.iter().enumerate() {
        w.write_record([i.to_string(), format!("{l:.9}"), format!("{r:.9}")])?;
    }
    w.flush()?;
    Ok(())
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
