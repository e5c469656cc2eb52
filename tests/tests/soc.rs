//! The firmware ELF on the SoC in the loop: the release ELF that QEMU runs, on a real
//! RV32IMAC core (VexRiscv from PyPI) with both channels' `sc_fabric` and stream engines on
//! its bus, cameras wired to them, under Verilator with the `virt` machine's RAM, UART and
//! finisher around it (`hdl-interface/soc/`), speaking to the same host driver and session.
//! The bytes on its link (the UART and both LINK_OUT ports) must be the in-process device's,
//! as QEMU's are (`tests/tests/qemu.rs`), and its records equal to the bit.
//!
//! The simulator is this package's binary `sc-soc-sim`, which `build.rs` builds (it needs
//! verilator, python3 with venv and, on the first build, network for pip); the test builds
//! the ELF itself.

use stereocal::session::SessionConfig;
use stereocal_hil::{
    assert_same_records, assert_same_stream, run_in_process, run_qemu, soc_or_skip, Scenario,
};
use stereocal_synth::SceneKind;

#[test]
fn soc_runs_the_release_elf_and_sends_the_in_process_bytes() {
    let test = "soc_runs_the_release_elf_and_sends_the_in_process_bytes";
    let Some(soc) = soc_or_skip(test, env!("CARGO_BIN_EXE_sc-soc-sim")) else {
        return;
    };
    let scenario = Scenario::synthetic(SceneKind::Road, 128, 96, 2, SessionConfig::default());
    let reference = run_in_process(&scenario);
    let (on_soc, run) = run_qemu(&scenario, &soc).unwrap_or_else(|e| panic!("{test}: {e}"));
    assert!(run.end.exit.is_success(), "{test}: {}", run.end.exit);
    assert_same_stream(&scenario.name, &on_soc.bytes, &reference.bytes);
    assert_same_records(&scenario.name, &on_soc.records, &reference.records);
    eprintln!(
        "{test}: {} UART bytes identical to in-process; SoC run {:.1} s ({})",
        on_soc.bytes.len(),
        on_soc.seconds,
        run.end.stderr.trim()
    );
}
