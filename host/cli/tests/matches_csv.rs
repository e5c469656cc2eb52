//! `stereocal run --matches` writes `matches.csv` beside `verge.csv`: as many rows under each
//! frame as `verge.csv` counts inliers, each a pixel pair that the rendered truth's geometry
//! explains, so that refitting a frame's rows alone gives its true verge back. Without the flag
//! no `matches.csv` is written.

mod common;

use std::collections::BTreeMap;

use common::{stereocal, succeeded, synth_road};
use stereocal::calib::Calibration;
use stereocal::estimator::{EstimatorConfig, PixelPair, VergeEstimator};
use stereocal::output::verge_csv::read_truth_csv;

#[test]
fn matches_csv_holds_each_frames_consistent_pairs() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("seq");
    let path = |p: &std::path::Path| p.to_str().unwrap().to_owned();
    synth_road(&seq, 4, 3);
    let run = |out: &std::path::Path, extra: &[&str]| {
        let args = [
            "run".to_owned(),
            "--left".to_owned(),
            path(&seq.join("left")),
            "--right".to_owned(),
            path(&seq.join("right")),
            "--calib".to_owned(),
            path(&seq.join("calib.toml")),
            "--out".to_owned(),
            path(out),
        ];
        let extra: Vec<String> = extra.iter().map(|s| s.to_string()).collect();
        succeeded(stereocal(&[&args[..], &extra[..]].concat()));
    };
    let (with, without) = (dir.path().join("with"), dir.path().join("without"));
    run(&with, &["--matches"]);
    run(&without, &[]);
    assert!(!without.join("matches.csv").exists(), "written unasked");
    assert_eq!(
        std::fs::read(with.join("verge.csv")).unwrap(),
        std::fs::read(without.join("verge.csv")).unwrap(),
        "--matches changed the estimates"
    );

    let mut pairs: BTreeMap<usize, Vec<PixelPair>> = BTreeMap::new();
    let mut reader = csv::Reader::from_path(with.join("matches.csv")).unwrap();
    assert_eq!(
        reader.headers().unwrap(),
        vec!["frame", "left_x", "left_y", "right_x", "right_y", "weight"]
    );
    for row in reader.records() {
        let row = row.unwrap();
        let v: Vec<f64> = (1..6).map(|i| row[i].parse().unwrap()).collect();
        assert!(v[4] > 0.0, "weight {row:?}");
        pairs
            .entry(row[0].parse().unwrap())
            .or_default()
            .push(([v[0], v[1]], [v[2], v[3]]));
    }
    let inliers: Vec<usize> = csv::Reader::from_path(with.join("verge.csv"))
        .unwrap()
        .deserialize::<BTreeMap<String, String>>()
        .map(|r| r.unwrap()["inliers"].parse().unwrap())
        .collect();
    let rows: Vec<usize> = (0..inliers.len())
        .map(|f| pairs.get(&f).map_or(0, Vec::len))
        .collect();
    assert_eq!(rows, inliers, "rows per frame against verge.csv's inliers");

    let calib = Calibration::load(seq.join("calib.toml")).unwrap();
    let truth = read_truth_csv(&seq.join("truth.csv")).unwrap();
    let refit = VergeEstimator::new(calib, EstimatorConfig::default());
    for (frame, p) in &pairs {
        let est = refit.estimate_from_pixels(p).unwrap();
        let err = est.verge_deg - truth[*frame];
        assert!(err.abs() < 0.05, "frame {frame}: refit off by {err:.4}°");
    }
}
