//! Builds the Verilated models, each with `verilator --cc` into `OUT_DIR`, compiled with the
//! `cc` crate together with one copy of the Verilator runtime into one archive that this
//! package's library links:
//!
//! - top `sc_frontend` of `hdl-interface/rtl`, driven by the shim
//!   `hdl-interface/sim/sc_sim.cpp` (used by `src/rtl.rs`);
//! - top `sc_fabric` with the small sizes of [`FABRIC_PARAMS`], driven by
//!   `hdl-interface/sim/sc_fabric_sim.cpp` (used by `src/rtl_fabric.rs`);
//!
//! both setting `cfg(rtl_sim)`; and
//!
//! - top `sc_soc`, the SoC in the loop (`hdl-interface/soc/sc_soc.v`, its core fetched by
//!   `hdl-interface/soc/fetch_core.sh` into `OUT_DIR`, and the fabric's RTL), driven by the
//!   harness `hdl-interface/soc/sim/sc_soc_sim.cpp`, whose `sc_soc_sim_main` the binary
//!   `sc-soc-sim` runs; it sets `cfg(soc_sim)`.
//!
//! A model that cannot be had for want of a tool (no `verilator` on `PATH`, no
//! `sc_frontend.v` yet, for the SoC no python3 with venv or no network for pip on the first
//! build) is left out, `STEREOCAL_RTL_SKIP` or `STEREOCAL_SOC_SKIP` carrying the reason: the
//! tests print it loudly before passing, `sc-soc-sim` prints it and exits with status 2.
//! Under `CI=true` the build fails instead. `STEREOCAL_RTL_DIR` points the build at another
//! RTL directory.

#[path = "build/compile.rs"]
mod compile;
#[path = "build/soc.rs"]
mod soc;
#[path = "build/verilate.rs"]
mod verilate;

use std::env;
use std::fs;
use std::path::{Path, PathBuf};

use verilate::{Top, Verilator};

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

/// Where the sources are.
struct Sources {
    /// The fabric's RTL (`hdl-interface/rtl` or `STEREOCAL_RTL_DIR`).
    rtl: PathBuf,
    /// The co-simulations' shims.
    sim: PathBuf,
    /// The SoC in the loop.
    soc: PathBuf,
}

fn main() {
    println!("cargo::rustc-check-cfg=cfg(rtl_sim)");
    println!("cargo::rustc-check-cfg=cfg(soc_sim)");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=build");
    println!("cargo:rerun-if-env-changed=CI");
    println!("cargo:rerun-if-env-changed=STEREOCAL_RTL_DIR");

    let manifest = PathBuf::from(env::var("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    let root = manifest.parent().expect("workspace root").to_path_buf();
    let sources = Sources {
        rtl: env::var_os("STEREOCAL_RTL_DIR")
            .map(PathBuf::from)
            .unwrap_or_else(|| root.join("hdl-interface/rtl")),
        sim: root.join("hdl-interface/sim"),
        soc: root.join("hdl-interface/soc"),
    };
    // The RTL's own files (not the whole directory: testbenches under it do not matter), and
    // the directory while it has no sc_frontend.v yet; of the SoC, what its build reads (not
    // its README).
    println!("cargo:rerun-if-changed={}", sources.sim.display());
    if !sources.rtl.join("sc_frontend.v").exists() {
        println!("cargo:rerun-if-changed={}", sources.rtl.display());
    }
    for file in ["sc_soc.v", "sim", "fetch_core.sh"] {
        println!(
            "cargo:rerun-if-changed={}",
            sources.soc.join(file).display()
        );
    }

    let out = PathBuf::from(env::var("OUT_DIR").expect("OUT_DIR"));
    let (rtl, soc) = build(&sources, &out);
    let ci = env::var("CI").as_deref() == Ok("true");
    report(
        ci,
        "RTL co-simulation",
        "rtl_sim",
        "STEREOCAL_RTL_SKIP",
        rtl,
    );
    report(ci, "SoC in the loop", "soc_sim", "STEREOCAL_SOC_SKIP", soc);
}

/// Sets `cfg` when the model was built; otherwise fails under `CI=true` or passes the reason
/// on in `skip_env`.
fn report(ci: bool, what: &str, cfg: &str, skip_env: &str, built: Result<(), String>) {
    match built {
        Ok(()) => println!("cargo:rustc-cfg={cfg}"),
        Err(why) if ci => panic!("\n\n{what} cannot be built under CI=true: {why}\n\n"),
        Err(why) => {
            println!("cargo:warning={what} not built: {why}");
            println!("cargo:rustc-env={skip_env}={why}");
        }
    }
}

/// Verilates and compiles the models; whether the co-simulations' and the SoC's were built,
/// `Err` saying why not.
fn build(sources: &Sources, out: &Path) -> (Result<(), String>, Result<(), String>) {
    let setup = Verilator::find().and_then(|v| Ok((v, rtl_sources(&sources.rtl)?)));
    let (verilator, rtl) = match setup {
        Ok(setup) => setup,
        Err(why) => return (Err(why.clone()), Err(why)),
    };
    let vobj = out.join("vobj");
    if vobj.exists() {
        fs::remove_dir_all(&vobj).expect("clean the Verilator output directory");
    }
    fs::create_dir_all(&vobj).expect("create the Verilator output directory");

    let mut tops = vec![
        Top {
            module: "sc_frontend",
            params: &[],
            sources: rtl.clone(),
            driver: sources.sim.join("sc_sim.cpp"),
        },
        Top {
            module: "sc_fabric",
            params: &FABRIC_PARAMS,
            sources: rtl.clone(),
            driver: sources.sim.join("sc_fabric_sim.cpp"),
        },
    ];
    // Verilator runs on one core: the co-simulations' tops are verilated while the core is
    // fetched, then the SoC's.
    let mut runs: Vec<_> = tops
        .iter()
        .map(|top| verilate::spawn(top, &vobj.join(top.module)))
        .collect();
    let soc = soc::fetch_core(&sources.soc, out).map(|core| {
        let top = soc::top(&sources.soc, core, &rtl);
        runs.push(verilate::spawn(&top, &vobj.join(top.module)));
        tops.push(top);
    });
    for (top, run) in tops.iter().zip(runs) {
        verilate::wait(top, run);
    }

    let base = compile::base(&verilator);
    let mut units = compile::runtime(&base, &verilator);
    for top in &tops {
        units.extend(compile::model(&base, top, &vobj.join(top.module)));
    }
    compile::archive(units, "sc_sim");
    (Ok(()), soc)
}

/// The RTL's `.v` files, sorted; `Err` when there is no `sc_frontend.v` among them yet.
fn rtl_sources(rtl: &Path) -> Result<Vec<PathBuf>, String> {
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
    Ok(sources)
}
