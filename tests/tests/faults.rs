//! A firmware that hangs or a core that traps ends a hardware-in-the-loop run within seconds,
//! once, with an error that names what timed out or trapped and carries the firmware's log,
//! under QEMU and on the SoC in the loop.
//!
//! The faults are made by patching a copy of the release ELF: the first instruction of a
//! function the first frame runs once the host has configured the device becomes `j .` (a
//! hang) or `ecall` (an exception: VexRiscv does not trap on every illegal encoding, every
//! core traps on `ecall`). Under QEMU the function is `FrameInput::image`, which the main
//! loop calls for each image; on the SoC, where the main loop inlines that call, it is
//! `WiredFabric::idle`, the driver's wait for the fabric to finish a frame. Every run has
//! four pairs: a runner that waited once per remaining frame would take four times its
//! timeout.

use std::path::Path;
use std::time::{Duration, Instant};

use object::{Object, ObjectSection, ObjectSymbol};
use stereocal::session::SessionConfig;
use stereocal_firmware::softcore::finisher::ExitCode;
use stereocal_hil::{qemu_or_skip, run_qemu, soc_or_skip, Scenario};
use stereocal_synth::SceneKind;
use stereocal_tools::hil::{FirmwareExit, HilError, MachineConfig, MachineTimeouts, TimeoutKind};

/// `jal x0, 0`: jumps to itself.
const HANG: u32 = 0x0000_006f;
/// `ecall`: an environment call from M-mode, exception code 11.
const ECALL: u32 = 0x0000_0073;

/// The patched function's mangled name: QEMU's or the SoC's (see the module docs).
fn target(config: &MachineConfig) -> &'static str {
    if config.soc.is_some() {
        "WiredFabric"
    } else {
        "10FrameInput5image"
    }
}

/// A copy of `elf` whose function named by `part` (and, for `WiredFabric`, its `idle`)
/// starts with `word`.
fn patched(elf: &Path, part: &str, word: u32) -> tempfile::NamedTempFile {
    let mut bytes = std::fs::read(elf).unwrap();
    let offset = {
        let file = object::File::parse(&*bytes).unwrap();
        let symbol = file
            .symbols()
            .find(|s| {
                s.name().is_ok_and(|n| {
                    n.contains(part) && (!part.contains("Wired") || n.contains("4idle"))
                })
            })
            .unwrap_or_else(|| panic!("the ELF has no function named like {part}"));
        let section = file
            .section_by_index(symbol.section_index().unwrap())
            .unwrap();
        let (start, _) = section.file_range().unwrap();
        usize::try_from(start + symbol.address() - section.address()).unwrap()
    };
    bytes[offset..offset + 4].copy_from_slice(&word.to_le_bytes());
    let file = tempfile::NamedTempFile::new().unwrap();
    std::fs::write(file.path(), &bytes).unwrap();
    file
}

/// Runs four 128x96 pairs on `config` with `word` patched in; the error and the wall time.
fn run_faulty(config: &MachineConfig, word: u32) -> (HilError, Duration) {
    let elf = patched(&config.elf, target(config), word);
    let config = MachineConfig {
        elf: elf.path().to_path_buf(),
        ..config.clone()
    };
    let scenario = Scenario::synthetic(SceneKind::Road, 128, 96, 4, SessionConfig::default());
    let start = Instant::now();
    let err = run_qemu(&scenario, &config).expect_err("the patched firmware cannot succeed");
    (err, start.elapsed())
}

fn assert_trap_named(test: &str, err: &HilError, took: Duration) {
    match err {
        HilError::Device { exit, log, .. } => {
            assert_eq!(*exit, FirmwareExit::Code(ExitCode::Trap), "{test}: {err}");
            assert!(log.contains("trap: mcause 0xb"), "{test}: {err}");
        }
        other => panic!("{test}: not the trap's error: {other}"),
    }
    assert!(
        err.to_string().contains("the core trapped"),
        "{test}: {err}"
    );
    assert!(took < Duration::from_secs(60), "{test}: took {took:?}");
    eprintln!("{test}: {took:.1?}: {err}");
}

#[test]
fn qemu_hung_firmware_ends_the_run_once_on_its_silence() {
    let test = "qemu_hung_firmware_ends_the_run_once_on_its_silence";
    let Some(mut qemu) = qemu_or_skip(test) else {
        return;
    };
    qemu.timeouts.silence = Duration::from_secs(3);
    let (err, took) = run_faulty(&qemu, HANG);
    assert!(
        matches!(
            err,
            HilError::Timeout {
                kind: TimeoutKind::Silence,
                ..
            }
        ),
        "{test}: {err}"
    );
    assert!(
        err.to_string().contains("silence timeout (3s)"),
        "{test}: {err}"
    );
    // One silence timeout and the machine's shutdown, not one per remaining pair.
    assert!(took < Duration::from_secs(9), "{test}: took {took:?}");
    eprintln!("{test}: {took:.1?}: {err}");
}

#[test]
fn qemu_trap_ends_the_run_at_once_with_the_cause() {
    let test = "qemu_trap_ends_the_run_at_once_with_the_cause";
    let Some(qemu) = qemu_or_skip(test) else {
        return;
    };
    let (err, took) = run_faulty(&qemu, ECALL);
    assert_trap_named(test, &err, took);
}

#[test]
fn soc_hung_firmware_is_ended_by_the_board_watchdog() {
    let test = "soc_hung_firmware_is_ended_by_the_board_watchdog";
    let Some(soc) = soc_or_skip(test, env!("CARGO_BIN_EXE_sc-soc-sim")) else {
        return;
    };
    assert_eq!(
        soc.timeouts,
        MachineTimeouts::soc(),
        "{test}: the board's watchdog must be first"
    );
    let (err, took) = run_faulty(&soc, HANG);
    match &err {
        HilError::Device { exit, stderr, .. } => {
            assert_eq!(*exit, FirmwareExit::Other(124), "{test}: {err}");
            assert!(stderr.contains("watchdog: nothing moved"), "{test}: {err}");
        }
        other => panic!("{test}: not the watchdog's error: {other}"),
    }
    // The watchdog's 419,840 simulated clocks (twenty 640-pixel line times at the board's
    // pixel clock) at some 100,000 a second, and the board's start.
    assert!(took < Duration::from_secs(60), "{test}: took {took:?}");
    eprintln!("{test}: {took:.1?}: {err}");
}

#[test]
fn soc_trap_ends_the_run_at_once_with_the_cause() {
    let test = "soc_trap_ends_the_run_at_once_with_the_cause";
    let Some(soc) = soc_or_skip(test, env!("CARGO_BIN_EXE_sc-soc-sim")) else {
        return;
    };
    let (err, took) = run_faulty(&soc, ECALL);
    assert_trap_named(test, &err, took);
}
