//! `stereocal live` against a head that grabs its own frames: the in-process firmware and
//! fabric model behind a TCP socket, a Unix socket and a pseudo-terminal standing in for a
//! board's serial port. The head waits for the host's enable, then streams the pairs of a
//! rendered sequence and closes the link; `live` must estimate exactly what `run` estimates
//! on the same images (the same bytes cross the wire), and a head that goes quiet must end in
//! a timeout that names the link, with the pairs already received written out.

mod common;

use std::io::ErrorKind;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{stereocal, succeeded, synth_road};
use std::thread;
use std::time::Duration;

use stereocal::link::{InProcessLink, Link, TimedStream};
use stereocal_wire::EncodersRepr;

const FRAMES: usize = 4;
/// The sequence's frame period at `stereocal run`'s default 30 fps.
const PERIOD_US: f64 = 1e6 / 30.0;

/// Renders the road sequence into `dir` (left/, right/, calib.toml).
fn synth(dir: &Path) -> (u32, u32) {
    synth_road(dir, FRAMES, 3);
    image::open(dir.join("left").join(first_file(&dir.join("left"))))
        .expect("rendered image")
        .to_luma8()
        .dimensions()
}

fn first_file(dir: &Path) -> String {
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    names.remove(0)
}

fn sorted_images(dir: &Path) -> Vec<Vec<u8>> {
    let mut paths: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| image::open(p).unwrap().to_luma8().into_raw())
        .collect()
}

/// The head: answers the host through the in-process device until it is enabled, then
/// grabs the first `pairs` pairs of `dir` as its cameras would, sends their packets and, when
/// `close` is set, closes the link (a quiet head keeps it open until the host leaves).
fn head(stream: impl TimedStream, dir: &Path, pairs: usize, close: bool) {
    head_with(stream, dir, pairs, close, Quirks::default());
}

/// What a head may do besides streaming cleanly.
#[derive(Default, Clone, Copy)]
struct Quirks {
    /// Pairs it had streamed to nobody when the host connected (its ids do not start at 0).
    before: usize,
    /// A pair whose bytes it damages on the way out, and where: 20 bytes in a row flipped from
    /// this fraction of the pair's bytes on (0: in the left frame's `FrameStart`), more than
    /// error correction repairs in one block.
    damage: Option<(usize, f64)>,
    /// Whether it sends an `Encoders` reading before each pair ([`encoder_yaws_udeg`]).
    encoders: bool,
}

/// The yaws (µdeg) a head with encoders reports for pair `i`: a left camera turning 0.3° per
/// frame that the images do not show, so the filter's output tells whether it took them.
fn encoder_yaws_udeg(i: usize) -> (i32, i32) {
    (800_000 + 300_000 * i as i32, -800_000)
}

fn head_with(mut stream: impl TimedStream, dir: &Path, pairs: usize, close: bool, q: Quirks) {
    let left = sorted_images(&dir.join("left"));
    let right = sorted_images(&dir.join("right"));
    let mut device = InProcessLink::new().unwrap();
    for _ in 0..q.before {
        device.submit_pair(&left[0], &right[0], 0).unwrap();
        Link::take_sent(&mut device, &mut Vec::new()).unwrap();
    }
    stream
        .set_receive_timeout(Duration::from_millis(10))
        .unwrap();
    let mut buf = [0u8; 4096];
    let mut out = Vec::new();
    let mut grabbed = false;
    loop {
        match stream.read(&mut buf) {
            Ok(0) => return,
            Ok(n) => device.send(&buf[..n]).unwrap(),
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
            Err(_) => return,
        }
        let mut send = |device: &mut InProcessLink, damage: Option<f64>| {
            out.clear();
            Link::take_sent(device, &mut out).unwrap();
            if let Some(at) = damage {
                // Byte 3 is inside the first link frame, whatever its COBS code bytes.
                let at = ((out.len() as f64 * at) as usize).max(3);
                let end = (at + 20).min(out.len());
                out[at..end].iter_mut().for_each(|b| *b ^= 0x5a);
            }
            stream.write_all(&out).is_ok()
        };
        if !send(&mut device, None) {
            return;
        }
        if device.enabled() && !grabbed {
            grabbed = true;
            for (i, (l, r)) in left.iter().zip(&right).take(pairs).enumerate() {
                if q.encoders {
                    let (left_yaw_udeg, right_yaw_udeg) = encoder_yaws_udeg(i);
                    device
                        .send_encoders(EncodersRepr {
                            frame_id: i as u32,
                            left_yaw_udeg,
                            right_yaw_udeg,
                        })
                        .unwrap();
                }
                device
                    .submit_pair(l, r, (i as f64 * PERIOD_US).round() as u64)
                    .unwrap();
                let damage = q.damage.filter(|&(pair, _)| pair == i).map(|(_, at)| at);
                if !send(&mut device, damage) {
                    return;
                }
            }
            if close {
                return;
            }
        }
    }
}

fn filtered_verges(csv: &Path) -> Vec<String> {
    std::fs::read_to_string(csv)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(2).unwrap().to_owned())
        .collect()
}

fn raw_verges(csv: &Path) -> Vec<String> {
    std::fs::read_to_string(csv)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').take(2).collect::<Vec<_>>().join(","))
        .collect()
}

/// `live` on `link_args` while `serve` runs the head, then the same frames through `run`.
fn live_equals_run(link_args: &[&str], serve: impl FnOnce(&Path) + Send) {
    let dir = tempfile::tempdir().unwrap();
    let seq = dir.path().join("seq");
    let (w, h) = synth(&seq);
    let calib = seq.join("calib.toml");
    let live_out = dir.path().join("live");
    let run_out = dir.path().join("run");
    let live = thread::scope(|scope| {
        scope.spawn(|| serve(&seq));
        let mut args = vec!["live"];
        args.extend_from_slice(link_args);
        let (w, h) = (w.to_string(), h.to_string());
        args.extend([
            "--calib",
            calib.to_str().unwrap(),
            "--width",
            &w,
            "--height",
            &h,
            "--out",
            live_out.to_str().unwrap(),
            "--json",
        ]);
        stereocal(&args)
    });
    let live = succeeded(live);
    let summary: serde_json::Value = serde_json::from_slice(&live.stdout).unwrap();
    assert_eq!(summary["frames"], FRAMES);
    assert_eq!(summary["estimated_frames"], FRAMES);
    let run = stereocal(&[
        "run",
        "--left",
        seq.join("left").to_str().unwrap(),
        "--right",
        seq.join("right").to_str().unwrap(),
        "--calib",
        calib.to_str().unwrap(),
        "--out",
        run_out.to_str().unwrap(),
    ]);
    succeeded(run);
    let (live, run) = (
        raw_verges(&live_out.join("verge.csv")),
        raw_verges(&run_out.join("verge.csv")),
    );
    assert_eq!(live.len(), FRAMES);
    assert_eq!(live, run, "live and run estimate the same bytes alike");
    assert!(live_out.join("verge.png").is_file());
}

#[test]
fn live_over_tcp_estimates_what_run_does() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap().to_string();
    live_equals_run(&["--tcp", &addr], |seq| {
        let (stream, _) = listener.accept().unwrap();
        head(stream, seq, FRAMES, true);
    });
}

#[cfg(unix)]
#[test]
fn live_over_a_unix_socket_estimates_what_run_does() {
    use std::os::unix::net::UnixListener;
    let sock_dir = tempfile::tempdir().unwrap();
    let path = sock_dir.path().join("head.sock");
    let listener = UnixListener::bind(&path).unwrap();
    live_equals_run(&["--unix", path.to_str().unwrap()], |seq| {
        let (stream, _) = listener.accept().unwrap();
        head(stream, seq, FRAMES, true);
    });
}

#[cfg(unix)]
#[test]
fn live_over_a_serial_port_estimates_what_run_does() {
    use serialport::{SerialPort, TTYPort};
    let (master, slave) = TTYPort::pair().expect("pseudo-terminal pair");
    let name = slave.name().expect("pty name");
    // A UART never ends its stream: the run is bounded by --frames.
    let frames = FRAMES.to_string();
    live_equals_run(
        &["--serial", &name, "--baud", "115200", "--frames", &frames],
        move |seq| {
            // The host opens the slave by name; this end stays open until the head is done.
            let _slave = slave;
            head(Box::new(master) as Box<dyn SerialPort>, seq, FRAMES, true);
        },
    );
}

/// A rendered sequence in a temporary directory and a TCP listener its head will serve on.
struct TcpHeadSetup {
    dir: tempfile::TempDir,
    seq: PathBuf,
    /// The frames' width and height, as `live` takes them.
    size: (String, String),
    listener: TcpListener,
    addr: String,
}

impl TcpHeadSetup {
    fn new() -> Self {
        let dir = tempfile::tempdir().unwrap();
        let seq = dir.path().join("seq");
        let (w, h) = synth(&seq);
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = listener.local_addr().unwrap().to_string();
        Self {
            dir,
            seq,
            size: (w.to_string(), h.to_string()),
            listener,
            addr,
        }
    }

    /// Where `live` writes its outputs.
    fn out_dir(&self) -> PathBuf {
        self.dir.path().join("live")
    }

    /// `live`'s arguments for this head, up to its optional flags.
    fn live_args<'a>(&'a self, calib: &'a Path, out_dir: &'a Path) -> Vec<&'a str> {
        vec![
            "live",
            "--tcp",
            &self.addr,
            "--calib",
            calib.to_str().unwrap(),
            "--width",
            &self.size.0,
            "--height",
            &self.size.1,
            "--out",
            out_dir.to_str().unwrap(),
        ]
    }
}

/// A head serving the rendered sequence over TCP, grabbing `pairs` pairs with `quirks` (and
/// closing the link after them when `close` is set), and `stereocal live` on it with `extra`
/// arguments.
fn live_on_a_tcp_head(
    pairs: usize,
    close: bool,
    quirks: Quirks,
    extra: &[&str],
) -> (Output, TcpHeadSetup) {
    let setup = TcpHeadSetup::new();
    let live = thread::scope(|scope| {
        scope.spawn(|| {
            let (stream, _) = setup.listener.accept().unwrap();
            head_with(stream, &setup.seq, pairs, close, quirks);
        });
        let (calib, out_dir) = (setup.seq.join("calib.toml"), setup.out_dir());
        let mut args = setup.live_args(&calib, &out_dir);
        args.extend_from_slice(extra);
        stereocal(&args)
    });
    (live, setup)
}

#[test]
fn a_quiet_head_times_out_naming_the_link_and_keeps_what_arrived() {
    let extra = ["--frames", "3", "--timeout-ms", "500"];
    let (live, setup) = live_on_a_tcp_head(2, false, Quirks::default(), &extra);
    assert!(!live.status.success());
    let stderr = String::from_utf8_lossy(&live.stderr);
    assert!(
        stderr.contains(&format!("frame 2 on tcp {}", setup.addr)) && stderr.contains("timed out"),
        "{stderr}"
    );
    assert!(stderr.contains("stopped after 2 frame pairs"), "{stderr}");
    assert_eq!(raw_verges(&setup.out_dir().join("verge.csv")).len(), 2);
}

#[cfg(unix)]
#[test]
fn ctrl_c_ends_the_run_and_writes_what_arrived() {
    let setup = TcpHeadSetup::new();
    let (calib, out_dir) = (setup.seq.join("calib.toml"), setup.out_dir());
    let live = thread::scope(|scope| {
        scope.spawn(|| {
            let (stream, _) = setup.listener.accept().unwrap();
            head(stream, &setup.seq, 2, false);
        });
        let mut args = setup.live_args(&calib, &out_dir);
        args.extend(["--timeout-ms", "3000"]);
        let child = common::command()
            .args(args)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // Two pairs take well under this; the head then stays quiet.
        thread::sleep(Duration::from_secs(2));
        let kill = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status()
            .unwrap();
        assert!(kill.success());
        child.wait_with_output().unwrap()
    });
    succeeded(live);
    assert_eq!(raw_verges(&out_dir.join("verge.csv")).len(), 2);
}

#[test]
fn a_head_streaming_before_the_host_connects_starts_the_numbering() {
    let quirks = Quirks {
        before: 5,
        ..Quirks::default()
    };
    let (live, _setup) = live_on_a_tcp_head(2, true, quirks, &["--json"]);
    let live = succeeded(live);
    let summary: serde_json::Value = serde_json::from_slice(&live.stdout).unwrap();
    assert_eq!(summary["frames"], 2);
    assert_eq!(summary["estimated_frames"], 2);
}

#[test]
fn a_pair_damaged_on_the_link_is_dropped_and_says_why() {
    let quirks = Quirks {
        damage: Some((1, 0.0)),
        ..Quirks::default()
    };
    let (live, setup) = live_on_a_tcp_head(3, true, quirks, &[]);
    let live = succeeded(live);
    let stderr = String::from_utf8_lossy(&live.stderr);
    assert!(
        stderr.contains("frame 1: dropped: ") && stderr.contains("damaged"),
        "{stderr}"
    );
    assert_eq!(statuses(&setup), ["ok", "dropped", "ok"]);
}

#[test]
fn a_pair_that_lost_a_sobel_row_is_salvaged_and_says_what_it_lost() {
    let quirks = Quirks {
        damage: Some((1, 0.3)),
        ..Quirks::default()
    };
    // Salvage is the noisy-link guard's: it makes a lost packet cost little.
    let (live, setup) = live_on_a_tcp_head(3, true, quirks, &["--noisy-link"]);
    succeeded(live);
    assert_eq!(statuses(&setup), ["ok", "salvaged", "ok"]);
    let csv = std::fs::read_to_string(setup.out_dir().join("verge.csv")).unwrap();
    let lost: Vec<&str> = csv.lines().nth(2).unwrap().split(',').skip(10).collect();
    assert_eq!(lost[0], "1", "{csv}");
    assert!(lost[1].parse::<u32>().unwrap() > 0, "{csv}");
}

/// The `status` column of the live run's `verge.csv`.
fn statuses(setup: &TcpHeadSetup) -> Vec<String> {
    let csv = std::fs::read_to_string(setup.out_dir().join("verge.csv")).unwrap();
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').nth(6).unwrap().to_owned())
        .collect()
}

#[test]
fn a_head_with_encoders_moves_the_filter_as_run_does_with_them() {
    let quirks = Quirks {
        encoders: true,
        ..Quirks::default()
    };
    let (live, setup) = live_on_a_tcp_head(FRAMES, true, quirks, &[]);
    succeeded(live);
    let (seq, dir) = (&setup.seq, setup.dir.path());
    let encoders = dir.join("encoders.csv");
    let mut text = String::from("frame,left_yaw_deg,right_yaw_deg\n");
    for i in 0..FRAMES {
        let (l, r) = encoder_yaws_udeg(i);
        text += &format!(
            "{i},{:.6},{:.6}\n",
            f64::from(l) * 1e-6,
            f64::from(r) * 1e-6
        );
    }
    std::fs::write(&encoders, text).unwrap();
    let (left, right, calib) = (seq.join("left"), seq.join("right"), seq.join("calib.toml"));
    let run = |extra: &[&str], out: &Path| {
        let mut args = vec![
            "run",
            "--left",
            left.to_str().unwrap(),
            "--right",
            right.to_str().unwrap(),
            "--calib",
            calib.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let done = stereocal(&args);
        succeeded(done);
        filtered_verges(&out.join("verge.csv"))
    };
    let with = run(
        &["--encoders", encoders.to_str().unwrap()],
        &dir.join("with"),
    );
    let without = run(&[], &dir.join("without"));
    let live = filtered_verges(&setup.out_dir().join("verge.csv"));
    assert_eq!(live, with, "live takes the packets as run takes the CSV");
    assert_ne!(with, without, "the readings moved the filter");
}

#[test]
fn live_needs_exactly_one_link() {
    let out = stereocal(&[
        "live", "--calib", "c.toml", "--width", "64", "--height", "64",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--serial"));
}
