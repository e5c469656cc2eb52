//! The C++ of the Verilated models: every translation unit compiled on its own with its own
//! optimisation level, `NUM_JOBS` at a time, into one static archive.

use std::env;
use std::fs;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::verilate::{Top, Verilator};

/// One translation unit: the file, its optimisation level, and the build that carries its
/// include directories and defines.
pub struct Unit {
    file: PathBuf,
    opt: u32,
    build: cc::Build,
}

/// The flags every unit shares: those Verilator's own makefiles use, C++17, no warnings (the
/// generated code is not ours) and no debug information. The optimisation levels are set
/// per unit and do not follow the Cargo profile: a debug build's tests clock the models as
/// long as a release build's do.
pub fn base(verilator: &Verilator) -> cc::Build {
    let mut base = cc::Build::new();
    base.cpp(true)
        .std("c++17")
        .warnings(false)
        .debug(false)
        .cargo_metadata(false)
        .include(&verilator.include)
        .include(verilator.include.join("vltstd"))
        .define("VM_COVERAGE", "0")
        .define("VM_SC", "0")
        .define("VM_TRACE", "0")
        .define("VM_TRACE_FST", "0")
        .define("VM_TRACE_VCD", "0")
        .flag("-faligned-new");
    base
}

/// The Verilator runtime, once for all the models, at -O1 (it is not on the clocked path).
pub fn runtime(base: &cc::Build, verilator: &Verilator) -> Vec<Unit> {
    ["verilated.cpp", "verilated_threads.cpp"]
        .into_iter()
        .map(|name| Unit {
            file: verilator.include.join(name),
            opt: 1,
            build: base.clone(),
        })
        .collect()
}

/// `top`'s generated C++ in `mdir` and its driver: the model's code at -O2, its run-once
/// construction code (`*__Slow.cpp`) at -O0, the driver at -O2 with the top's parameters as
/// `<MODULE>_<NAME>` macros (a shim checks its sizes against them).
pub fn model(base: &cc::Build, top: &Top, mdir: &Path) -> Vec<Unit> {
    let mut build = base.clone();
    build.include(mdir);
    let mut generated: Vec<PathBuf> = fs::read_dir(mdir)
        .expect("Verilator output directory")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "cpp"))
        .collect();
    generated.sort();
    let mut units: Vec<Unit> = generated
        .into_iter()
        .map(|file| {
            let slow = file.to_string_lossy().ends_with("__Slow.cpp");
            Unit {
                file,
                opt: if slow { 0 } else { 2 },
                build: build.clone(),
            }
        })
        .collect();
    let prefix = top.module.to_uppercase();
    for (name, value) in top.params {
        build.define(&format!("{prefix}_{name}"), value.to_string().as_str());
    }
    units.push(Unit {
        file: top.driver.clone(),
        opt: 2,
        build,
    });
    units
}

/// Compiles `units`, `NUM_JOBS` (Cargo's `-j`) at a time and largest first, so that the long
/// ones do not end up last on one core; then archives the objects as `lib<name>.a` and has
/// Cargo link it (with the C++ library) into this package's library. The scheduling is ours
/// rather than `cc`'s `parallel` feature: that compiles the files of one `cc::Build`, all
/// with the same flags, in parallel, while the units here differ in optimisation level and
/// include directories and would run as a sequence of groups, each ending on one core.
pub fn archive(mut units: Vec<Unit>, name: &str) {
    units.sort_by_key(|u| std::cmp::Reverse(fs::metadata(&u.file).map_or(0, |m| m.len())));
    let jobs = env::var("NUM_JOBS")
        .ok()
        .and_then(|j| j.parse::<usize>().ok())
        .unwrap_or(2)
        .clamp(1, 16);
    let queue = Mutex::new(units.into_iter());
    let objects: Vec<PathBuf> = std::thread::scope(|s| {
        let workers: Vec<_> = (0..jobs)
            .map(|_| {
                s.spawn(|| {
                    let mut objects = Vec::new();
                    loop {
                        let next = queue.lock().expect("queue").next();
                        let Some(unit) = next else {
                            break objects;
                        };
                        objects.extend(
                            unit.build
                                .clone()
                                .opt_level(unit.opt)
                                .file(&unit.file)
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
    cc::Build::new().cpp(true).objects(&objects).compile(name);
    println!("cargo:rustc-link-lib=pthread");
}
