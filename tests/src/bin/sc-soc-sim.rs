//! The SoC in the loop as a program: the firmware ELF on a real RV32IMAC core (VexRiscv) and
//! both channels' `sc_fabric` under Verilator, with the `virt` machine's RAM, UART and
//! finisher around it (`hdl-interface/soc`). `stereocal hil --soc` and the `soc` test start
//! it in place of QEMU. Its options are the harness's, in the header of
//! `hdl-interface/soc/sim/sc_soc_sim.cpp`; `build.rs` Verilates the model and compiles the
//! harness into this package's native archive, and `main` hands the arguments to the
//! harness's `sc_soc_sim_main`.
//!
//! Built where the model could not be (no `verilator`, no python3 with venv or no network
//! for the core's first fetch), the binary says why on stderr and exits with status 64, the
//! harness's status for a board that cannot run (no firmware exit code is 64).

#[cfg(soc_sim)]
use std::ffi::{c_char, c_int, CString};
#[cfg(soc_sim)]
use std::os::unix::ffi::OsStringExt;

// The model and the harness are in the native archive of this package's library: using the
// library links it.
#[cfg(soc_sim)]
use stereocal_hil as _;

#[cfg(soc_sim)]
extern "C" {
    /// The harness's `main`: parses `argv` (`argv[argc]` null), runs the SoC and returns
    /// the exit status (0 when the firmware finished with success).
    fn sc_soc_sim_main(argc: c_int, argv: *mut *mut c_char) -> c_int;
}

#[cfg(soc_sim)]
fn main() {
    // The strings are the harness's for the rest of the process, as C's `main` gets them.
    let mut argv: Vec<*mut c_char> = std::env::args_os()
        .map(|a| CString::new(a.into_vec()).expect("an OS argument holds no NUL"))
        .map(CString::into_raw)
        .collect();
    let argc = c_int::try_from(argv.len()).expect("argument count fits a C int");
    argv.push(std::ptr::null_mut());
    // SAFETY: `argv` holds `argc` NUL-terminated strings, then a null pointer, as C's `main`
    // gets them, and lives until the call returns.
    let status = unsafe { sc_soc_sim_main(argc, argv.as_mut_ptr()) };
    std::process::exit(status);
}

#[cfg(not(soc_sim))]
fn main() {
    eprintln!(
        "sc-soc-sim: this build has no SoC model: {}\n\
         sc-soc-sim: install what is missing, then rebuild it with `touch tests/build.rs && \
         cargo build --release -p stereocal-hil --bin sc-soc-sim` (the core's first fetch \
         needs python3 with venv and network for pip)",
        env!("STEREOCAL_SOC_SKIP")
    );
    std::process::exit(64);
}
