//! The `stereocal run` binary (and `stereocal inject` on a sequence) against bad input, end to end.
//!
//! The CLI contract (`docs/ARCHITECTURE.md`, "The command line") promises that every bad call ends with a message naming
//! the file, field, key or flag at fault, a non-zero exit, and nothing half-written. Unit tests
//! check the error values of each module; these tests check what a user actually sees: the
//! exit status, stderr (the named culprit, and never a panic) and the `--out` directory (no
//! `verge.csv` or `verge.png`). The last test is the contract's other side of a failure: a
//! sequence without texture is not an error, it gives `no_estimate` rows.
//!
//! Every sequence is a few 160x120 frames (one image is wider, to exceed the fabric), so the
//! whole file runs in under a second in release.

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;

use image::{GrayImage, Luma};
use tempfile::TempDir;

const VALID_CALIB: &str = "baseline_m = 0.3
[left]
fx = 500.0
fy = 500.0
cx = 80.0
cy = 60.0
[right]
fx = 500.0
fy = 500.0
cx = 80.0
cy = 60.0
";

const WIDTH: u32 = 160;
const HEIGHT: u32 = 120;

/// A scratch directory with `left/`, `right/`, `calib.toml` and the path of a (not yet
/// created) `out/` directory.
struct Fixture {
    root: TempDir,
}

impl Fixture {
    /// Empty `left/` and `right/` directories and the valid calibration.
    fn new() -> Self {
        let root = tempfile::tempdir().expect("temp dir");
        std::fs::create_dir(root.path().join("left")).expect("left dir");
        std::fs::create_dir(root.path().join("right")).expect("right dir");
        let fixture = Fixture { root };
        fixture.write_calib(VALID_CALIB);
        fixture
    }

    /// `frames` pairs of valid textured 160x120 images.
    fn with_frames(frames: usize) -> Self {
        let fixture = Self::new();
        for i in 0..frames {
            let name = frame_name(i);
            save(&textured(WIDTH, HEIGHT), &fixture.left().join(&name));
            save(&textured(WIDTH, HEIGHT), &fixture.right().join(&name));
        }
        fixture
    }

    fn path(&self, name: &str) -> PathBuf {
        self.root.path().join(name)
    }

    fn left(&self) -> PathBuf {
        self.path("left")
    }

    fn right(&self) -> PathBuf {
        self.path("right")
    }

    fn calib(&self) -> PathBuf {
        self.path("calib.toml")
    }

    fn out(&self) -> PathBuf {
        self.path("out")
    }

    fn write_calib(&self, text: &str) {
        std::fs::write(self.calib(), text).expect("write calib");
    }

    /// `stereocal run` on the fixture's directories, calibration and output, plus `extra`.
    fn run(&self, extra: &[&str]) -> Output {
        self.command("run", extra)
    }

    /// `stereocal COMMAND` on the fixture's directories (as a sequence), calibration and
    /// output, plus `extra`. Backtraces are off, as for a user: stderr is the message alone,
    /// and no backtrace frame (`lifecycle.rs` holds `cy`) can stand in for the culprit's name.
    fn command(&self, command: &str, extra: &[&str]) -> Output {
        common::command()
            .arg(command)
            .arg("--left")
            .arg(self.left())
            .arg("--right")
            .arg(self.right())
            .arg("--calib")
            .arg(self.calib())
            .arg("--out")
            .arg(self.out())
            .args(extra)
            .output()
            .expect("the stereocal binary runs")
    }

    /// Runs with `extra` and checks the failure contract: non-zero exit, stderr holds every
    /// one of `needles` and no panic, and nothing at all was written to `--out` (neither
    /// `verge.csv` nor `verge.png`, nor a leftover staging directory).
    fn assert_fails(&self, extra: &[&str], needles: &[&str]) {
        let output = self.run(extra);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            !output.status.success(),
            "expected a failure, got {}; stderr:\n{stderr}",
            output.status
        );
        assert!(!stderr.contains("panicked"), "panic:\n{stderr}");
        for needle in needles {
            assert!(
                stderr.contains(needle),
                "stderr does not name `{needle}`:\n{stderr}"
            );
        }
        let written: Vec<PathBuf> = match std::fs::read_dir(self.out()) {
            Ok(entries) => entries.map(|e| e.expect("list out").path()).collect(),
            Err(_) => Vec::new(),
        };
        assert!(written.is_empty(), "a failed run wrote {written:?}");
    }
}

fn frame_name(i: usize) -> String {
    format!("{i:04}.png")
}

/// A deterministic pattern with plenty of gradient, so that only the fault under test fails.
fn textured(width: u32, height: u32) -> GrayImage {
    GrayImage::from_fn(width, height, |x, y| {
        Luma([((x * 37 + y * 91 + (x * y) % 29 * 5) % 256) as u8])
    })
}

fn save(image: &GrayImage, path: &Path) {
    image.save(path).expect("write image");
}

fn display(path: &Path) -> String {
    path.display().to_string()
}

#[test]
fn missing_left_or_right_directory() {
    let f = Fixture::with_frames(1);
    std::fs::remove_dir_all(f.left()).expect("remove left");
    f.assert_fails(&[], &["left image directory", &display(&f.left())]);

    let f = Fixture::with_frames(1);
    std::fs::remove_dir_all(f.right()).expect("remove right");
    f.assert_fails(&[], &["right image directory", &display(&f.right())]);
}

#[test]
fn directory_without_images() {
    let f = Fixture::with_frames(2);
    for i in 0..2 {
        std::fs::remove_file(f.right().join(frame_name(i))).expect("remove image");
    }
    // A file that is not an image does not count.
    std::fs::write(f.right().join("notes.txt"), "not an image").expect("write notes");
    f.assert_fails(&[], &["right image directory", "holds no"]);
}

#[test]
fn different_frame_counts() {
    let f = Fixture::with_frames(3);
    std::fs::remove_file(f.left().join(frame_name(2))).expect("remove image");
    f.assert_fails(
        &[],
        &["left directory has 2 images but right directory has 3"],
    );
}

#[test]
fn png_cut_in_half_is_named() {
    // Frame 1 of 3: the failure comes after a frame was processed, so this also checks that a
    // run stopped part-way writes nothing.
    let f = Fixture::with_frames(3);
    let broken = f.right().join(frame_name(1));
    let bytes = std::fs::read(&broken).expect("read image");
    std::fs::write(&broken, &bytes[..bytes.len() / 2]).expect("truncate image");
    f.assert_fails(&[], &[&display(&broken), "cannot decode"]);
}

#[test]
fn png_holding_text_is_named() {
    let f = Fixture::with_frames(2);
    let broken = f.left().join(frame_name(0));
    std::fs::write(&broken, "this is not a PNG\n").expect("write text");
    f.assert_fails(&[], &[&display(&broken), "cannot decode"]);
}

#[test]
fn left_and_right_sizes_differ() {
    let f = Fixture::with_frames(2);
    save(
        &textured(WIDTH, HEIGHT - 20),
        &f.right().join(frame_name(0)),
    );
    f.assert_fails(&[], &["frame 0", "160x120", "160x100", "differ in size"]);
}

#[test]
fn image_wider_than_the_fabric() {
    let f = Fixture::new();
    // 1281 px is one more than the line buffers hold; 16 lines keep the files small.
    for dir in [f.left(), f.right()] {
        save(&textured(1281, 16), &dir.join(frame_name(0)));
    }
    f.assert_fails(&[], &["1281 px wide", "at most 1280 px"]);
}

#[test]
fn calibration_with_an_unknown_key() {
    let f = Fixture::with_frames(1);
    f.write_calib(&VALID_CALIB.replace("cy = 60.0\n[right]", "cy = 60.0\nskew = 0.0\n[right]"));
    f.assert_fails(&[], &[&display(&f.calib()), "unknown field `skew`"]);
}

#[test]
fn calibration_with_a_wrong_type() {
    let f = Fixture::with_frames(1);
    f.write_calib(&VALID_CALIB.replacen("fx = 500.0", "fx = \"abc\"", 1));
    // The parser's message names the type; its quoted line names the key.
    f.assert_fails(
        &[],
        &[
            &display(&f.calib()),
            "invalid type: string \"abc\"",
            "fx = \"abc\"",
        ],
    );
}

#[test]
fn calibration_with_a_missing_field() {
    let f = Fixture::with_frames(1);
    f.write_calib(&VALID_CALIB.replacen("cy = 60.0\n", "", 1));
    f.assert_fails(&[], &[&display(&f.calib()), "missing field `cy`", "[left]"]);
}

#[test]
fn out_of_range_flags() {
    let f = Fixture::with_frames(1);
    for (flag, value, reason) in [
        ("--ratio", "0", "outside (0, 1)"),
        ("--ratio", "1", "outside (0, 1)"),
        ("--ratio", "1.5", "outside (0, 1)"),
        ("--best", "0", "must be at least 1"),
    ] {
        f.assert_fails(&[flag, value], &[flag, &format!("'{value}'"), reason]);
    }
}

#[test]
fn truth_with_a_bad_header() {
    let f = Fixture::with_frames(2);
    let truth = f.path("truth.csv");
    std::fs::write(&truth, "frame,angle\n0,0.5\n1,0.5\n").expect("write truth");
    let truth_arg = display(&truth);
    f.assert_fails(
        &["--truth", &truth_arg],
        &[
            &truth_arg,
            "header must be `frame,verge_deg`",
            "frame,angle",
        ],
    );
}

#[test]
fn truth_with_a_non_numeric_value() {
    let f = Fixture::with_frames(2);
    let truth = f.path("truth.csv");
    std::fs::write(&truth, "frame,verge_deg\n0,0.5\n1,abc\n").expect("write truth");
    let truth_arg = display(&truth);
    f.assert_fails(
        &["--truth", &truth_arg],
        &[&format!("{truth_arg}:3"), "verge_deg `abc`"],
    );
}

#[test]
fn encoders_with_a_bad_field_or_a_frame_beyond_the_sequence() {
    let f = Fixture::with_frames(2);
    let encoders = f.path("encoders.csv");
    let arg = display(&encoders);
    for (text, expected) in [
        (
            "frame,left_yaw_deg,right_yaw_deg\n0,0.8,-0.8\n1,0.8,x\n",
            vec![format!("{arg}:3"), "field `right_yaw_deg`: `x`".into()],
        ),
        (
            "frame,verge_deg\n0,1.6\n2,1.6\n",
            vec![
                format!("{arg}:3"),
                "frame 2 is beyond the sequence's 2 frames".into(),
            ],
        ),
        (
            "frame,yaw_deg\n0,1.6\n",
            vec![arg.clone(), "header must be".into()],
        ),
    ] {
        std::fs::write(&encoders, text).expect("write encoders");
        let expected: Vec<&str> = expected.iter().map(String::as_str).collect();
        f.assert_fails(&["--encoders", &arg], &expected);
    }
}

#[test]
fn textureless_sequence_gives_no_estimate_rows() {
    const FRAMES: usize = 3;
    let f = Fixture::new();
    let grey = GrayImage::from_pixel(WIDTH, HEIGHT, Luma([128]));
    for i in 0..FRAMES {
        save(&grey, &f.left().join(frame_name(i)));
        save(&grey, &f.right().join(frame_name(i)));
    }
    let output = f.run(&[]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{}:\n{stderr}", output.status);
    assert!(!stderr.contains("panicked"), "panic:\n{stderr}");

    let csv = std::fs::read_to_string(f.out().join("verge.csv")).expect("verge.csv written");
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some(
            "frame,raw_verge_deg,filtered_verge_deg,filtered_sigma_deg,matches,inliers,status,\
             pitch_deg,roll_deg,baseline_tilt_deg,packets_lost,keypoints_lost,truth_deg,\
             raw_sigma_deg"
        )
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), FRAMES, "{csv}");
    for (i, row) in rows.iter().enumerate() {
        assert_eq!(row.len(), 14, "{csv}");
        assert_eq!(row[0], i.to_string(), "{csv}");
        assert_eq!(&row[1..4], ["", "", ""], "angles of frame {i}:\n{csv}");
        assert_eq!(row[6], "no_estimate", "{csv}");
        assert_eq!(
            &row[7..10],
            ["", "", ""],
            "misalignment of frame {i}:\n{csv}"
        );
        assert_eq!(&row[10..12], ["0", "0"], "link losses of frame {i}:\n{csv}");
        assert_eq!(row[12], "", "no truth given, frame {i}:\n{csv}");
        assert_eq!(row[13], "", "no estimate, no sigma, frame {i}:\n{csv}");
    }
    assert!(f.out().join("verge.png").is_file(), "verge.png written");
}

impl Fixture {
    /// `stereocal inject` on the fixture's directories as a sequence, writing to `--out`.
    fn inject(&self, extra: &[&str]) -> Output {
        self.command("inject", extra)
    }
}

#[test]
fn inject_into_a_sequence_writes_every_frame_its_truth_and_its_yaws() {
    let f = Fixture::with_frames(2);
    let output = f.inject(&["--motion", "swing"]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for side in ["left", "right"] {
        let n = std::fs::read_dir(f.out().join(side)).expect("list").count();
        assert_eq!(n, 2, "{side}");
    }
    let truth = std::fs::read_to_string(f.out().join("truth.csv")).expect("truth");
    assert_eq!(truth.lines().count(), 3, "{truth}");
    assert!(truth.starts_with("frame,verge_deg\n0,0.0"), "{truth}");
    let encoders = std::fs::read_to_string(f.out().join("encoders.csv")).expect("encoders");
    assert_eq!(encoders.lines().count(), 3, "{encoders}");
    assert!(
        encoders.starts_with("frame,left_yaw_deg,right_yaw_deg\n0,0.0"),
        "{encoders}"
    );
}

#[test]
fn inject_refuses_bad_sequences_and_flag_mixes() {
    let f = Fixture::with_frames(2);
    let fails = |extra: &[&str], needle: &str| {
        let output = f.inject(extra);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            !output.status.success() && !stderr.contains("panicked"),
            "{stderr}"
        );
        assert!(
            stderr.contains(needle),
            "stderr does not name `{needle}`:\n{stderr}"
        );
        assert!(
            !f.out().exists(),
            "a failed inject wrote {}",
            display(&f.out())
        );
    };
    fails(&["--frames", "3"], "3 asked for, the sequence has 2");
    let image = display(&f.left().join(frame_name(0)));
    fails(&["--left-image", &image], "--left-image");
    let broken = f.right().join(frame_name(1));
    std::fs::write(&broken, "this is not a PNG\n").expect("write text");
    fails(&[], &display(&broken));
}
