//! Builds the RTL co-simulation models: `verilator --cc` on `hdl-interface/rtl/*.v` twice
//! into `OUT_DIR`, top `sc_frontend` (wrapped by the shim `hdl-interface/sim/sc_sim.cpp`,
//! used by `src/rtl.rs`) and top `sc_fabric` with the small sizes of [`FABRIC_PARAMS`]
//! (wrapped by `hdl-interface/sim/sc_fabric_sim.cpp`, used by `src/rtl_fabric.rs`), then the
//! generated C++, the Verilator runtime and the shims compiled and linked with the `cc`
//! crate. On success it sets `cfg(rtl_sim)`.
//!
//! Without `verilator` on `PATH` (or before `sc_frontend.v` exists) the model is not built and
//! `STEREOCAL_RTL_SKIP` carries the reason, which the rtl tests print loudly before passing;
//! under `CI=true` the build fails instead. `STEREOCAL_RTL_DIR` points the build at another
//! RTL directory.

use std::env;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

/// `sc_fabric`'s parameters in the contract co-simulation: line memories of 64 pixels and
/// FIFOs of 8 points and 3 x 64 Sobel pixels, so that small frames fill both FIFOs and the
/// model stays small to compile. `src/rtl_fabric.rs` builds the device model with the same
/// sizes and checks them against the shim's `sc_fabric_sim_params`.
const FABRIC_PARAMS: [(&str, u32); 6] = [
    ("W0", 64),
    ("W1", 32),
    ("W2", 16),
    ("W3", 12),
    ("POINT_DEPTH", 8),
    ("SOBEL_DEPTH", 192),
];

/// One Verilated top and the shim around it.
struct Top {
    module: &'static str,
    params: &'static [(&'static str, u32)],
    shim: &'static str,
}

const TOPS: [Top; 2] = [
    Top {
        module: "sc_frontend",
        params: &[],
        shim: "sc_sim.cpp",
    },
    Top {
        module: "sc_fabric",
        params: &FABRIC_PARAMS,
        shim: "sc_fabric_sim.cpp",
    },
];

fn main() {
    println!("cargo::rustc-check-cfg=cfg(rtl_sim)");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=CI");
    println!("cargo:rerun-if-env-changed=STEREOCAL_RTL_DIR");

    let manifest = PathBuf::from(env::var("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    let root = manifest.parent().expect("workspace root").to_path_buf();
    let rtl = env::var_os("STEREOCAL_RTL_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("hdl-interface/rtl"));
    let sim = root.join("hdl-interface/sim");
    // The RTL's own files (not the whole directory: testbenches under it do not matter), and
    // the directory while it has no sc_frontend.v yet.
    println!("cargo:rerun-if-changed={}", sim.display());
    if !rtl.join("sc_frontend.v").exists() {
        println!("cargo:rerun-if-changed={}", rtl.display());
    }
    let ci = env::var("CI").as_deref() == Ok("true");

    if let Err(why) = build(&rtl, &sim) {
        if ci {
            panic!("\n\nRTL co-simulation cannot be built under CI=true: {why}\n\n");
        }
        println!("cargo:warning=RTL co-simulation not built: {why}");
        println!("cargo:rustc-env=STEREOCAL_RTL_SKIP={why}");
    }
}

/// Runs Verilator and the C++ compiler; `Err` says why the model is unavailable. A Verilator
/// or compiler error in present sources panics (that is a broken RTL, not a missing tool).
fn build(rtl: &Path, sim: &Path) -> Result<(), String> {
    let verilator = Command::new("verilator").arg("--version").output();
    match verilator {
        Ok(o) if o.status.success() => {}
        _ => {
            return Err("`verilator` not found on PATH (Debian: apt-get install verilator)".into())
        }
    }
    let mut sources: Vec<PathBuf> = fs::read_dir(rtl)
        .map_err(|e| format!("cannot read {}: {e}", rtl.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "v"))
        .collect();
    sources.sort();
    for s in &sources {
        println!("cargo:rerun-if-changed={}", s.display());
    }
    if !sources.iter().any(|p| p.ends_with("sc_frontend.v")) {
        return Err(format!("{} has no sc_frontend.v", rtl.display()));
    }

    let out = PathBuf::from(env::var("OUT_DIR").expect("OUT_DIR"));
    let vobj = out.join("vobj");
    if vobj.exists() {
        fs::remove_dir_all(&vobj).expect("clean the Verilator output directory");
    }
    fs::create_dir_all(&vobj).expect("create the Verilator output directory");
    // Both tops at once (Verilator runs on one core).
    let runs: Vec<_> = TOPS
        .iter()
        .map(|top| {
            let mdir = vobj.join(top.module);
            let child = Command::new("verilator")
                .args([
                    "--cc",
                    "-O3",
                    "--x-assign",
                    "fast",
                    "--x-initial",
                    "unique",
                    "--noassert",
                ])
                .args(["-Wno-fatal", "-Wno-lint", "-Wno-style"])
                .args(["--top-module", top.module, "--prefix"])
                .arg(format!("V{}", top.module))
                .args(
                    top.params
                        .iter()
                        .map(|(name, value)| format!("-G{name}={value}")),
                )
                .arg("--Mdir")
                .arg(&mdir)
                .args(&sources)
                .spawn()
                .map_err(|e| format!("running verilator: {e}"))?;
            Ok((top, mdir, child))
        })
        .collect::<Result<_, String>>()?;
    let mut mdirs = Vec::new();
    for (top, mdir, mut child) in runs {
        let status = child
            .wait()
            .map_err(|e| format!("running verilator: {e}"))?;
        assert!(
            status.success(),
            "verilator --cc (top {}) failed on {} (see its messages above)",
            top.module,
            rtl.display()
        );
        mdirs.push((top, mdir));
    }

    let root = Command::new("verilator")
        .args(["--getenv", "VERILATOR_ROOT"])
        .output()
        .map_err(|e| format!("verilator --getenv VERILATOR_ROOT: {e}"))?;
    let vroot = PathBuf::from(String::from_utf8_lossy(&root.stdout).trim());
    let include = vroot.join("include");
    if !include.join("verilated.cpp").exists() {
        return Err(format!("no verilated.cpp under {}", include.display()));
    }

    // Every translation unit on its own, NUM_JOBS at a time: the model's code at -O2, the
    // run-once construction code (`*__Slow.cpp`) at -O0, the Verilator runtime at -O1.
    let mut base = cc::Build::new();
    base.cpp(true)
        .std("c++17")
        .warnings(false)
        .debug(false)
        .cargo_metadata(false)
        .include(&include)
        .include(include.join("vltstd"))
        .include(sim)
        .define("VM_COVERAGE", "0")
        .define("VM_SC", "0")
        .define("VM_TRACE", "0")
        .define("VM_TRACE_FST", "0")
        .define("VM_TRACE_VCD", "0")
        .flag("-faligned-new");
    // Each unit with its optimization level and the build that compiles it (a top's own
    // include directory and, for a shim, the top's parameters as SC_<MODULE>_<NAME> macros).
    let mut units: Vec<(PathBuf, u32, cc::Build)> = vec![
        (include.join("verilated.cpp"), 1, base.clone()),
        (include.join("verilated_threads.cpp"), 1, base.clone()),
    ];
    for (top, mdir) in &mdirs {
        let mut build = base.clone();
        build.include(mdir);
        let mut generated: Vec<PathBuf> = fs::read_dir(mdir)
            .expect("Verilator output directory")
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "cpp"))
            .collect();
        generated.sort();
        for p in generated {
            let slow = p.to_string_lossy().ends_with("__Slow.cpp");
            units.push((p, if slow { 0 } else { 2 }, build.clone()));
        }
        let prefix = top.module.to_uppercase();
        for (name, value) in top.params {
            build.define(&format!("{prefix}_{name}"), value.to_string().as_str());
        }
        units.push((sim.join(top.shim), 2, build));
    }
    // Largest first, so the long ones do not end up last on one core.
    units.sort_by_key(|(p, ..)| std::cmp::Reverse(fs::metadata(p).map_or(0, |m| m.len())));
    let jobs = env::var("NUM_JOBS")
        .ok()
        .and_then(|j| j.parse::<usize>().ok())
        .unwrap_or(2)
        .clamp(1, 16);
    let queue = std::sync::Mutex::new(units.into_iter());
    let objects: Vec<PathBuf> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..jobs)
            .map(|_| {
                s.spawn(|| {
                    let mut objs = Vec::new();
                    loop {
                        let next = queue.lock().expect("queue").next();
                        let Some((file, opt, build)) = next else {
                            break objs;
                        };
                        objs.extend(
                            build
                                .clone()
                                .opt_level(opt)
                                .file(&file)
                                .compile_intermediates(),
                        );
                    }
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().expect("C++ compile worker"))
            .collect()
    });
    cc::Build::new()
        .cpp(true)
        .objects(&objects)
        .compile("sc_sim");
    println!("cargo:rustc-link-lib=pthread");
    println!("cargo:rustc-cfg=rtl_sim");
    Ok(())
}
