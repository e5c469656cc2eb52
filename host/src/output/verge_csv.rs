//! The per-frame output CSV (`verge.csv`) and the ground-truth CSV (`frame,verge_deg`), in the
//! formats of `docs/ARCHITECTURE.md` ("`verge.csv`", "Truth CSV").

use std::io::Write;
use std::path::{Path, PathBuf};

use crate::output::record::FrameRecord;

/// Header of `verge.csv`; part of the CLI contract, never reordered (new columns go last).
pub const VERGE_HEADER: [&str; 14] = [
    "frame",
    "raw_verge_deg",
    "filtered_verge_deg",
    "filtered_sigma_deg",
    "matches",
    "inliers",
    "status",
    "pitch_deg",
    "roll_deg",
    "baseline_tilt_deg",
    "packets_lost",
    "keypoints_lost",
    "truth_deg",
    "raw_sigma_deg",
];

/// Header of a ground-truth file.
pub const TRUTH_HEADER: [&str; 2] = ["frame", "verge_deg"];

/// A ground-truth file that could not be used, naming the file and the line at fault.
#[derive(Debug, thiserror::Error)]
pub enum TruthError {
    /// The file could not be opened or read, or a row is not CSV.
    #[error("{path}: cannot read truth file: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The CSV reader's error.
        source: csv::Error,
    },
    /// The header is not `frame,verge_deg`.
    #[error("{path}: header must be `frame,verge_deg`, found `{found}`")]
    Header {
        /// The file.
        path: PathBuf,
        /// The header found, fields joined by commas.
        found: String,
    },
    /// A field does not parse: a frame that is not a non-negative integer, or a verge that is
    /// not a finite number.
    #[error("{path}:{line}: {problem}")]
    Row {
        /// The file.
        path: PathBuf,
        /// 1-based line of the row.
        line: u64,
        /// The field and its text, and what it must be.
        problem: String,
    },
    /// A frame number that is not the next one (0, 1, 2, …).
    #[error("{path}: frames must be 0, 1, 2, … in order; line {line} has frame {found}")]
    Order {
        /// The file.
        path: PathBuf,
        /// 1-based line of the row.
        line: u64,
        /// The row's frame number.
        found: usize,
    },
}

/// Writes `verge.csv` rows; angles with 6 decimals (micro-degrees), empty when absent.
pub fn write_verge_csv<W: Write>(out: W, records: &[FrameRecord]) -> Result<(), csv::Error> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(VERGE_HEADER)?;
    let angle = |v: Option<f64>| v.map(|d| format!("{d:.6}")).unwrap_or_default();
    for r in records {
        w.write_record([
            r.frame.to_string(),
            angle(r.raw_verge_deg),
            angle(r.filtered_verge_deg),
            angle(r.filtered_sigma_deg),
            r.matches.to_string(),
            r.inliers.to_string(),
            r.status.as_str().to_string(),
            angle(r.misalignment.map(|m| m.pitch_deg)),
            angle(r.misalignment.map(|m| m.roll_deg)),
            angle(r.misalignment.map(|m| m.baseline_tilt_deg)),
            r.link_loss.map_or(0, |l| l.packets_lost).to_string(),
            r.link_loss.map_or(0, |l| l.keypoints_lost).to_string(),
            angle(r.truth_deg),
            angle(r.raw_sigma_deg),
        ])?;
    }
    w.flush()?;
    Ok(())
}

/// Writes a ground-truth CSV.
pub fn write_truth_csv<W: Write>(out: W, verge_deg: &[f64]) -> Result<(), csv::Error> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(TRUTH_HEADER)?;
    for (i, v) in verge_deg.iter().enumerate() {
        w.write_record([i.to_string(), format!("{v:.9}")])?;
    }
    w.flush()?;
    Ok(())
}

/// Reads a ground-truth CSV: one finite verge per frame, frames numbered from 0 in order.
pub fn read_truth_csv(path: &Path) -> Result<Vec<f64>, TruthError> {
    let read = |source| TruthError::Read {
        path: path.to_owned(),
        source,
    };
    let mut r = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(read)?;
    let header = r.headers().map_err(read)?.clone();
    if header.iter().collect::<Vec<_>>() != TRUTH_HEADER {
        return Err(TruthError::Header {
            path: path.to_owned(),
            found: header.iter().collect::<Vec<_>>().join(","),
        });
    }
    let mut truth = Vec::new();
    for row in r.records() {
        let row = row.map_err(read)?;
        let line = row.position().map_or(0, |p| p.line());
        let bad = |problem: String| TruthError::Row {
            path: path.to_owned(),
            line,
            problem,
        };
        let frame: usize = row[0]
            .parse()
            .map_err(|_| bad(format!("frame `{}` is not a non-negative integer", &row[0])))?;
        let verge: f64 = row[1]
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| bad(format!("verge_deg `{}` is not a finite number", &row[1])))?;
        if frame != truth.len() {
            return Err(TruthError::Order {
                path: path.to_owned(),
                line,
                found: frame,
            });
        }
        truth.push(verge);
    }
    Ok(truth)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::misalignment::MisalignmentEstimate;
    use crate::output::record::{FrameStatus, LinkLoss};

    #[test]
    fn verge_csv_has_contract_header_and_empty_fields_without_estimate() {
        let records = [
            FrameRecord {
                raw_verge_deg: Some(1.25),
                raw_sigma_deg: Some(0.02),
                filtered_verge_deg: Some(1.2),
                filtered_sigma_deg: Some(0.01),
                matches: 40,
                inliers: 38,
                status: FrameStatus::Ok,
                misalignment: Some(MisalignmentEstimate {
                    pitch_deg: 0.01,
                    roll_deg: -0.03,
                    baseline_tilt_deg: 0.0,
                    pitch_sigma_deg: 0.001,
                    roll_sigma_deg: 0.002,
                    baseline_tilt_sigma_deg: 0.0,
                    pitch_spread_deg: 0.0,
                    frames: 1,
                }),
                ..FrameRecord::dropped(0, Some(1.3))
            },
            FrameRecord {
                matches: 2,
                status: FrameStatus::NoEstimate,
                ..FrameRecord::dropped(1, None)
            },
            FrameRecord {
                raw_verge_deg: Some(1.5),
                raw_sigma_deg: Some(0.03),
                filtered_verge_deg: Some(1.3),
                filtered_sigma_deg: Some(0.01),
                matches: 30,
                inliers: 29,
                status: FrameStatus::Salvaged,
                link_loss: Some(LinkLoss {
                    packets_lost: 3,
                    keypoints_lost: 7,
                }),
                ..FrameRecord::dropped(2, None)
            },
        ];
        let mut out = Vec::new();
        write_verge_csv(&mut out, &records).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert_eq!(
            text,
            "frame,raw_verge_deg,filtered_verge_deg,filtered_sigma_deg,matches,inliers,status,\
             pitch_deg,roll_deg,baseline_tilt_deg,packets_lost,keypoints_lost,truth_deg,\
             raw_sigma_deg\n\
             0,1.250000,1.200000,0.010000,40,38,ok,0.010000,-0.030000,0.000000,0,0,1.300000,0.020000\n\
             1,,,,2,0,no_estimate,,,,0,0,,\n\
             2,1.500000,1.300000,0.010000,30,29,salvaged,,,,3,7,,0.030000\n"
        );
    }

    #[test]
    fn truth_round_trips_and_bad_rows_name_the_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("truth.csv");
        let mut f = std::fs::File::create(&path).unwrap();
        write_truth_csv(&mut f, &[0.5, -1.25]).unwrap();
        assert_eq!(read_truth_csv(&path).unwrap(), vec![0.5, -1.25]);

        std::fs::write(&path, "frame,verge_deg\n0,0.5\n1,abc\n").unwrap();
        let err = read_truth_csv(&path).unwrap_err().to_string();
        assert!(err.contains("truth.csv:3") && err.contains("abc"), "{err}");

        std::fs::write(&path, "frame,angle\n0,0.5\n").unwrap();
        assert!(matches!(
            read_truth_csv(&path),
            Err(TruthError::Header { .. })
        ));

        std::fs::write(&path, "frame,verge_deg\n1,0.5\n").unwrap();
        assert!(matches!(
            read_truth_csv(&path),
            Err(TruthError::Order { found: 1, .. })
        ));
    }
}
