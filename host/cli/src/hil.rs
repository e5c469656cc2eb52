//! `stereocal hil`: the `eval` run with the firmware ELF on the emulated soft-core (QEMU) or
//! on the SoC in the loop (a real core and the fabric's RTL under Verilator) instead of the
//! in-process device, then the same frames on the in-process device, whose bytes and records
//! the run's are compared with.

use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::Context;
use clap::Args;
use stereocal::output::summary::{Residual, Summary};
use stereocal_synth::{SceneKind, Sequence, SequenceConfig, TrajectoryKind};
use stereocal_tools::hil::{
    instruction_reports, kernel_report, run_sequence, MachineConfig, MachineTimeouts, SequenceRun,
    SocReport, DEFAULT_QEMU,
};

use crate::options::{EstimateArgs, SizeArgs};
use crate::output::{finish, progress_bar, Finish};

#[derive(Debug, Clone, Args)]
pub struct HilArgs {
    /// The firmware ELF (default: the release build beside this program's target directory,
    /// `target/riscv32imc-unknown-none-elf/release/stereocal-firmware`, which `cargo build
    /// --release -p stereocal-firmware --target riscv32imc-unknown-none-elf` makes).
    #[arg(long)]
    elf: Option<PathBuf>,
    /// Built-in scene: road, lab or sparse.
    #[arg(long, default_value = "road")]
    scene: SceneKind,
    /// Frame pairs (every pair is loaded into the soft-core's RAM: at most 191 at 640x480).
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..=1000))]
    frames: u32,
    /// Seed of the scene layout, trajectory, noise and drops.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Head motion (default: the scene's own: fixed on the road, manual moves elsewhere).
    #[arg(long)]
    trajectory: Option<TrajectoryKind>,
    #[command(flatten)]
    size: SizeArgs,
    #[command(flatten)]
    estimate: EstimateArgs,
    /// The QEMU binary.
    #[arg(long, default_value = DEFAULT_QEMU)]
    qemu: PathBuf,
    /// Run the ELF on the SoC in the loop instead of QEMU: a real RV32IMAC core (VexRiscv)
    /// and both channels' fabric RTL under Verilator. Without a path, the simulator
    /// `sc-soc-sim` next to this program or on PATH (`cargo build --release -p
    /// stereocal-hil --bin sc-soc-sim`).
    #[arg(long, value_name = "SC_SOC_SIM", num_args = 0..=1)]
    soc: Option<Option<PathBuf>>,
    /// On the SoC: the cameras' pixel clock, one clock in N (the board's default is 32, the
    /// stream engine's pace; 1 is a pixel every clock).
    #[arg(long, requires = "soc", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pixel_clock_divider: Option<u32>,
    /// Seconds to wait for one answer or frame pair (default: 120 under QEMU, where a run
    /// whose link is silent for 10 s ends as hung; 3600 on the SoC, where a 640x480 pair is
    /// minutes of simulation and the board itself ends a firmware that hangs after twenty
    /// line times in which nothing moved).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=86_400))]
    timeout: Option<u64>,
    /// Count instructions (QEMU: with `-icount shift=0`; the SoC's core counts them itself)
    /// and print the soft-core's instructions per pixel, and per pair its program's own
    /// (`softcore_instructions_per_pair` in `--json`).
    #[arg(long)]
    count_instructions: bool,
    /// Print the firmware's log messages (decoded with the ELF's defmt table) on stderr.
    #[arg(short, long)]
    verbose: bool,
    /// Also write verge.csv and verge.png here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print the summary as one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

pub fn hil(args: &HilArgs) -> anyhow::Result<()> {
    let mut config = SequenceConfig::for_scene(args.scene);
    config.frames = args.frames as usize;
    config.seed = args.seed;
    if let Some(t) = args.trajectory {
        config.trajectory = t;
    }
    args.size.apply(&mut config);
    let sequence = Sequence::builtin(args.scene, config)
        .with_context(|| format!("cannot build the `{}` sequence", args.scene))?;
    let elf = firmware_elf(args.elf.as_deref())?;
    let soc = args
        .soc
        .as_ref()
        .map(|given| soc_simulator(given.as_deref()))
        .transpose()?;
    let defaults = if soc.is_some() {
        MachineTimeouts::soc()
    } else {
        MachineTimeouts::default()
    };
    let qemu = MachineConfig {
        qemu: args.qemu.clone(),
        count_instructions: args.count_instructions,
        soc: soc.clone(),
        pixel_clock_divider: args.pixel_clock_divider,
        timeouts: MachineTimeouts {
            answer: args.timeout.map_or(defaults.answer, Duration::from_secs),
            ..defaults
        },
        ..MachineConfig::new(&elf)
    };

    let machine = if soc.is_some() {
        "soft-core on the SoC (Verilator)"
    } else {
        "soft-core under QEMU"
    };
    let bar = progress_bar(sequence.len() as u64, machine);
    let run = run_sequence(
        &qemu,
        &sequence,
        args.estimate.session_config(),
        &mut |_| bar.inc(1),
    );
    bar.finish_and_clear();
    let SequenceRun {
        device: run,
        wire,
        records_identical,
    } = run.with_context(|| format!("hardware-in-the-loop run of {}", elf.display()))?;
    if args.verbose {
        if run.logs.is_empty() {
            eprintln!("firmware: no log messages");
        }
        for log in &run.logs {
            eprintln!("firmware {log}");
        }
        if run.board.is_some() {
            for line in run.end.stderr.lines() {
                eprintln!("board {line}");
            }
        }
    }
    let mut json_extra = serde_json::Map::new();
    match &wire {
        Some(Ok(())) => {
            eprintln!("wire bytes after the Hello: identical to the in-process device's")
        }
        Some(Err(e)) => eprintln!("wire bytes: NOT the in-process device's: {e}"),
        None => eprintln!("wire bytes: not compared (the instruction reports are extra packets)"),
    }
    eprintln!(
        "records: {} the in-process device's",
        if records_identical {
            "identical to"
        } else {
            "NOT"
        }
    );
    json_extra.insert(
        "wire_bytes_identical".into(),
        wire.as_ref().map(Result::is_ok).into(),
    );
    json_extra.insert("records_identical".into(), records_identical.into());
    eprintln!(
        "link: longest silence {:.2} s",
        run.end.longest_silence.as_secs_f64()
    );
    json_extra.insert(
        "link_longest_silence_s".into(),
        run.end.longest_silence.as_secs_f64().into(),
    );
    if let Some(board) = &run.board {
        board_figures(board, &mut json_extra);
    }
    if args.count_instructions {
        print_instructions(&run.logs);
        let per_pair = softcore_instructions_per_pair(&run.logs)
            .context("the firmware sent no instruction reports")?;
        eprintln!("soft-core program, most instructions in one pair: {per_pair}");
        json_extra.insert("softcore_instructions_per_pair".into(), per_pair.into());
    }
    eprintln!(
        "{machine}: {}, {} bytes on the link",
        run.end.exit,
        run.end.transcript.len()
    );

    let (records, cost) = run.value;
    let (w, h) = sequence.image_size();
    let summary = Summary::from_records(&records, Residual::Keep, cost.into());
    let title = format!(
        "stereocal hil: {} ({}), seed {}, {machine}",
        args.scene,
        sequence.config().trajectory,
        args.seed
    );
    finish(
        &records,
        &summary,
        true,
        (w, h),
        Finish {
            out: args.out.as_deref(),
            matches: false,
            json: args.json,
            title: &title,
            json_extra,
        },
    )
}

/// The firmware's release ELF, relative to cargo's target directory.
const FIRMWARE_ELF: &str = "riscv32imc-unknown-none-elf/release/stereocal-firmware";

/// The ELF `--elf` names, or without it the release build in the target directory this
/// program was built into (`target/release/stereocal` → `target/FIRMWARE_ELF`).
fn firmware_elf(given: Option<&Path>) -> anyhow::Result<PathBuf> {
    if let Some(given) = given {
        return Ok(given.to_path_buf());
    }
    std::env::current_exe()
        .ok()
        .and_then(|exe| Some(exe.parent()?.parent()?.join(FIRMWARE_ELF)))
        .filter(|elf| elf.is_file())
        .with_context(|| {
            format!(
                "no firmware ELF beside this program's target directory ({FIRMWARE_ELF}): \
                 build it with `cargo build --release -p stereocal-firmware --target \
                 riscv32imc-unknown-none-elf`, or give its path as --elf PATH"
            )
        })
}

/// The SoC simulator's name, as `cargo build -p stereocal-hil --bin sc-soc-sim` builds it.
const SOC_SIMULATOR: &str = "sc-soc-sim";

/// The simulator `--soc` names: the given path, or without one `sc-soc-sim` next to this
/// program (both in cargo's target directory) or on PATH.
fn soc_simulator(given: Option<&Path>) -> anyhow::Result<PathBuf> {
    if let Some(given) = given {
        return Ok(given.to_path_buf());
    }
    let beside = std::env::current_exe()
        .ok()
        .and_then(|exe| exe.parent().map(|dir| dir.join(SOC_SIMULATOR)));
    let on_path = std::env::var_os("PATH")
        .into_iter()
        .flat_map(|path| std::env::split_paths(&path).collect::<Vec<_>>())
        .map(|dir| dir.join(SOC_SIMULATOR));
    beside
        .into_iter()
        .chain(on_path)
        .find(|candidate| candidate.is_file())
        .with_context(|| {
            format!(
                "the SoC simulator {SOC_SIMULATOR} is neither beside this program nor on PATH: \
                 build it with `cargo build --release -p stereocal-hil --bin {SOC_SIMULATOR}` \
                 (needs verilator, python3-venv and, once, network for pip), or give its path \
                 as --soc PATH"
            )
        })
}

/// What the SoC's board measured, on stderr and into the JSON summary.
fn board_figures(board: &SocReport, json: &mut serde_json::Map<String, serde_json::Value>) {
    let cycles = board.softcore_cycles_per_pair();
    let clocks = board.sim_clocks_per_pair();
    let latency = board.latency();
    let speed = board.clocks_per_second();
    eprintln!(
        "SoC: soft-core cycles per pair: its own work {}, polling BUSY {}; simulated clocks \
         per pair {}, FIFO overflows {}",
        show(cycles),
        show(board.busy_wait_cycles_per_pair()),
        show(clocks),
        board.fifo_overflows()
    );
    if let Some(l) = latency {
        eprintln!(
            "SoC: worst image, first pixel in to last byte out {} clocks, last pixel in to \
             last byte out {} clocks",
            l.first_pixel_to_last_byte, l.last_pixel_to_last_byte
        );
    }
    if let (Some(end), Some(speed)) = (board.end, speed) {
        eprintln!(
            "SoC: {} clocks in {:.1} s ({speed:.0} clocks/s), longest stillness {} clocks",
            end.cycles,
            end.millis as f64 / 1000.0,
            end.longest_still
        );
    }
    json.insert("softcore_cycles_per_pair".into(), cycles.into());
    json.insert(
        "softcore_busy_wait_cycles_per_pair".into(),
        board.busy_wait_cycles_per_pair().into(),
    );
    json.insert("sim_clocks_per_pair".into(), clocks.into());
    json.insert("fifo_overflows".into(), board.fifo_overflows().into());
    json.insert(
        "pixel_clock_divider".into(),
        board.end.map(|e| e.pixel_clock_divider).into(),
    );
    json.insert(
        "latency_first_pixel_to_last_byte_clocks".into(),
        latency.map(|l| l.first_pixel_to_last_byte).into(),
    );
    json.insert(
        "latency_last_pixel_to_last_byte_clocks".into(),
        latency.map(|l| l.last_pixel_to_last_byte).into(),
    );
    json.insert("sim_clocks_per_second".into(), speed.into());
    json.insert(
        "sim_longest_still_clocks".into(),
        board.end.map(|e| e.longest_still).into(),
    );
}

fn show(value: Option<u64>) -> String {
    value.map_or_else(|| "unknown".into(), |v| v.to_string())
}

/// The soft-core's instructions per pixel, per image and over the run, on stderr.
fn print_instructions(logs: &[stereocal_tools::hil::DeviceLog]) {
    let reports = instruction_reports(logs);
    let (mut pixels, mut front_end, mut driver) = (0u64, 0u64, 0u64);
    for r in &reports {
        eprintln!(
            "frame {} camera {}: instructions per pixel: front end {:.1}, driver {:.1} \
             (and {} waiting for the UART)",
            r.frame,
            r.camera,
            r.front_end_per_pixel(),
            r.driver_per_pixel(),
            r.uart_wait
        );
        pixels += u64::from(r.pixels);
        front_end += r.front_end;
        driver += r.driver;
    }
    if pixels > 0 {
        eprintln!(
            "soft-core over {} images: front end {:.1} instructions/pixel, driver {:.1}",
            reports.len(),
            front_end as f64 / pixels as f64,
            driver as f64 / pixels as f64
        );
    }
    if let Some(k) = kernel_report(logs) {
        eprintln!(
            "octave-0 row kernels per pixel: Gaussian scales {:.1}, DoG {:.1}, Sobel + CORDIC {:.1}",
            k.per_pixel(k.gaussian),
            k.per_pixel(k.dog),
            k.per_pixel(k.sobel_cordic)
        );
    }
}

/// The soft-core program's own instructions for the costliest pair of the run: both cameras'
/// `driver` counts (configuring, arming, offering the rows, polling), without the fabric's
/// software stand-in (`front_end`) and without the waits for the emulated UART, which a
/// link that keeps up does not cause. The budget is per pair, so the worst pair is the figure.
fn softcore_instructions_per_pair(logs: &[stereocal_tools::hil::DeviceLog]) -> Option<u64> {
    let mut per_frame = std::collections::BTreeMap::<u32, u64>::new();
    for r in instruction_reports(logs) {
        *per_frame.entry(r.frame).or_default() += r.driver;
    }
    per_frame.into_values().max()
}

#[cfg(test)]
mod tests {
    use clap::Parser;
    use stereocal_tools::hil::DeviceLog;

    use super::{softcore_instructions_per_pair, HilArgs};

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        hil: HilArgs,
    }

    #[test]
    fn soc_takes_an_optional_path() {
        let soc = |args: &[&str]| {
            Cli::try_parse_from([&["stereocal"], args].concat())
                .unwrap()
                .hil
                .soc
        };
        assert_eq!(soc(&[]), None);
        assert_eq!(soc(&["--soc", "--width", "128"]), Some(None));
        assert_eq!(soc(&["--soc"]), Some(None));
        assert_eq!(soc(&["--soc", "sim"]), Some(Some("sim".into())));
    }

    fn report(frame: u32, camera: u8, driver: u64) -> DeviceLog {
        DeviceLog {
            seq: 0,
            level: None,
            text: format!(
                "instructions: frame {frame} camera {camera} pixels 100 front_end 9999 \
                 driver {driver} uart_wait 777"
            ),
        }
    }

    #[test]
    fn the_costliest_pair_counts_both_cameras_and_nothing_of_the_fabric() {
        let logs = [
            report(0, 0, 10),
            report(0, 1, 20),
            report(1, 0, 25),
            report(1, 1, 1),
            DeviceLog {
                seq: 1,
                level: Some("info"),
                text: "instructions: frame 1 camera 0 pixels 1 front_end 1 driver 1000 uart_wait 0"
                    .into(),
            },
        ];
        assert_eq!(softcore_instructions_per_pair(&logs), Some(30));
        assert_eq!(softcore_instructions_per_pair(&[]), None);
    }
}
