//! Linker setup for the soft-core ELF.
//!
//! Only the bare-metal target links through riscv-rt: there `memory.x` (the QEMU `virt` memory
//! map) goes on the linker search path and the bins get `link.x` and `defmt.x`. Host builds get
//! nothing, so `cargo build --workspace` on x86 links an ordinary program.

use std::{env, fs, path::PathBuf};

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory.x");

    if env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("none") {
        return;
    }

    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR for build scripts"));
    fs::copy("memory.x", out.join("memory.x")).expect("firmware/memory.x is readable");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
}
