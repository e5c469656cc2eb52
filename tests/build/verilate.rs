//! Verilator: finding it, and turning one top into C++ (`verilator --cc`) in a directory of
//! its own.

use std::path::{Path, PathBuf};
use std::process::{Child, Command};

/// One Verilated top: its sources, the parameters it is built with (`-G`) and the C++ file
/// that drives the model (a shim for the co-simulations, the harness for the SoC).
pub struct Top {
    pub module: &'static str,
    pub params: &'static [(&'static str, u32)],
    pub sources: Vec<PathBuf>,
    pub driver: PathBuf,
}

/// The Verilator installation: its runtime's include directory (`verilated.cpp` and the
/// headers the generated code includes).
pub struct Verilator {
    pub include: PathBuf,
}

impl Verilator {
    /// `Err` says why there is no usable Verilator: a missing tool is a skip, not a failure.
    pub fn find() -> Result<Self, String> {
        let version = Command::new("verilator").arg("--version").output();
        if !version.is_ok_and(|o| o.status.success()) {
            return Err("`verilator` not found on PATH (Debian: apt-get install verilator)".into());
        }
        let root = Command::new("verilator")
            .args(["--getenv", "VERILATOR_ROOT"])
            .output()
            .map_err(|e| format!("verilator --getenv VERILATOR_ROOT: {e}"))?;
        let include = PathBuf::from(String::from_utf8_lossy(&root.stdout).trim()).join("include");
        if !include.join("verilated.cpp").exists() {
            return Err(format!("no verilated.cpp under {}", include.display()));
        }
        Ok(Self { include })
    }
}

/// Starts `verilator --cc` on `top` into `mdir`: fully optimised and without assertions (the
/// simulations run millions of clocks), the model's class named `V<module>` so that several
/// models link into one binary. Lint warnings do not stop it: the RTL's own lint is CI's
/// `verilator -Wall` step, and the SoC's core is generated Verilog that is not ours.
pub fn spawn(top: &Top, mdir: &Path) -> Child {
    Command::new("verilator")
        .args(["--cc", "-O3", "--x-assign", "fast", "--x-initial", "unique"])
        .arg("--noassert")
        .args(["-Wno-fatal", "-Wno-lint", "-Wno-style"])
        .args(["--top-module", top.module, "--prefix"])
        .arg(format!("V{}", top.module))
        .args(
            top.params
                .iter()
                .map(|(name, value)| format!("-G{name}={value}")),
        )
        .arg("--Mdir")
        .arg(mdir)
        .args(&top.sources)
        .spawn()
        .unwrap_or_else(|e| panic!("running verilator (top {}): {e}", top.module))
}

/// Waits for a `spawn`ed run. A Verilator error on present sources panics: that is a broken
/// RTL, not a missing tool.
pub fn wait(top: &Top, mut child: Child) {
    let status = child
        .wait()
        .unwrap_or_else(|e| panic!("running verilator (top {}): {e}", top.module));
    assert!(
        status.success(),
        "verilator --cc (top {}) failed (see its messages above)",
        top.module
    );
}
