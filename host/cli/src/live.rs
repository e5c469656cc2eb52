//! `stereocal live`: a head that grabs its own frames (a board on a serial port, or the
//! firmware under an emulator started by hand, on a TCP or Unix socket), configured and then
//! listened to.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use anyhow::Context;
use clap::{ArgGroup, Args};
use stereocal::calib::Calibration;
use stereocal::driver::DriverError;
use stereocal::link::{Link, LinkError, OwnCameras, StreamLink};
use stereocal::output::record::FrameRecord;
use stereocal::output::summary::{Residual, Summary};
use stereocal::session::{Session, SessionError};

use crate::options::EstimateArgs;
use crate::output::{finish, keep, progress_bar, Finish};

#[derive(Debug, Clone, Args)]
#[command(group(ArgGroup::new("link").required(true).args(["serial", "tcp", "unix"])))]
pub struct LiveArgs {
    /// Serial port of the board's soft-core UART (e.g. /dev/ttyUSB0, COM3), 8N1.
    #[arg(long, value_name = "DEVICE")]
    serial: Option<String>,
    /// Baud rate of --serial. Full Sobel rows are megabytes a pair: at UART rates use
    /// `--sobel patches`.
    #[arg(long, default_value_t = 921_600, requires = "serial")]
    baud: u32,
    /// TCP address of the device (e.g. QEMU's `-chardev socket,host=..,port=..,server=on`).
    #[arg(long, value_name = "HOST:PORT")]
    tcp: Option<String>,
    /// Unix socket of the device (e.g. QEMU's `-chardev socket,path=..,server=on`).
    #[arg(long, value_name = "PATH")]
    unix: Option<PathBuf>,
    /// Calibration file, recognised by content: the project's TOML (baseline_m, [left] and
    /// [right] fx, fy, cx, cy, optional k1, k2, p1, p2, k3 and [extrinsics]), OpenCV's
    /// stereoCalibrate results written by cv::FileStorage (K1, D1, K2, D2, R, T; T in metres),
    /// a Kalibr camchain.yaml (cam0, cam1) or KITTI's calib.txt (P0, P1 or P_rect_00, P_rect_01).
    #[arg(long)]
    calib: PathBuf,
    /// Width of the cameras' frames, as the fabric is to be configured.
    #[arg(long)]
    width: u16,
    /// Height of the cameras' frames.
    #[arg(long)]
    height: u16,
    /// Stop after this many frame pairs (default: until the device closes the link or Ctrl-C,
    /// which ends the run at the next pair, or at the timeout if the head is quiet).
    #[arg(long)]
    frames: Option<usize>,
    /// Longest wait, in milliseconds, for an answer or for the next pair.
    #[arg(long, default_value_t = 5000)]
    timeout_ms: u64,
    /// Where verge.csv and verge.png go.
    #[arg(long, default_value = "out/live")]
    out: PathBuf,
    #[command(flatten)]
    estimate: EstimateArgs,
    /// Print the summary as one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

pub fn live(args: &LiveArgs) -> anyhow::Result<()> {
    let interrupted = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&interrupted);
    ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
        .context("cannot install the Ctrl-C handler")?;
    let calib = Calibration::load(&args.calib)?;
    let (link, name): (Box<dyn Link>, String) = if let Some(device) = &args.serial {
        let link = StreamLink::serial(device, args.baud)?;
        let name = link.name().to_owned();
        (Box::new(link), name)
    } else if let Some(addr) = &args.tcp {
        let link = StreamLink::tcp(addr)?;
        let name = link.name().to_owned();
        (Box::new(link), name)
    } else {
        let path = args.unix.as_ref().context("no link given")?;
        open_unix(path)?
    };
    let timeout = Duration::from_millis(args.timeout_ms);
    let device = OwnCameras::new(link, timeout);
    let mut session = Session::with_device(
        device,
        calib,
        args.width,
        args.height,
        args.estimate.session_config(),
    )
    .with_context(|| format!("cannot start the device on {name}"))?;

    let bar = progress_bar(args.frames.unwrap_or(0) as u64, "listening");
    let mut records: Vec<FrameRecord> = Vec::new();
    // A failure after pairs were recorded still writes them: nothing accepted is lost.
    let mut stopped = None;
    while args.frames.is_none_or(|n| records.len() < n) && !interrupted.load(Ordering::Relaxed) {
        match session.receive(records.len()) {
            Ok(record) => keep(&mut records, record, &bar),
            Err(SessionError::Driver(DriverError::Link(LinkError::Closed { .. })))
                if args.frames.is_none() && !records.is_empty() =>
            {
                break
            }
            Err(_) if interrupted.load(Ordering::Relaxed) => break,
            Err(e) => {
                stopped = Some(
                    anyhow::Error::new(e).context(format!("frame {} on {name}", records.len())),
                );
                break;
            }
        }
    }
    bar.finish_and_clear();
    if records.is_empty() {
        return Err(stopped.unwrap_or_else(|| anyhow::anyhow!("{name}: no frame pair arrived")));
    }
    let summary = Summary::from_records(&records, Residual::Keep, session.cost().into());
    let title = format!("stereocal live: {name}");
    finish(
        &records,
        &summary,
        false,
        (u32::from(args.width), u32::from(args.height)),
        Finish {
            out: Some(&args.out),
            matches: false,
            json: args.json,
            title: &title,
            json_extra: Default::default(),
        },
    )?;
    match stopped {
        Some(e) => Err(e.context(format!(
            "stopped after {} frame pairs (written to {})",
            records.len(),
            args.out.display()
        ))),
        None => Ok(()),
    }
}

#[cfg(unix)]
fn open_unix(path: &std::path::Path) -> anyhow::Result<(Box<dyn Link>, String)> {
    let link = StreamLink::unix(path)?;
    let name = link.name().to_owned();
    Ok((Box::new(link), name))
}

#[cfg(not(unix))]
fn open_unix(path: &std::path::Path) -> anyhow::Result<(Box<dyn Link>, String)> {
    anyhow::bail!("{}: Unix sockets exist only on Unix", path.display())
}
