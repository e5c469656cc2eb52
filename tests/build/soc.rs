//! The SoC in the loop (`hdl-interface/soc`): its core fetched, and its top.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::verilate::Top;

/// Fetches the core with `fetch_core.sh` into `out/core` (the script keeps its venv there and
/// only re-runs pip on a later build); the adapted core's Verilog. `Err` says why there is no
/// core: no python3 with venv, or no network for pip on the first build.
pub fn fetch_core(soc: &Path, out: &Path) -> Result<PathBuf, String> {
    let dir = out.join("core");
    let fetched = Command::new("bash")
        .arg(soc.join("fetch_core.sh"))
        .arg(&dir)
        .output()
        .map_err(|e| format!("cannot run bash for hdl-interface/soc/fetch_core.sh: {e}"))?;
    if !fetched.status.success() {
        let stderr = String::from_utf8_lossy(&fetched.stderr);
        // Its last lines, on one line: the reason travels in an environment variable.
        let lines: Vec<&str> = stderr.lines().collect();
        return Err(format!(
            "hdl-interface/soc/fetch_core.sh could not fetch the core (it needs python3 with \
             venv, Debian: apt-get install python3-venv, and network for pip on the first \
             build): {}",
            lines[lines.len().saturating_sub(3)..].join(" / ")
        ));
    }
    Ok(dir.join("VexRiscv_virt.v"))
}

/// Top `sc_soc` (its fabrics at their default 640-pixel lines) from `sc_soc.v`, the core and
/// the fabric's `rtl` sources, driven by the harness `sim/sc_soc_sim.cpp`.
pub fn top(soc: &Path, core: PathBuf, rtl: &[PathBuf]) -> Top {
    let mut sources = vec![soc.join("sc_soc.v"), core];
    sources.extend_from_slice(rtl);
    Top {
        module: "sc_soc",
        params: &[],
        sources,
        driver: soc.join("sim/sc_soc_sim.cpp"),
    }
}
