//! `matches.csv`: every frame's point pairs consistent with its estimate, in the format of
//! `docs/ARCHITECTURE.md` ("`matches.csv`"). It says which scene points a frame's verge rests
//! on, so that two runs over the same frames (an untouched and an injected drive, two settings)
//! can be compared match by match rather than only by their verges.

use std::io::Write;

use crate::output::record::FrameRecord;

/// Header of `matches.csv`; part of the CLI contract, never reordered (new columns go last).
pub const MATCHES_HEADER: [&str; 6] = ["frame", "left_x", "left_y", "right_x", "right_y", "weight"];

/// Writes one row per consistent pair of every record, frames in record order: pixels with 4
/// decimals (a ten-thousandth of a pixel, far below any match's noise), weights with 6.
pub fn write_matches_csv<W: Write>(out: W, records: &[FrameRecord]) -> Result<(), csv::Error> {
    let mut w = csv::Writer::from_writer(out);
    w.write_record(MATCHES_HEADER)?;
    for r in records {
        let frame = r.frame.to_string();
        for p in &r.consistent_pairs {
            w.write_record([
                frame.clone(),
                format!("{:.4}", p.left[0]),
                format!("{:.4}", p.left[1]),
                format!("{:.4}", p.right[0]),
                format!("{:.4}", p.right[1]),
                format!("{:.6}", p.weight),
            ])?;
        }
    }
    w.flush()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::estimator::ConsistentPair;
    use crate::output::record::FrameStatus;

    fn record(frame: usize, pairs: Vec<ConsistentPair>) -> FrameRecord {
        FrameRecord {
            inliers: pairs.len(),
            status: FrameStatus::Ok,
            consistent_pairs: pairs,
            ..FrameRecord::dropped(frame, None)
        }
    }

    #[test]
    fn one_row_per_pair_under_its_frame() {
        let pair = |x: f64, w: f64| ConsistentPair {
            left: [x, 2.5],
            right: [x - 10.0, 2.25],
            weight: w,
        };
        let records = [
            record(0, vec![pair(100.0, 1.0), pair(200.125, 0.5)]),
            record(1, Vec::new()),
            record(2, vec![pair(7.0, 2.0)]),
        ];
        let mut out = Vec::new();
        write_matches_csv(&mut out, &records).unwrap();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "frame,left_x,left_y,right_x,right_y,weight\n\
             0,100.0000,2.5000,90.0000,2.2500,1.000000\n\
             0,200.1250,2.5000,190.1250,2.2500,0.500000\n\
             2,7.0000,2.5000,-3.0000,2.2500,2.000000\n"
        );
    }
}
