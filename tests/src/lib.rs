//! Hardware-in-the-loop harness: the same frames and configuration through the in-process
//! device and through the firmware ELF under `qemu-system-riscv32`, with the UART bytes and
//! the host's estimates side by side.
//!
//! - **The emulator**: `qemu-system-riscv32` on `PATH` (Debian: `qemu-system-misc`). Without
//!   it a test prints a loud `SKIPPED` line and passes, except under `CI=true`, where it
//!   fails.
//! - **The ELF**: every test binary first runs `cargo build --release -p stereocal-firmware
//!   --target riscv32imc-unknown-none-elf` once (a no-op when it is up to date, so the ELF
//!   never lags behind the in-process model it is compared with) and uses
//!   `target/riscv32imc-unknown-none-elf/release/stereocal-firmware` (`CARGO_TARGET_DIR` is
//!   honoured). A toolchain without that target gets it from `rustup target add`; where that
//!   cannot be done (no rustup, no network, a release the registry does not serve the target
//!   for) the tests that need the ELF skip loudly, and fail under `CI=true`.
//!   `STEREOCAL_FIRMWARE_ELF` names another ELF and skips the build.
//!
//! The comparison ([`assert_same_stream`]): the firmware answers the host's `Hello` with the
//! `LOG` capability added (it has a defmt logger; the in-process device does not). Every
//! byte after that first link frame must be identical: register answers, every frame's
//! packets, their sequence numbers and CRCs.
//!
//! The RTL co-simulations (Verilated by `build.rs`; without Verilator they skip loudly):
//! [`rtl`] clocks `sc_frontend` beside the register-level model and compares every
//! observation port; [`fabric_contract`] clocks the whole `sc_fabric` ([`rtl_fabric`]) beside
//! the device model's clock-exact entry point and compares every word read over the bus.
//!
//! The SoC in the loop (the binary `sc-soc-sim`, whose model `build.rs` builds beside the
//! co-simulations' and leaves out, with a reason, where a tool is missing): [`soc_or_skip`]
//! runs the ELF on it in place of QEMU.

pub mod fabric_contract;
pub mod rng;
pub mod rtl;
pub mod rtl_fabric;
pub mod stream_cosim;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::Instant;

use stereocal::calib::Calibration;
use stereocal::link::{FrameInput, InProcessLink, Link, Recording};
use stereocal::output::record::FrameRecord;
use stereocal::session::{Session, SessionConfig, SessionError};
use stereocal_synth::{SceneKind, Sequence, SequenceConfig};
use stereocal_tools::eval::{fabric_size, sequence_calibration};
use stereocal_tools::hil::{
    compare_streams, run_on_machine, HilError, MachineConfig, MachineRun, MachineTimeouts,
    DEFAULT_QEMU,
};

/// One stereo pair.
#[derive(Debug, Clone)]
pub struct Pair {
    /// Capture time.
    pub timestamp_us: u64,
    /// Left image, raster order.
    pub left: Vec<u8>,
    /// Right image, raster order.
    pub right: Vec<u8>,
}

/// Frames, calibration and host configuration of one comparison.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// For messages.
    pub name: String,
    /// The head's calibration.
    pub calib: Calibration,
    /// Image width.
    pub width: u16,
    /// Image height.
    pub height: u16,
    /// Host settings (estimator, Kalman, Sobel output mode).
    pub config: SessionConfig,
    /// The pairs, in order.
    pub pairs: Vec<Pair>,
}

impl Scenario {
    /// `frames` pairs of a built-in scene rendered at `width` x `height`.
    pub fn synthetic(
        scene: SceneKind,
        width: u32,
        height: u32,
        frames: usize,
        config: SessionConfig,
    ) -> Self {
        let sequence = Sequence::builtin(
            scene,
            SequenceConfig {
                width,
                height,
                frames,
                ..SequenceConfig::for_scene(scene)
            },
        )
        .expect("built-in scene");
        let (width, height) = fabric_size(&sequence).expect("image size fits the registers");
        let pairs = (0..frames)
            .map(|i| {
                let frame = sequence.frame(i).expect("rendering");
                let images = frame.images.expect("the scenes drop no frames by default");
                Pair {
                    timestamp_us: frame.timestamp_us,
                    left: images.left.into_raw(),
                    right: images.right.into_raw(),
                }
            })
            .collect();
        Self {
            name: format!("{scene} {width}x{height}"),
            calib: sequence_calibration(&sequence).expect("synthetic calibration"),
            width,
            height,
            config,
            pairs,
        }
    }

    /// Runs the pairs on `device` through a host session; the records, one per pair.
    pub fn run_session<D: Link + FrameInput>(
        &self,
        device: D,
    ) -> Result<Vec<FrameRecord>, SessionError> {
        let mut session =
            Session::with_device(device, self.calib, self.width, self.height, self.config)?;
        let size = (usize::from(self.width), usize::from(self.height));
        self.pairs
            .iter()
            .enumerate()
            .map(|(i, p)| session.process(i, Some((&p.left, &p.right)), size, p.timestamp_us, None))
            .collect()
    }

    /// The frames as the soft-core's frame-grabber input.
    pub fn grabber_input(&self) -> stereocal_tools::hil::GrabberInput {
        let mut input = stereocal_tools::hil::GrabberInput::new(self.width, self.height);
        for p in &self.pairs {
            input
                .push_pair(&p.left, &p.right, p.timestamp_us)
                .expect("the scenario fits the frame region");
        }
        input
    }
}

/// What a run gave: the host's records and every byte the device sent.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// One record per pair.
    pub records: Vec<FrameRecord>,
    /// Device-to-host bytes.
    pub bytes: Vec<u8>,
    /// Wall time of the run.
    pub seconds: f64,
}

/// The scenario on the in-process device (the fabric model's fast path, in this process).
pub fn run_in_process(scenario: &Scenario) -> Outcome {
    let start = Instant::now();
    let mut device = Recording::new(InProcessLink::new().expect("in-process device"));
    let records = scenario
        .run_session(&mut device)
        .unwrap_or_else(|e| panic!("{}: in-process run: {e}", scenario.name));
    Outcome {
        records,
        bytes: device.take_received(),
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// The scenario on the firmware under QEMU.
pub fn run_qemu(
    scenario: &Scenario,
    qemu: &MachineConfig,
) -> Result<(Outcome, MachineRun<Vec<FrameRecord>>), HilError> {
    let start = Instant::now();
    let run = run_on_machine(qemu, &scenario.grabber_input(), |device| {
        Ok(scenario.run_session(device)?)
    })?;
    let outcome = Outcome {
        records: run.value.clone(),
        bytes: run.end.transcript.clone(),
        seconds: start.elapsed().as_secs_f64(),
    };
    Ok((outcome, run))
}

/// Asserts that the firmware's UART bytes are the in-process device's bytes: the same
/// `Hello` but for the `LOG` capability, then every byte the same ([`compare_streams`]).
pub fn assert_same_stream(name: &str, device: &[u8], in_process: &[u8]) {
    if let Err(e) = compare_streams(device, in_process) {
        panic!("{name}: {e}");
    }
}

/// Whether the runs gave the same records, field by field (floats exactly).
pub fn assert_same_records(name: &str, qemu: &[FrameRecord], in_process: &[FrameRecord]) {
    assert_eq!(qemu.len(), in_process.len(), "{name}: record count");
    for (q, i) in qemu.iter().zip(in_process) {
        assert_eq!(q, i, "{name}: frame {} differs", i.frame);
    }
}

/// The QEMU configuration for the tests, or `None` (after a loud `SKIPPED` line) when the
/// emulator is not installed. Under `CI=true` a missing emulator is a failure.
pub fn qemu_or_skip(test: &str) -> Option<MachineConfig> {
    let found = Command::new(DEFAULT_QEMU)
        .arg("--version")
        .output()
        .is_ok_and(|out| out.status.success());
    if !found {
        skip(
            test,
            &format!(
                "{DEFAULT_QEMU} not found on PATH (Debian/Ubuntu: apt-get install qemu-system-misc)"
            ),
        );
        return None;
    }
    firmware_elf_or_skip(test).map(MachineConfig::new)
}

/// Why `build.rs` left the SoC model out of the binary `sc-soc-sim` (`None` when it is in).
pub const SOC_SKIP: Option<&str> = option_env!("STEREOCAL_SOC_SKIP");

/// The firmware ELF on the SoC in the loop ([`MachineConfig::soc`]) run by `sim`, this package's
/// binary `sc-soc-sim` (a test passes `env!("CARGO_BIN_EXE_sc-soc-sim")`: Cargo tells its
/// path to integration tests only), or `None` after a loud `SKIPPED` line when the binary
/// has no model ([`SOC_SKIP`]). Under `CI=true` the build has failed instead.
pub fn soc_or_skip(test: &str, sim: impl Into<PathBuf>) -> Option<MachineConfig> {
    if let Some(why) = SOC_SKIP {
        skip(test, &format!("sc-soc-sim has no SoC model: {why}"));
        return None;
    }
    firmware_elf_or_skip(test).map(|elf| MachineConfig {
        soc: Some(sim.into()),
        timeouts: MachineTimeouts::soc(),
        ..MachineConfig::new(elf)
    })
}

/// The soft-core's Rust target: the firmware ELF is built for it.
pub const FIRMWARE_TARGET: &str = "riscv32imc-unknown-none-elf";

/// The firmware ELF, built once per test binary (see the crate docs), or `None` after a loud
/// `SKIPPED` line naming [`FIRMWARE_TARGET`] when the toolchain lacks that target and
/// `rustup target add` cannot install it. Under `CI=true` a missing target is a failure. A
/// target that is present but fails to build the firmware is always a failure.
pub fn firmware_elf_or_skip(test: &str) -> Option<PathBuf> {
    static ELF: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    match ELF.get_or_init(build_firmware_elf) {
        Ok(elf) => Some(elf.clone()),
        Err(reason) => {
            skip(test, reason);
            None
        }
    }
}

/// `Err` says why the target cannot be had; a failed build of a present target panics.
fn build_firmware_elf() -> Result<PathBuf, String> {
    if let Some(elf) = std::env::var_os("STEREOCAL_FIRMWARE_ELF") {
        return Ok(PathBuf::from(elf));
    }
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the workspace");
    ensure_firmware_target(workspace)?;
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let status = Command::new(cargo)
        .current_dir(workspace)
        .args(["build", "--release", "-p", "stereocal-firmware"])
        .args(["--target", FIRMWARE_TARGET])
        .status()
        .expect("cannot run cargo to build the firmware ELF");
    assert!(
        status.success(),
        "building the firmware ELF for {FIRMWARE_TARGET} failed (the target is installed, \
         so this is the firmware's own error, printed above)"
    );
    Ok(std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace.join("target"))
        .join(FIRMWARE_TARGET)
        .join("release/stereocal-firmware"))
}

/// Makes sure the toolchain that builds the workspace has [`FIRMWARE_TARGET`]'s standard
/// library, adding it with `rustup target add` when it is missing: rustup installs a
/// toolchain file's targets by itself only when its auto-install is on, and many machines
/// turn that off. `Err` names the target, the compiler and what the attempt said.
fn ensure_firmware_target(workspace: &Path) -> Result<(), String> {
    let rustc = std::env::var_os("RUSTC").unwrap_or_else(|| "rustc".into());
    let installed = || {
        Command::new(&rustc)
            .current_dir(workspace)
            .args(["--print", "target-libdir", "--target", FIRMWARE_TARGET])
            .output()
            .ok()
            .filter(|out| out.status.success())
            .map(|out| PathBuf::from(String::from_utf8_lossy(&out.stdout).trim()))
            .and_then(|libdir| std::fs::read_dir(libdir).ok())
            .is_some_and(|mut entries| {
                entries.any(|e| {
                    e.is_ok_and(|e| e.file_name().to_string_lossy().starts_with("libcore-"))
                })
            })
    };
    if installed() {
        return Ok(());
    }
    let version = Command::new(&rustc)
        .arg("--version")
        .output()
        .map(|out| String::from_utf8_lossy(&out.stdout).trim().to_string())
        .unwrap_or_else(|e| format!("rustc ({e})"));
    {
        use std::io::Write;
        // Past the harness's capture, like `skip`: a download is worth a line. A closed
        // stderr has nobody to tell.
        let _ = writeln!(
            std::io::stderr(),
            "{FIRMWARE_TARGET} is missing from {version}: running `rustup target add {FIRMWARE_TARGET}`"
        );
    }
    let added = Command::new("rustup")
        .current_dir(workspace)
        .args(["target", "add", FIRMWARE_TARGET])
        .output();
    let why = match added {
        Ok(out) if out.status.success() && installed() => return Ok(()),
        Ok(out) => format!(
            "`rustup target add {FIRMWARE_TARGET}` failed ({})",
            rustup_error(&String::from_utf8_lossy(&out.stderr))
        ),
        Err(e) => format!("rustup is not available to add it ({e})"),
    };
    Err(format!(
        "the Rust target {FIRMWARE_TARGET} is not installed for {version} and {why}; \
         install it with `rustup target add {FIRMWARE_TARGET}`, or name a prebuilt ELF in \
         STEREOCAL_FIRMWARE_ELF"
    ))
}

/// rustup's `error:` lines, without the backtrace it may append; all of its output when it
/// has none.
fn rustup_error(stderr: &str) -> String {
    let errors: Vec<&str> = stderr
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("error"))
        .collect();
    if errors.is_empty() {
        stderr.trim().to_string()
    } else {
        errors.join("; ")
    }
}

/// `../shared/data/real` (or `STEREOCAL_REAL_DATA`), or `None` after a loud `SKIPPED` line
/// when it is absent; under `CI=true` its absence is a failure.
pub fn real_data_or_skip(test: &str) -> Option<PathBuf> {
    let root = std::env::var_os("STEREOCAL_REAL_DATA")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/real"));
    if root.join("eth3d_two_view").is_dir() {
        return Some(root);
    }
    skip(
        test,
        &format!(
            "real data not found at {} (set STEREOCAL_REAL_DATA)",
            root.display()
        ),
    );
    None
}

/// `test` cannot run for `reason` (a tool or data set missing): under `CI=true` that is a
/// failure; elsewhere it says so loudly, straight to stderr, past the test harness's output
/// capture, so the line shows in a plain `cargo test` run, and the caller returns.
pub fn skip(test: &str, reason: &str) {
    use std::io::Write;
    if std::env::var("CI").as_deref() == Ok("true") {
        panic!("{test}: {reason}; required under CI=true");
    }
    // A closed stderr has nobody to tell.
    let _ = writeln!(std::io::stderr(), "\n*** SKIPPED {test}: {reason} ***\n");
}

impl Scenario {
    /// `frames` pairs cut from an ETH3D two-view pair (`root/eth3d_two_view/SCENE/im0.png`,
    /// `im1.png`, `calib.txt`): a `width` x `height` window at (`x`, `y`) in both images,
    /// moved `step` pixels right per frame, grey. The calibration is the window's at frame 0.
    #[allow(clippy::too_many_arguments)]
    pub fn real_crop(
        root: &Path,
        scene: &str,
        (x, y): (u32, u32),
        (width, height): (u16, u16),
        step: u32,
        frames: usize,
        config: SessionConfig,
    ) -> Self {
        let dir = root.join("eth3d_two_view").join(scene);
        let grey = |name: &str| {
            let path = dir.join(name);
            image::open(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
                .into_luma8()
        };
        let (left, right) = (grey("im0.png"), grey("im1.png"));
        let crop = |img: &image::GrayImage, i: usize| {
            let x = x + step * i as u32;
            image::imageops::crop_imm(img, x, y, u32::from(width), u32::from(height))
                .to_image()
                .into_raw()
        };
        let pairs = (0..frames)
            .map(|i| Pair {
                timestamp_us: i as u64 * 33_333,
                left: crop(&left, i),
                right: crop(&right, i),
            })
            .collect();
        let calib_path = dir.join("calib.txt");
        let text = std::fs::read_to_string(&calib_path)
            .unwrap_or_else(|e| panic!("{}: {e}", calib_path.display()));
        let value = |key: &str| {
            text.lines()
                .find_map(|l| l.strip_prefix(key))
                .unwrap_or_else(|| panic!("{}: no {key}", calib_path.display()))
        };
        // `cam0=[fx 0 cx; 0 fy cy; 0 0 1]`, baseline in millimetres.
        let camera = |key: &str| {
            let m: Vec<f64> = value(key)
                .trim_matches(|c| c == '[' || c == ']')
                .replace(';', " ")
                .split_whitespace()
                .map(|v| v.parse().expect("calib.txt number"))
                .collect();
            format!(
                "fx = {}\nfy = {}\ncx = {}\ncy = {}\n",
                m[0],
                m[4],
                m[2] - f64::from(x),
                m[5] - f64::from(y)
            )
        };
        let baseline_mm: f64 = value("baseline=").trim().parse().expect("baseline");
        let toml = format!(
            "baseline_m = {}\n[left]\n{}[right]\n{}",
            baseline_mm / 1000.0,
            camera("cam0="),
            camera("cam1=")
        );
        Self {
            name: format!("eth3d {scene} {width}x{height} crop"),
            calib: Calibration::from_toml_str(&toml, &calib_path).expect("calibration"),
            width,
            height,
            config,
            pairs,
        }
    }
}
