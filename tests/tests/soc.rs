//! The firmware ELF on the SoC in the loop: the release ELF that QEMU runs, on a real
//! RV32IMAC core (VexRiscv from PyPI) with both channels' `sc_fabric` and stream engines on
//! its bus, cameras wired to them, under Verilator with the `virt` machine's RAM, UART and
//! finisher around it (`hdl-interface/soc/`), speaking to the same host driver and session.
//! `stereocal hil --soc`'s run of two 128x96 road pairs, in both Sobel modes: its link bytes
//! (the UART and both LINK_OUT ports) are the in-process device's, its records and its
//! `verge.csv` those of `stereocal eval` on the same sequence, and the board's figures are
//! there: the soft-core's cycles per pair within the budget, no FIFO overflow.
//!
//! The simulator is this package's binary `sc-soc-sim`, which `build.rs` builds (it needs
//! verilator, python3 with venv and, on the first build, network for pip); the test builds
//! the ELF itself.

use stereocal::output::record::FrameRecord;
use stereocal::output::verge_csv::write_verge_csv;
use stereocal::session::SessionConfig;
use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_hil::soc_or_skip;
use stereocal_synth::{SceneKind, Sequence, SequenceConfig};
use stereocal_tools::eval::evaluate;
use stereocal_tools::hil::run_sequence;

/// The soft-core's clock cycles for its own work per pair: a 100 MHz core at 60 pairs a
/// second (the budget `tests/tests/qemu.rs` holds QEMU's instruction counts to).
const BUDGET: u64 = 1_600_000;

fn hil_equals_eval(test: &str, sobel_output: SobelOutput) {
    let Some(soc) = soc_or_skip(test, env!("CARGO_BIN_EXE_sc-soc-sim")) else {
        return;
    };
    let sequence = Sequence::builtin(
        SceneKind::Road,
        SequenceConfig {
            width: 128,
            height: 96,
            frames: 2,
            ..SequenceConfig::for_scene(SceneKind::Road)
        },
    )
    .unwrap();
    let config = SessionConfig {
        sobel_output,
        ..SessionConfig::default()
    };
    let (eval, _) = evaluate(&sequence, config, &mut |_| {}).unwrap();
    let run = run_sequence(&soc, &sequence, config, &mut |_| {})
        .unwrap_or_else(|e| panic!("{test}: {e}"));
    assert!(
        run.device.end.exit.is_success(),
        "{test}: {}",
        run.device.end.exit
    );
    assert_eq!(run.wire, Some(Ok(())), "{test}: link bytes");
    assert!(run.records_identical, "{test}: records");
    let csv = |records: &[FrameRecord]| {
        let mut out = Vec::new();
        write_verge_csv(&mut out, records).unwrap();
        out
    };
    assert_eq!(csv(&run.device.value.0), csv(&eval), "{test}: verge.csv");

    let board = run.device.board.as_ref().expect("the SoC's board reports");
    let cycles = board.softcore_cycles_per_pair().expect("cycle reports");
    assert!(
        cycles <= BUDGET,
        "{test}: {cycles} soft-core cycles per pair"
    );
    assert_eq!(board.fifo_overflows(), 0, "{test}: FIFO overflows");
    let clocks = board.sim_clocks_per_pair().expect("timing lines");
    let latency = board.latency().expect("timing lines");
    eprintln!(
        "{test}: {} link bytes identical to in-process, verge.csv equal to eval's; soft-core \
         cycles per pair {cycles}, simulated clocks per pair {clocks}, first pixel to last \
         byte {} clocks, {:.0} clocks/s",
        run.device.end.transcript.len(),
        latency.first_pixel_to_last_byte,
        board.clocks_per_second().unwrap_or(0.0)
    );
}

#[test]
fn soc_hil_equals_eval_sobel_patches() {
    hil_equals_eval("soc_hil_equals_eval_sobel_patches", SobelOutput::Patches);
}

#[test]
fn soc_hil_equals_eval_sobel_rows() {
    hil_equals_eval("soc_hil_equals_eval_sobel_rows", SobelOutput::Rows);
}
