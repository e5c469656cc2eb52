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

use crate::options::EstimateArgs;
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
    estimate: EstimateArgs,
    /// The QEMU binary.
    #[arg(long, default_value = DEFAULT_QEMU)]
    qemu: PathBuf,
    /// Seconds to wait for one answer or frame pair from the emulated device.
    #[arg(long, default_value_t = QemuTimeouts::default().answer.as_secs(),
          value_parser = clap::value_parser!(u64).range(1..=86_400))]
    timeout: u64,
    /// Run with `-icount shift=0` and print the soft-core's instructions per pixel.
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
    let sequence = Sequence::builtin(args.scene, config)
        .with_context(|| format!("cannot build the `{}` sequence", args.scene))?;
    let qemu = QemuConfig {
        qemu: args.qemu.clone(),
        count_instructions: args.count_instructions,
        timeouts: QemuTimeouts {
            answer: Duration::from_secs(args.timeout),
            ..QemuTimeouts::default()
        },
        ..QemuConfig::new(&args.elf)
    };

    let bar = progress_bar(sequence.len() as u64, "soft-core under QEMU");
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
    if args.count_instructions {
        print_instructions(&run.logs);
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
