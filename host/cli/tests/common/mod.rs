//! What the command-line tests share: the built `stereocal` and running it as a user does.
//!
//! Each test file compiles this module on its own and uses part of it.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::path::Path;
use std::process::{Command, Output};

/// The `stereocal` binary Cargo built for these tests.
pub const BIN: &str = env!("CARGO_BIN_EXE_stereocal");

/// `stereocal` with the backtrace variables removed, as for a user: a failure's stderr is
/// then its message alone, the same under any environment, and no backtrace frame can stand
/// in for the name a message must give.
pub fn command() -> Command {
    let mut c = Command::new(BIN);
    c.env_remove("RUST_BACKTRACE")
        .env_remove("RUST_LIB_BACKTRACE");
    c
}

/// Runs `stereocal` with `args` to its end.
pub fn stereocal<S: AsRef<OsStr>>(args: &[S]) -> Output {
    command().args(args).output().expect("stereocal runs")
}

/// `out`, after checking that its command succeeded; a failure shows the command's stderr.
#[track_caller]
pub fn succeeded(out: Output) -> Output {
    assert!(
        out.status.success(),
        "stereocal failed ({}): {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// `stereocal synth --scene road --frames FRAMES --seed SEED --out OUT`, which must succeed:
/// the rendered road with exact truth (left/, right/, calib.toml, truth.csv, ...).
pub fn synth_road(out: &Path, frames: usize, seed: u64) {
    succeeded(stereocal(&[
        "synth",
        "--scene",
        "road",
        "--frames",
        &frames.to_string(),
        "--seed",
        &seed.to_string(),
        "--out",
        out.to_str().expect("a UTF-8 path"),
    ]));
}
