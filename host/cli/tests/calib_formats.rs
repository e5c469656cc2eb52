//! `--calib` reads the calibrations users already have: OpenCV's `stereoCalibrate` results as
//! `cv::FileStorage` writes them, a Kalibr camchain and KITTI's `calib.txt`, recognised by
//! content. The fixtures in `tests/data/calib/` hold two rigs, each written in its tools' own
//! conventions: the rendered road head (rectified; all four formats, OpenCV's as YAML and as
//! JSON) and a raw head verged by
//! 1.2° with fixed misalignments (TOML, OpenCV, Kalibr; KITTI holds only rectified pairs).
//! Every file of a rig must read as that rig's TOML, `stereocal run` must estimate the same on
//! each, and each bad file must be refused with the file, key and line named.

mod common;

use std::path::{Path, PathBuf};

use common::{stereocal, succeeded, synth_road};
use stereocal::calib::{Calibration, Extrinsics};
use stereocal::output::verge_csv::read_truth_csv;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/calib")
        .join(name)
}

fn load(name: &str) -> Calibration {
    Calibration::load(fixture(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The intrinsics must be read to the bit; the baseline and pose come out of arithmetic on
/// R and T (KITTI: `-P1[0,3] / P1[0,0]`), so they are compared to a rounding error.
fn assert_same_rig(name: &str, got: &Calibration, want: &Calibration) {
    assert_eq!(got.left, want.left, "{name}: left camera");
    assert_eq!(got.right, want.right, "{name}: right camera");
    assert!(
        (got.baseline_m - want.baseline_m).abs() < 1e-12,
        "{name}: baseline {} vs {}",
        got.baseline_m,
        want.baseline_m
    );
    let angles = |e: &Extrinsics| {
        [
            e.verge_deg,
            e.pitch_deg,
            e.roll_deg,
            e.left_yaw_deg,
            e.baseline_tilt_deg,
        ]
    };
    for (g, w) in angles(&got.extrinsics).iter().zip(angles(&want.extrinsics)) {
        assert!(
            (g - w).abs() < 1e-9,
            "{name}: pose {:?} vs {:?}",
            got.extrinsics,
            want.extrinsics
        );
    }
}

#[test]
fn every_format_of_the_rectified_rig_reads_as_its_toml() {
    let toml = load("road.toml");
    assert!(toml.extrinsics.is_zero());
    for name in [
        "road-opencv.yml",
        "road-opencv.json",
        "road-camchain.yaml",
        "road-kitti.txt",
    ] {
        let got = load(name);
        assert_same_rig(name, &got, &toml);
        // A rectified pair has no pose at all, not a pose of rounding errors.
        assert!(got.extrinsics.is_zero(), "{name}: {:?}", got.extrinsics);
    }
}

#[test]
fn the_starting_verge_and_misalignments_come_from_r_and_t() {
    let toml = load("verged.toml");
    assert_eq!(toml.extrinsics.verge_deg, 1.2);
    for name in ["verged-opencv.yml", "verged-camchain.yaml"] {
        let got = load(name);
        assert_same_rig(name, &got, &toml);
        assert!((got.extrinsics.verge_deg - 1.2).abs() < 1e-9, "{name}");
        assert!((got.extrinsics.pitch_deg - 0.3).abs() < 1e-9, "{name}");
    }
    // The TOML can say everything the other formats can: what it writes reads back the same.
    let again = Calibration::from_str_any(&load("verged-opencv.yml").to_toml_string(), "x")
        .expect("written TOML reads back");
    assert_eq!(again, load("verged-opencv.yml"));
}

#[test]
fn run_on_each_format_estimates_what_run_on_the_toml_does() {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("seq");
    synth_road(&seq, 4, 3);
    let run = |calib: &str| {
        let out = dir.path().join(calib);
        let summary = succeeded(stereocal(&[
            "run",
            "--left",
            seq.join("left").to_str().unwrap(),
            "--right",
            seq.join("right").to_str().unwrap(),
            "--calib",
            fixture(calib).to_str().unwrap(),
            "--truth",
            seq.join("truth.csv").to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--json",
        ]));
        let summary: serde_json::Value = serde_json::from_slice(&summary.stdout).unwrap();
        assert_eq!(summary["estimated_frames"], 4, "{calib}: {summary}");
        std::fs::read_to_string(out.join("verge.csv")).unwrap()
    };
    let toml = run("road.toml");
    // `verge.csv` carries the truth it was given, to its 6 decimals.
    let given = read_truth_csv(&seq.join("truth.csv")).unwrap();
    let mut lines = toml.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let at = header.iter().position(|h| *h == "truth_deg").unwrap();
    let written: Vec<f64> = lines
        .map(|l| l.split(',').nth(at).unwrap().parse().unwrap())
        .collect();
    assert_eq!(given.len(), written.len(), "{toml}");
    for (g, w) in given.iter().zip(&written) {
        assert!((g - w).abs() <= 5e-7, "truth {g}, verge.csv {w}:\n{toml}");
    }
    for calib in [
        "road-opencv.yml",
        "road-opencv.json",
        "road-camchain.yaml",
        "road-kitti.txt",
    ] {
        assert_eq!(
            run(calib),
            toml,
            "{calib} estimates otherwise than road.toml"
        );
    }
}

/// Writes `text` to a file named `name` and checks that loading it fails with an error naming
/// the file, and every one of `needles`.
fn assert_refused(name: &str, text: &str, needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    let err = match Calibration::load(&path) {
        Ok(c) => panic!("{name} was read as {c:?}"),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains(name),
        "the error does not name the file: {err}"
    );
    for needle in needles {
        assert!(err.contains(needle), "`{needle}` missing from: {err}");
    }
}

/// `text` with the first `from` replaced by `to`, and the line `from` starts on.
fn edit(text: &str, from: &str, to: &str) -> (String, usize) {
    let at = text
        .find(from)
        .unwrap_or_else(|| panic!("`{from}` not in the fixture"));
    (
        text.replacen(from, to, 1),
        text[..at].matches('\n').count() + 1,
    )
}

fn line(n: usize) -> String {
    format!("line {n}")
}

fn read(name: &str) -> String {
    std::fs::read_to_string(fixture(name)).unwrap()
}

#[test]
fn opencv_errors_name_the_file_key_and_line() {
    let text = read("verged-opencv.yml");
    // A bad number.
    let (bad, at) = edit(&text, "3.6721499999999997e+02", "3.67.215e+02");
    assert_refused(
        "bad-number.yml",
        &bad,
        &["M1.data[2]", &line(at), "3.67.215e+02"],
    );
    // A matrix of the wrong size: T with four rows (the error stands on `T:`).
    let (bad, at) = edit(
        &text,
        "   rows: 3\n   cols: 1\n   dt: d\n   data: [ -1.0998825163307825e-01,",
        "   rows: 4\n   cols: 1\n   dt: d\n   data: [ 0., -1.0998825163307825e-01,",
    );
    assert_refused("wrong-size.yml", &bad, &["`T`", &line(at - 1), "4x1"]);
    // data not matching rows x cols (the error stands on `data:`, a line up).
    let (bad, at) = edit(
        &text,
        "1.7618711400000001e-05, 0. ]",
        "1.7618711400000001e-05 ]",
    );
    assert_refused(
        "short-data.yml",
        &bad,
        &["D1.data", &line(at - 1), "4 values for 1x5"],
    );
    // A distortion model beyond k1, k2, p1, p2, k3 (CALIB_RATIONAL_MODEL's k4, k5, k6).
    let (bad, at) = edit(
        &text,
        "D2: !!opencv-matrix\n   rows: 1\n   cols: 5",
        "D2: !!opencv-matrix\n   rows: 1\n   cols: 8",
    );
    let (bad, _) = edit(
        &bad,
        "-3.5559070000000001e-05, 0. ]",
        "-3.5559070000000001e-05, 0., 0., 0.1, 0. ]",
    );
    assert_refused("rational.yml", &bad, &["`D2`", &line(at), "k5 = 0.1"]);
    // A missing key.
    let bad = text.replace("T: !!opencv-matrix", "Tvec: !!opencv-matrix");
    assert_refused("missing.yml", &bad, &["`T`", "missing"]);
    // Not a rotation (the error stands on `R:`, four lines above its data).
    let (bad, at) = edit(&text, "9.9977754435494204e-01", "9.8e-01");
    assert_refused(
        "not-a-rotation.yml",
        &bad,
        &["`R`", &line(at - 4), "not a rotation"],
    );
    // XML storage is named as such, not taken for broken TOML.
    let xml = "<?xml version=\"1.0\"?>\n<opencv_storage>\n<R type_id=\"opencv-matrix\">\n";
    assert_refused("stereo.xml", xml, &["XML", "YAML or JSON"]);
}

#[test]
fn kalibr_errors_name_the_file_key_and_line() {
    let text = read("verged-camchain.yaml");
    let (bad, at) = edit(&text, "intrinsics: [458.654,", "intrinsics: [458.6x4,");
    assert_refused(
        "bad-number.yaml",
        &bad,
        &["cam0.intrinsics[0]", &line(at), "458.6x4"],
    );
    // Without its last row; the error stands on `T_cn_cnm1:`, four lines up.
    let (bad, at) = edit(&text, "  - [0.0, 0.0, 0.0, 1.0]\n", "");
    assert_refused(
        "three-rows.yaml",
        &bad,
        &["cam1.T_cn_cnm1", &line(at - 4), "4x4"],
    );
    let (bad, at) = edit(
        &text,
        "distortion_model: radtan",
        "distortion_model: equidistant",
    );
    assert_refused(
        "fisheye.yaml",
        &bad,
        &["cam0.distortion_model", &line(at), "equidistant"],
    );
    let (bad, at) = edit(&text, "camera_model: pinhole", "camera_model: omni");
    assert_refused("omni.yaml", &bad, &["cam0.camera_model", &line(at), "omni"]);
    let bad = text.replacen("  intrinsics: [457.587", "  intrinsic: [457.587", 1);
    assert_refused("missing.yaml", &bad, &["cam1.intrinsics", "missing"]);
}

#[test]
fn kitti_errors_name_the_file_key_and_line() {
    let text = read("road-kitti.txt");
    let (bad, at) = edit(&text, "-1.810500000000e+02", "-1.81O5e+02");
    assert_refused("bad-number.txt", &bad, &["`P1`", &line(at), "-1.81O5e+02"]);
    let (bad, at) = edit(&text, " 0.000000000000e+00\nP2:", "\nP2:");
    assert_refused("eleven.txt", &bad, &["`P1`", &line(at), "11 values"]);
    let bad: String =
        text.lines()
            .filter(|l| !l.starts_with("P1:"))
            .fold(String::new(), |mut s, l| {
                s.push_str(l);
                s.push('\n');
                s
            });
    assert_refused("missing.txt", &bad, &["`P1`", "missing"]);
    let (bad, at) = edit(&text, "Tr:", "Tr");
    assert_refused("no-colon.txt", &bad, &[&line(at), "KEY: values"]);
}

#[test]
fn run_names_the_bad_key_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (bad, at) = edit(
        &read("road-camchain.yaml"),
        "distortion_model: radtan",
        "distortion_model: fov",
    );
    let calib = dir.path().join("camchain.yaml");
    std::fs::write(&calib, bad).unwrap();
    for side in ["left", "right"] {
        std::fs::create_dir(dir.path().join(side)).unwrap();
    }
    let out = dir.path().join("out");
    let run = stereocal(&[
        "run",
        "--left",
        dir.path().join("left").to_str().unwrap(),
        "--right",
        dir.path().join("right").to_str().unwrap(),
        "--calib",
        calib.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success(), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    for needle in ["camchain.yaml", "cam0.distortion_model", &line(at), "fov"] {
        assert!(stderr.contains(needle), "`{needle}` missing from: {stderr}");
    }
    assert!(
        !out.exists(),
        "a refused calibration wrote {}",
        out.display()
    );
}

#[test]
fn inject_refuses_an_unrectified_pair() {
    let dir = tempfile::tempdir().unwrap();
    let out = stereocal(&[
        "inject",
        "--left-image",
        "left.png",
        "--right-image",
        "right.png",
        "--calib",
        fixture("verged-camchain.yaml").to_str().unwrap(),
        "--out",
        dir.path().join("set").to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    for needle in ["verged-camchain.yaml", "unrectified", "verge 1.2000°"] {
        assert!(stderr.contains(needle), "`{needle}` missing from: {stderr}");
    }
}
