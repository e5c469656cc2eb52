//! The generated C header, Verilog include and Verilog register block must pass the tools that
//! will consume them.
//!
//! Each test runs on the committed file (the staleness test ties it to the description).
//! A missing tool skips the test with a message on stderr, except under `CI=true`, where it
//! fails: CI installs gcc, verilator and iverilog.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use stereocal_hdl_regen::{hdl_interface_dir, C_PATH, VERILOG_PATH, VERILOG_REGS_PATH};

fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true")
}

/// True when `tool` runs; otherwise skips loudly, or panics under CI.
fn tool_available(tool: &str) -> bool {
    let found = Command::new(tool)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success() || !o.stdout.is_empty() || !o.stderr.is_empty());
    if !found {
        assert!(
            !in_ci(),
            "`{tool}` is required under CI=true but could not be run"
        );
        // Straight to stderr: the test harness captures `eprintln!`, and a skip must be seen.
        let _ = writeln!(
            std::io::stderr(),
            "SKIPPED: `{tool}` not found; install it to check the generated hdl-interface files"
        );
    }
    found
}

fn run(command: &mut Command) {
    let shown = format!("{command:?}");
    let out = command
        .output()
        .unwrap_or_else(|e| panic!("{shown}: could not run: {e}"));
    assert!(
        out.status.success() && out.stderr.is_empty(),
        "{shown} failed ({}):\n{}{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A scratch directory under the target dir, fresh for each test.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    dir
}

/// Includes the header and uses a few macros, so a macro that expands to nonsense fails too.
const C_USER: &str = r#"#include "stereocal_regs.h"
#include <stdint.h>
_Static_assert(STEREOCAL_BASE_ADDR % STEREOCAL_WINDOW_SIZE == 0u, "aligned window");
_Static_assert((STEREOCAL_OUTPUT_MODE_RESET & STEREOCAL_OUTPUT_MODE_SOBEL_SCALE_MASK)
                   >> STEREOCAL_OUTPUT_MODE_SOBEL_SCALE_SHIFT == STEREOCAL_OUTPUT_MODE_SOBEL_SCALE_RESET,
               "field reset inside register reset");
uint32_t stereocal_width_field(uint32_t reg) {
    return (reg & STEREOCAL_WIDTH_VALUE_MASK) >> STEREOCAL_WIDTH_VALUE_SHIFT;
}
"#;

#[test]
fn c_header_compiles() {
    if !tool_available("cc") {
        return;
    }
    let header = hdl_interface_dir().join(C_PATH);
    let include_dir = header.parent().expect("header has a directory");
    // The header alone (no -pedantic: on its own it is an empty translation unit).
    run(Command::new("cc")
        .args([
            "-fsyntax-only",
            "-std=c11",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-x",
            "c",
        ])
        .arg(&header));
    let dir = scratch("c_header_compiles");
    let user = dir.join("user.c");
    std::fs::write(&user, C_USER).unwrap_or_else(|e| panic!("{}: {e}", user.display()));
    run(Command::new("cc")
        .args([
            "-fsyntax-only",
            "-std=c11",
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-I",
        ])
        .arg(include_dir)
        .arg(&user));
}

/// Two modules including the file: the include must be legal in any module body, twice in
/// one compilation unit, and every localparam must elaborate. One module per file, named
/// after it, as verilator's -Wall wants.
const VERILOG_USER: &str = r#"`default_nettype none
module stereocal_regs_user (
    input  wire [31:0] status,
    output wire        frame_done
);
`include "stereocal_regs.vh"
    assign frame_done = |(status & SC_STATUS_FRAME_DONE_MASK);
endmodule
`default_nettype wire
"#;

const VERILOG_TOP: &str = r#"`default_nettype none
module stereocal_regs_top (
    input  wire [31:0] status,
    output wire        frame_done,
    output wire [7:0]  control_offset
);
`include "stereocal_regs.vh"
    assign control_offset = SC_CONTROL_OFFSET;
    stereocal_regs_user user (.status(status), .frame_done(frame_done));
endmodule
`default_nettype wire
"#;

/// Writes the two modules; returns their files and the include directory.
fn verilog_sources(test: &str) -> ([PathBuf; 2], PathBuf) {
    let dir = scratch(test);
    let files = [
        (dir.join("stereocal_regs_top.v"), VERILOG_TOP),
        (dir.join("stereocal_regs_user.v"), VERILOG_USER),
    ];
    for (path, text) in &files {
        std::fs::write(path, text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
    let include_dir = hdl_interface_dir()
        .join(VERILOG_PATH)
        .parent()
        .expect("include has a directory")
        .to_path_buf();
    ([files[0].0.clone(), files[1].0.clone()], include_dir)
}

#[test]
fn verilog_include_passes_verilator_lint() {
    if !tool_available("verilator") {
        return;
    }
    let (sources, include_dir) = verilog_sources("verilator_lint");
    run(Command::new("verilator")
        .args([
            "--lint-only",
            "-Wall",
            "--language",
            "1364-2005",
            "--top-module",
            "stereocal_regs_top",
        ])
        .arg(format!("-I{}", include_dir.display()))
        .args(&sources));
}

#[test]
fn verilog_include_passes_iverilog() {
    if !tool_available("iverilog") {
        return;
    }
    let (sources, include_dir) = verilog_sources("iverilog");
    let out = sources[0].with_extension("vvp");
    run(Command::new("iverilog")
        .args(["-g2005", "-Wall", "-s", "stereocal_regs_top", "-o"])
        .arg(&out)
        .arg("-I")
        .arg(&include_dir)
        .args(&sources));
}

#[test]
fn register_block_passes_verilator_lint() {
    if !tool_available("verilator") {
        return;
    }
    run(Command::new("verilator")
        .args([
            "--lint-only",
            "-Wall",
            "--language",
            "1364-2005",
            "--top-module",
            "sc_regs",
        ])
        .arg(hdl_interface_dir().join(VERILOG_REGS_PATH)));
}

#[test]
fn register_block_passes_iverilog() {
    if !tool_available("iverilog") {
        return;
    }
    let out = scratch("sc_regs_iverilog").join("sc_regs.vvp");
    run(Command::new("iverilog")
        .args(["-g2005", "-Wall", "-s", "sc_regs", "-o"])
        .arg(&out)
        .arg(hdl_interface_dir().join(VERILOG_REGS_PATH)));
}

/// `rtl/tb/sc_regs_tb.v` drives the committed block through every access type.
#[test]
fn register_block_testbench_passes() {
    if !tool_available("iverilog") || !tool_available("vvp") {
        return;
    }
    let rtl = hdl_interface_dir().join(VERILOG_REGS_PATH);
    let tb = rtl
        .parent()
        .expect("rtl has a directory")
        .join("tb/sc_regs_tb.v");
    let out = scratch("sc_regs_tb").join("sc_regs_tb.vvp");
    run(Command::new("iverilog")
        .args(["-g2005", "-Wall", "-I"])
        .arg(tb.parent().expect("tb has a directory"))
        .args(["-s", "sc_regs_tb", "-o"])
        .arg(&out)
        .arg(&rtl)
        .arg(&tb));
    let sim = Command::new("vvp")
        .arg("-n")
        .arg(&out)
        .output()
        .unwrap_or_else(|e| panic!("vvp: {e}"));
    let log = String::from_utf8_lossy(&sim.stdout);
    assert!(
        sim.status.success() && log.lines().any(|l| l == "PASS sc_regs_tb"),
        "sc_regs_tb failed:\n{log}{}",
        String::from_utf8_lossy(&sim.stderr)
    );
}
