//! The KITTI drive (`../shared/data/real/kitti_odometry_drive`, read at run time, never copied)
//! through the commands a user types: a head held at 1.5° while it turns ±1° (`stereocal
//! inject --motion fixed`) on a drive whose view changes every frame. Every frame must be
//! estimated, and the filtered verge must hold within issue 21's 0.05° span at the drive's
//! 10 fps (README, "Accuracy on real drives": 0.034°), helped by the filter learning how far
//! off the view puts its measurements (`host/src/kalman.rs`).

mod common;

use std::ffi::OsString;
use std::io::Write;
use std::path::{Path, PathBuf};

use common::{stereocal, succeeded};

/// Issue 21, item 2: the filtered span of a head that holds its verge.
const SPAN_LIMIT_DEG: f64 = 0.05;

/// KITTI's cameras run at 10 frames a second (bench/drives.py, `FRAME_RATES`).
const KITTI_FPS: &str = "10";

/// The drive's directory, or `None` (with a loud message) when the data set is absent outside
/// CI. Under `CI=true` its absence is a failure.
fn kitti() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/real/kitti_odometry_drive");
    if dir.join("calib.toml").is_file() {
        return Some(dir);
    }
    assert!(
        std::env::var("CI").as_deref() != Ok("true"),
        "KITTI drive missing under CI=true: {}",
        dir.display()
    );
    // Straight to stderr: the test harness captures `eprintln!`, and a skip must be seen.
    let _ = writeln!(
        std::io::stderr(),
        "\n*** SKIPPED the KITTI drive: {} not found ***\n",
        dir.display()
    );
    None
}

/// The `--left`, `--right` and `--calib` arguments of the sequence in `dir`, each flag and its
/// value as one argument (`--left=DIR/left`).
fn sequence(dir: &Path) -> [OsString; 3] {
    [
        ("left", "left"),
        ("right", "right"),
        ("calib", "calib.toml"),
    ]
    .map(|(flag, name)| {
        let mut arg = OsString::from(format!("--{flag}="));
        arg.push(dir.join(name));
        arg
    })
}

#[test]
fn a_held_head_on_a_real_drive_keeps_its_filtered_span() {
    let Some(kitti) = kitti() else { return };
    let tmp = tempfile::tempdir().expect("temp dir");
    let seq = tmp.path().join("fixed");
    let mut inject: Vec<OsString> = vec!["inject".into()];
    inject.extend(sequence(&kitti));
    inject.extend([
        "--motion".into(),
        "fixed".into(),
        "--out".into(),
        seq.clone().into(),
    ]);
    succeeded(stereocal(&inject));
    let mut run: Vec<OsString> = vec!["run".into()];
    run.extend(sequence(&seq));
    run.extend([
        "--truth".into(),
        seq.join("truth.csv").into(),
        "--fps".into(),
        KITTI_FPS.into(),
        "--out".into(),
        tmp.path().join("out").into(),
        "--json".into(),
    ]);
    let summary: serde_json::Value =
        serde_json::from_slice(&succeeded(stereocal(&run)).stdout).expect("JSON summary");
    let count = |key: &str| summary[key].as_u64().unwrap_or_else(|| panic!("{key}"));
    assert_eq!(count("estimated_frames"), count("frames"), "{summary}");
    let span = summary["filtered_span_deg"]
        .as_f64()
        .expect("filtered span");
    assert!(span <= SPAN_LIMIT_DEG, "filtered span {span:.4}°");
}

/// `inject --resample` warps the same frames with another kernel: the same truth and
/// calibration, other pixels.
#[test]
fn inject_resamples_with_the_kernel_it_is_given() {
    let Some(kitti) = kitti() else { return };
    let tmp = tempfile::tempdir().expect("temp dir");
    let inject = |kernel: &str| {
        let out = tmp.path().join(kernel);
        let mut args: Vec<OsString> = vec!["inject".into()];
        for (flag, name) in [("left-image", "left"), ("right-image", "right")] {
            let mut arg = OsString::from(format!("--{flag}="));
            arg.push(kitti.join(name).join("000000.png"));
            args.push(arg);
        }
        let mut calib = OsString::from("--calib=");
        calib.push(kitti.join("calib.toml"));
        args.push(calib);
        args.extend(["--frames", "2", "--resample", kernel, "--out"].map(OsString::from));
        args.push(out.clone().into());
        succeeded(stereocal(&args));
        let read = |name: &str| std::fs::read(out.join(name)).expect(name);
        let frames: Vec<Vec<u8>> = [
            "left/000000.png",
            "left/000001.png",
            "right/000000.png",
            "right/000001.png",
        ]
        .map(read)
        .into();
        (read("truth.csv"), read("calib.toml"), frames)
    };
    let (bicubic, lanczos) = (inject("bicubic"), inject("lanczos5"));
    assert_eq!(bicubic.0, lanczos.0, "truth.csv");
    assert_eq!(bicubic.1, lanczos.1, "calib.toml");
    assert_ne!(bicubic.2, lanczos.2, "the warped frames");
}
