//! `stereocal hil`: the `eval` run with the firmware ELF on the emulated soft-core (QEMU)
//! instead of the in-process device.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Context;
use clap::Args;
use stereocal::output::summary::{Residual, Summary};
use stereocal_synth::{SceneKind, Sequence, SequenceConfig, TrajectoryKind};
use stereocal_tools::hil::{
    instruction_reports, kernel_report, run_sequence, QemuConfig, QemuTimeouts, DEFAULT_QEMU,
};

use crate::options::{EstimateArgs, SizeArgs};
use crate::output::{finish, progress_bar, Finish};

#[derive(Debug, Clone, Args)]
pub struct HilArgs {
    /// The firmware ELF (build it with `cargo build --release -p stereocal-firmware
    /// --target riscv32imc-unknown-none-elf`).
    #[arg(long)]
    elf: PathBuf,
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
    /// under Verilator, the simulator `cargo build --release -p stereocal-hil --bin
    /// sc-soc-sim` builds as target/release/sc-soc-sim.
    #[arg(long, value_name = "SC_SOC_SIM")]
    soc: Option<PathBuf>,
    /// Seconds to wait for one answer or frame pair from the emulated device.
    #[arg(long, default_value_t = QemuTimeouts::default().answer.as_secs(),
          value_parser = clap::value_parser!(u64).range(1..=86_400))]
    timeout: u64,
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
    let qemu = QemuConfig {
        qemu: args.qemu.clone(),
        count_instructions: args.count_instructions,
        soc: args.soc.clone(),
        timeouts: QemuTimeouts {
            answer: Duration::from_secs(args.timeout),
            ..QemuTimeouts::default()
        },
        ..QemuConfig::new(&args.elf)
    };

    let machine = if args.soc.is_some() {
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
    let run = run.with_context(|| format!("hardware-in-the-loop run of {}", args.elf.display()))?;
    if args.verbose {
        if run.logs.is_empty() {
            eprintln!("firmware: no log messages");
        }
        for log in &run.logs {
            eprintln!("firmware {log}");
        }
    }
    let mut json_extra = serde_json::Map::new();
    if args.count_instructions {
        print_instructions(&run.logs);
        let per_pair = softcore_instructions_per_pair(&run.logs)
            .context("the firmware sent no instruction reports")?;
        eprintln!("soft-core program, most instructions in one pair: {per_pair}");
        json_extra.insert("softcore_instructions_per_pair".into(), per_pair.into());
    }
    eprintln!(
        "QEMU: {}, {} bytes from the UART",
        run.end.exit,
        run.end.transcript.len()
    );

    let (records, cost) = run.value;
    let (w, h) = sequence.image_size();
    let summary = Summary::from_records(&records, Residual::Keep, cost.into());
    let title = format!(
        "stereocal hil: {} ({}), seed {}, firmware under QEMU",
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
            json: args.json,
            title: &title,
            json_extra,
        },
    )
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
    use stereocal_tools::hil::DeviceLog;

    use super::softcore_instructions_per_pair;

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
