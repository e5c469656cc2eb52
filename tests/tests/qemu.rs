//! The firmware ELF under QEMU against the in-process device: identical UART bytes and
//! identical estimates for synthetic and real frames, `stereocal hil`'s summary equal to
//! `eval`'s, deterministic instruction counts, the soft-core's budget per 640x480 pair, and
//! failures named (exit code, timeout).
//!
//! Needs `qemu-system-riscv32` and builds the ELF itself (see the crate docs); every test
//! takes seconds (small frames, few of them). Run: `cargo test --release -p stereocal-hil
//! qemu -- --nocapture` for the figures.

use std::time::Duration;

use stereocal::driver::Driver;
use stereocal::output::summary::{Residual, RunCost, Summary};
use stereocal::session::{tuned_fabric_config, SessionConfig, SessionError};
use stereocal_firmware::softcore::finisher::ExitCode;
use stereocal_firmware::softcore::stack::StackReport;
use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_hil::{
    assert_same_records, assert_same_stream, qemu_or_skip, real_data_or_skip, run_in_process,
    run_qemu, Scenario,
};
use stereocal_synth::{SceneKind, Sequence, SequenceConfig};
use stereocal_tools::eval::{evaluate, EvalError};
use stereocal_tools::hil::{
    instruction_reports, kernel_report, run_on_machine, run_sequence, FirmwareExit, GrabberInput,
    HilError, MachineConfig, TimeoutKind,
};

/// Runs `scenario` both ways and checks bytes and records; prints the figures.
fn compare(test: &str, qemu: &MachineConfig, scenario: &Scenario) {
    let reference = run_in_process(scenario);
    let (on_qemu, run) = run_qemu(scenario, qemu).unwrap_or_else(|e| panic!("{test}: {e}"));
    assert!(run.end.exit.is_success(), "{test}: {}", run.end.exit);
    assert_same_stream(&scenario.name, &on_qemu.bytes, &reference.bytes);
    assert_same_records(&scenario.name, &on_qemu.records, &reference.records);
    let estimated = on_qemu
        .records
        .iter()
        .filter(|r| r.status.has_estimate())
        .count();
    eprintln!(
        "{test}: {} pairs, {} UART bytes identical to in-process, {estimated} estimates equal \
         ({:?}); QEMU run {:.1} s, in-process {:.2} s",
        scenario.pairs.len(),
        on_qemu.bytes.len(),
        on_qemu
            .records
            .iter()
            .map(|r| r.raw_verge_deg)
            .collect::<Vec<_>>(),
        on_qemu.seconds,
        reference.seconds
    );
    assert!(
        estimated > 0,
        "{test}: no frame was estimated, so the equal estimates prove little"
    );
}

#[test]
fn qemu_road_sobel_rows_bytes_and_estimates_match_in_process() {
    let test = "qemu_road_sobel_rows_bytes_and_estimates_match_in_process";
    let Some(qemu) = qemu_or_skip(test) else {
        return;
    };
    let scenario = Scenario::synthetic(SceneKind::Road, 256, 192, 3, SessionConfig::default());
    compare(test, &qemu, &scenario);
}

#[test]
fn qemu_lab_sobel_patches_bytes_and_estimates_match_in_process() {
    let test = "qemu_lab_sobel_patches_bytes_and_estimates_match_in_process";
    let Some(qemu) = qemu_or_skip(test) else {
        return;
    };
    let config = SessionConfig {
        sobel_output: SobelOutput::Patches,
        ..SessionConfig::default()
    };
    let scenario = Scenario::synthetic(SceneKind::Lab, 256, 192, 3, config);
    compare(test, &qemu, &scenario);
}

#[test]
fn qemu_real_eth3d_crop_bytes_and_estimates_match_in_process() {
    let test = "qemu_real_eth3d_crop_bytes_and_estimates_match_in_process";
    let Some(qemu) = qemu_or_skip(test) else {
        return;
    };
    let Some(root) = real_data_or_skip(test) else {
        return;
    };
    // The terrace pair is 713x434; the window sits on its textured middle.
    let scenario = Scenario::real_crop(
        &root,
        "terrace",
        (200, 120),
        (256, 192),
        4,
        2,
        SessionConfig::default(),
    );
    compare(test, &qemu, &scenario);
}

/// The summary of `stereocal hil` equals `stereocal eval`'s for the same sequence, but for
/// the time per pair.
#[test]
fn qemu_hil_summary_equals_eval_summary() {
    let test = "qemu_hil_summary_equals_eval_summary";
    let Some(qemu) = qemu_or_skip(test) else {
        return;
    };
    let sequence = Sequence::builtin(
        SceneKind::Road,
        SequenceConfig {
            width: 256,
            height: 192,
            frames: 3,
            seed: 1,
            ..SequenceConfig::for_scene(SceneKind::Road)
        },
    )
    .unwrap();
    let config = SessionConfig::default();
    let summary = |records: &[_], wire_bytes_per_pair| {
        Summary::from_records(
            records,
            Residual::Keep,
            RunCost {
                ms_per_frame_pair: 0.0,
                wire_bytes_per_pair,
            },
        )
    };
    let (records, cost) = evaluate(&sequence, config, &mut |_| {}).unwrap();
    let eval = summary(&records, cost.wire_bytes_per_pair());
    let run = run_sequence(&qemu, &sequence, config, &mut |_| {})
        .unwrap_or_else(|e| panic!("{test}: {e}"));
    let (hil_records, hil_cost) = &run.device.value;
    let hil = summary(hil_records, hil_cost.wire_bytes_per_pair());
    assert_eq!(hil, eval);
    assert_eq!(
        run.wire,
        Some(Ok(())),
        "{test}: the bytes are the in-process device's"
    );
    assert!(
        run.records_identical,
        "{test}: the records are the in-process device's"
    );
    assert_eq!(hil.estimated_frames, 3, "{hil:?}");
    eprintln!("{test}: equal summaries: {hil:?}");
}

/// Instructions per pixel at the thesis' 640x240 under `-icount shift=0`: the same on every
/// run, printed for the README.
#[test]
fn qemu_instructions_per_pixel_640x240_are_deterministic() {
    let test = "qemu_instructions_per_pixel_640x240_are_deterministic";
    let Some(qemu) = qemu_or_skip(test) else {
        return;
    };
    let qemu = MachineConfig {
        count_instructions: true,
        ..qemu
    };
    let scenario = Scenario::synthetic(SceneKind::Road, 640, 240, 1, SessionConfig::default());
    let counts = || {
        let (_, run) = run_qemu(&scenario, &qemu).unwrap_or_else(|e| panic!("{test}: {e}"));
        let kernels = kernel_report(&run.logs).expect("a kernel report");
        (instruction_reports(&run.logs), kernels)
    };
    let (first, kernels) = counts();
    assert_eq!(first.len(), 2, "one report per camera: {first:?}");
    let (second, kernels_again) = counts();
    assert_eq!(kernels, kernels_again, "row-kernel counts of two runs");
    eprintln!(
        "{test}: octave-0 row kernels per pixel: Gaussian scales {:.1}, DoG {:.1}, \
         Sobel + CORDIC {:.1}",
        kernels.per_pixel(kernels.gaussian),
        kernels.per_pixel(kernels.dog),
        kernels.per_pixel(kernels.sobel_cordic)
    );
    for (a, b) in first.iter().zip(&second) {
        assert_eq!(a.driver, b.driver, "driver counts of two runs");
        // The stream engine's stand-in writes the UART, so the front end's count carries a
        // few instructions around each wait for the transmitter, and how often it is busy
        // depends on how fast the host reads: two runs differ by thousands of instructions
        // in tens of millions under a loaded CI run. 1e-3 still pins the per-pixel figure to
        // a few tenths.
        let spread = a.front_end.abs_diff(b.front_end) as f64 / a.front_end as f64;
        assert!(
            spread < 1e-3,
            "front-end counts {} and {}",
            a.front_end,
            b.front_end
        );
    }
    for r in &first {
        assert_eq!(r.pixels, 640 * 240);
        eprintln!(
            "{test}: camera {}: front end {} instructions = {:.1}/pixel, driver {} = {:.1}/pixel \
             (second run {}), UART wait {} (second run {})",
            r.camera,
            r.front_end,
            r.front_end_per_pixel(),
            r.driver,
            r.driver_per_pixel(),
            second[usize::from(r.camera)].driver,
            r.uart_wait,
            second[usize::from(r.camera)].uart_wait
        );
    }
}

/// The soft-core program's own instructions per 640x480 stereo pair (both cameras' driver
/// counts, without the fabric's software stand-in and the UART waits) fit a 100 MHz
/// single-issue core at 60 Hz: at most 1,600,000, in both Sobel modes.
fn softcore_budget(test: &str, sobel_output: SobelOutput) {
    const BUDGET: u64 = 1_600_000;
    let Some(qemu) = qemu_or_skip(test) else {
        return;
    };
    let qemu = MachineConfig {
        count_instructions: true,
        ..qemu
    };
    let config = SessionConfig {
        sobel_output,
        ..SessionConfig::default()
    };
    let scenario = Scenario::synthetic(SceneKind::Road, 640, 480, 1, config);
    let (outcome, run) = run_qemu(&scenario, &qemu).unwrap_or_else(|e| panic!("{test}: {e}"));
    assert!(
        outcome.records[0].status.has_estimate(),
        "{test}: no estimate"
    );
    let reports = instruction_reports(&run.logs);
    assert_eq!(
        reports.len(),
        2,
        "{test}: one report per camera: {reports:?}"
    );
    let per_pair: u64 = reports.iter().map(|r| r.driver).sum();
    eprintln!(
        "{test}: {per_pair} soft-core instructions per pair ({:.3} per pixel), budget {BUDGET}",
        per_pair as f64 / (2.0 * 640.0 * 480.0)
    );
    assert!(per_pair <= BUDGET, "{test}: {per_pair} > {BUDGET}");
}

#[test]
fn qemu_softcore_budget_640x480_sobel_rows() {
    softcore_budget("qemu_softcore_budget_640x480_sobel_rows", SobelOutput::Rows);
}

#[test]
fn qemu_softcore_budget_640x480_sobel_patches() {
    softcore_budget(
        "qemu_softcore_budget_640x480_sobel_patches",
        SobelOutput::Patches,
    );
}

/// A frame the firmware cannot run ends QEMU with the firmware's exit code, and the error
/// carries the firmware's decoded log.
#[test]
fn qemu_firmware_failure_reports_exit_code_and_log() {
    let test = "qemu_firmware_failure_reports_exit_code_and_log";
    let Some(qemu) = qemu_or_skip(test) else {
        return;
    };
    // 128x96 images in the frame region, registers configured for 160x120.
    let mut input = GrabberInput::new(128, 96);
    input.push_pair(&[7; 128 * 96], &[9; 128 * 96], 0).unwrap();
    let err = run_on_machine(&qemu, &input, |device| {
        let driver_error = |e| EvalError::Session(SessionError::Driver(e));
        let mut driver = Driver::new(device);
        let t = Duration::from_secs(30);
        driver.hello(t).map_err(driver_error)?;
        driver
            .configure(&tuned_fabric_config(160, 120, SobelOutput::Rows), t)
            .map_err(driver_error)?;
        driver.enable().map_err(driver_error)?;
        driver.next_pair(t).map_err(driver_error)
    })
    .expect_err("the frame cannot run");
    let HilError::Device { exit, log, .. } = &err else {
        panic!("{test}: {err}");
    };
    assert_eq!(*exit, FirmwareExit::Code(ExitCode::FrameFailed), "{err}");
    assert!(log.contains("frame failed"), "{err}");
    eprintln!("{test}: {err}");
}

/// A timeout that fires is named, and QEMU does not outlive it.
#[test]
fn qemu_answer_timeout_is_named() {
    let test = "qemu_answer_timeout_is_named";
    let Some(mut qemu) = qemu_or_skip(test) else {
        return;
    };
    qemu.timeouts.answer = Duration::from_nanos(1);
    let scenario = Scenario::synthetic(SceneKind::Road, 160, 120, 1, SessionConfig::default());
    let err = run_qemu(&scenario, &qemu).expect_err("1 ns is too short");
    assert!(
        matches!(
            err,
            HilError::Timeout {
                kind: TimeoutKind::Answer,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("the answer timeout"), "{err}");
    eprintln!("{test}: {err}");
}

/// The main loop's worst-case stack at 640x480, both Sobel output modes: the firmware paints
/// the free stack at boot and reports the deepest overwritten word after the last frame
/// (`stereocal_firmware::softcore::stack`); the mark is found and below the region. Printed
/// for the README.
#[test]
fn qemu_stack_high_water_640x480_rows_and_patches() {
    let test = "qemu_stack_high_water_640x480_rows_and_patches";
    let Some(qemu) = qemu_or_skip(test) else {
        return;
    };
    // The stack report rides on the instruction-count flag, the run that logs measurements.
    let qemu = MachineConfig {
        count_instructions: true,
        ..qemu
    };
    let mut deepest = 0;
    for (mode, sobel_output) in [
        ("rows", SobelOutput::Rows),
        ("patches", SobelOutput::Patches),
    ] {
        let config = SessionConfig {
            sobel_output,
            ..SessionConfig::default()
        };
        let scenario = Scenario::synthetic(SceneKind::Road, 640, 480, 1, config);
        let (outcome, run) =
            run_qemu(&scenario, &qemu).unwrap_or_else(|e| panic!("{test}: {mode}: {e}"));
        assert!(
            run.end.exit.is_success(),
            "{test}: {mode}: {}",
            run.end.exit
        );
        assert_eq!(outcome.records.len(), 1, "{test}: {mode}: one pair");
        let reports: Vec<StackReport> = run
            .logs
            .iter()
            .filter(|log| log.level.is_none())
            .filter_map(|log| StackReport::parse(&log.text))
            .collect();
        let [report] = reports[..] else {
            panic!("{test}: {mode}: expected one stack report, got {reports:?}");
        };
        assert!(
            report.boot > 0 && report.main_loop > 0,
            "{test}: {mode}: no overwritten word: {report:?}"
        );
        assert!(
            report.worst() < report.region,
            "{test}: {mode}: the stack reached the bottom of its region: {report:?}"
        );
        eprintln!(
            "{test}: Sobel {mode}, 640x480 pair: stack high-water mark, main loop {} bytes \
             ({:.1} KiB), boot {} bytes ({:.1} KiB), of a {} byte region",
            report.main_loop,
            f64::from(report.main_loop) / 1024.0,
            report.boot,
            f64::from(report.boot) / 1024.0,
            report.region
        );
        deepest = deepest.max(report.worst());
    }
    eprintln!("{test}: worst case over both modes: {deepest} bytes");
}
