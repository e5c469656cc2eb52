//! Ctrl-C during `stereocal run`'s final write leaves nothing behind: no staging directory,
//! and in `--out` either the previous `verge.csv` and `verge.png` or the new ones, never one of
//! each. Ctrl-C while `stereocal synth` or `stereocal inject` writes a sequence leaves neither
//! its staging directory nor a part of the sequence.
//!
//! The test watches the output directory and sends SIGINT once the run's staging directory
//! appears, after a delay that grows from trial to trial, so that the signals land while the
//! files are written, while they are moved into place and after; at least one trial must
//! have been ended by the signal, or the test did not test anything.
#![cfg(unix)]

mod common;

use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

use image::{GrayImage, Luma};
use stereocal::output::output_dir::STAGING_PREFIX;

const FRAMES: usize = 12;
const CALIB: &str = "baseline_m = 0.3
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
const OLD_CSV: &str = "the previous run's verge.csv\n";
const OLD_PNG: &[u8] = b"the previous run's verge.png";

fn textured(shift: u32) -> GrayImage {
    GrayImage::from_fn(160, 120, |x, y| {
        let x = x + shift;
        Luma([((x * 37 + y * 91 + (x * y) % 29 * 5) % 256) as u8])
    })
}

fn staging_entries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|name| name.starts_with(STAGING_PREFIX))
                .collect()
        })
        .unwrap_or_default()
}

/// How one interrupted run ended.
struct Trial {
    /// The signal was sent (the staging directory appeared before the process ended).
    signalled: bool,
    /// The exit status: 0 when the run finished first, 130 when the signal ended it.
    code: i32,
    /// The output directory still holds the previous files.
    old_kept: bool,
}

/// Sends SIGINT to `child`.
fn interrupt(child: &std::process::Child) {
    let pid = libc::pid_t::try_from(child.id()).unwrap();
    // SAFETY: `kill` only sends a signal; the child is ours and not yet reaped.
    assert_eq!(unsafe { libc::kill(pid, libc::SIGINT) }, 0);
}

fn trial(root: &Path, out: &Path, delay: Duration) -> Trial {
    std::fs::create_dir_all(out).unwrap();
    std::fs::write(out.join("verge.csv"), OLD_CSV).unwrap();
    std::fs::write(out.join("verge.png"), OLD_PNG).unwrap();
    let mut child = common::command()
        .arg("run")
        .arg("--left")
        .arg(root.join("left"))
        .arg("--right")
        .arg(root.join("right"))
        .arg("--calib")
        .arg(root.join("calib.toml"))
        .arg("--out")
        .arg(out)
        .arg("--json")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("stereocal runs");
    let started = Instant::now();
    let mut signalled = false;
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if !signalled && !staging_entries(out).is_empty() {
            let seen = Instant::now();
            while seen.elapsed() < delay {
                std::hint::spin_loop();
            }
            interrupt(&child);
            signalled = true;
        }
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "stereocal run did not end"
        );
    };
    let left = staging_entries(out);
    assert!(
        left.is_empty(),
        "left behind in {}: {left:?}",
        out.display()
    );
    let code = status
        .code()
        .unwrap_or_else(|| panic!("stereocal run was killed ({status}) instead of ending"));
    assert!(
        code == 0 || (signalled && code == 130),
        "exit status {code} (signal sent: {signalled})"
    );
    let csv = std::fs::read_to_string(out.join("verge.csv")).unwrap();
    let png = std::fs::read(out.join("verge.png")).unwrap();
    let old_csv = csv == OLD_CSV;
    let old_png = png == OLD_PNG;
    assert_eq!(
        old_csv, old_png,
        "one file of each run: verge.csv previous {old_csv}, verge.png previous {old_png}"
    );
    if !old_csv {
        assert_eq!(csv.lines().count(), FRAMES + 1, "a whole verge.csv:\n{csv}");
        image::load_from_memory(&png).expect("a whole verge.png");
    }
    Trial {
        signalled,
        code,
        old_kept: old_csv,
    }
}

#[test]
fn ctrl_c_during_the_final_write_leaves_the_old_output_or_the_new_and_no_staging() {
    let root = tempfile::tempdir().unwrap();
    for side in ["left", "right"] {
        std::fs::create_dir(root.path().join(side)).unwrap();
    }
    for i in 0..FRAMES {
        let name = format!("{i:04}.png");
        let shift = i as u32;
        textured(shift)
            .save(root.path().join("left").join(&name))
            .unwrap();
        textured(shift + 3)
            .save(root.path().join("right").join(&name))
            .unwrap();
    }
    std::fs::write(root.path().join("calib.toml"), CALIB).unwrap();

    let trials: Vec<Trial> = (0..16)
        .map(|i| {
            let out = root.path().join(format!("out{i}"));
            trial(root.path(), &out, Duration::from_micros(250 * i))
        })
        .collect();
    let interrupted = trials
        .iter()
        .filter(|t| t.signalled && t.code == 130)
        .count();
    let kept = trials.iter().filter(|t| t.old_kept).count();
    eprintln!(
        "{} trials: {interrupted} ended by SIGINT, {kept} of them with the previous files kept",
        trials.len()
    );
    assert!(
        interrupted > 0,
        "no SIGINT landed during the final write: the test exercised nothing"
    );
}

#[test]
fn ctrl_c_while_synth_writes_leaves_no_staging_and_no_part_of_the_sequence() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("sequence");
    interrupt_sequence_writer(
        root.path(),
        &out,
        &["synth", "--scene", "road", "--frames", "8", "--seed", "1"],
    );
}

#[test]
fn ctrl_c_while_inject_writes_leaves_no_staging_and_no_part_of_the_sequence() {
    let root = tempfile::tempdir().unwrap();
    let big = |shift: u32| {
        GrayImage::from_fn(640, 480, |x, y| {
            let x = x + shift;
            Luma([((x * 37 + y * 91 + (x * y) % 29 * 5) % 256) as u8])
        })
    };
    let (left, right, calib) = (
        root.path().join("l.png"),
        root.path().join("r.png"),
        root.path().join("calib.toml"),
    );
    big(0).save(&left).unwrap();
    big(7).save(&right).unwrap();
    std::fs::write(&calib, CALIB).unwrap();
    let out = root.path().join("sequence");
    let arg = |p: &Path| p.to_str().unwrap().to_string();
    interrupt_sequence_writer(
        root.path(),
        &out,
        &[
            "inject",
            "--left-image",
            &arg(&left),
            "--right-image",
            &arg(&right),
            "--calib",
            &arg(&calib),
            "--frames",
            "60",
        ],
    );
}

/// Runs `stereocal ARGS --out OUT`, sends SIGINT once its staging directory appears in
/// `root`, and checks that it ended by the signal with neither the staging directory nor any
/// part of `out` left.
fn interrupt_sequence_writer(root: &Path, out: &Path, args: &[&str]) {
    let mut child = common::command()
        .args(args)
        .arg("--out")
        .arg(out)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("stereocal runs");
    let started = Instant::now();
    while staging_entries(root).is_empty() {
        assert!(
            child.try_wait().unwrap().is_none(),
            "{} ended before its staging directory was seen",
            args[0]
        );
        assert!(started.elapsed() < Duration::from_secs(60), "no staging");
    }
    interrupt(&child);
    let status = child.wait().unwrap();
    let left = staging_entries(root);
    assert!(left.is_empty(), "left behind: {left:?}");
    assert_eq!(status.code(), Some(130), "{status}");
    assert!(
        !out.exists(),
        "a part of the sequence was left in {}",
        out.display()
    );
}
