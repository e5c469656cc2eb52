//! The firmware ELF on a simulated soft-core machine, `qemu-system-riscv32 -machine virt` or
//! the SoC in the loop ([`MachineConfig::soc`]), as a [`Link`] with a [`FrameInput`].
//!
//! [`MachineDevice::start`] writes the pairs into a frame-grabber file, starts the machine
//! with that file loaded at the soft-core's frame region and the UART on a Unix socket, and
//! connects to the socket. From then on it is a link like any other: the host driver says Hello, writes
//! the configuration, sets `CONTROL.ENABLE`, and reads the frames' packets. The command line:
//!
//! ```text
//! qemu-system-riscv32 -machine virt -m 128M -bios none -display none -monitor none
//!     -kernel ELF -chardev socket,id=uart,path=DIR/uart.sock,server=on,wait=on
//!     -serial chardev:uart -device loader,file=DIR/frames.bin,addr=0x81000000
//!     [-icount shift=0]
//! ```
//! `wait=on` holds the machine until the host is connected, so no byte is lost; a socket and
//! not `-nographic`, whose monitor multiplexer eats `0x01` bytes. `-icount shift=0` (with
//! [`MachineConfig::count_instructions`]) makes `minstret` count retired instructions, one per
//! nanosecond of virtual time, so instruction counts are the same on every run.
//!
//! Every byte the UART sends is kept in a transcript. The run ends with
//! [`MachineDevice::finish`] (read to the end, wait for the firmware's exit through the
//! `sifive_test` finisher) or, on any error, [`MachineDevice::abort`]; dropping the device
//! kills the machine, so no error path leaves an emulator or a simulator behind.

use std::io::{self, Read};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use stereocal_firmware::softcore::frame_input::{
    FLAG_COUNT_INSTRUCTIONS, FLAG_WIRED_CAMERAS, VIRT_FRAME_REGION,
};

use super::input::PairDigest;
use super::{FirmwareExit, GrabberInput, HilError, TimeoutKind};
use stereocal::link::{FrameInput, Link, LinkError, Recording, StreamLink, UnixLink};

/// The emulator, found on `PATH` unless [`MachineConfig::qemu`] says otherwise.
pub const DEFAULT_QEMU: &str = "qemu-system-riscv32";

/// How often the host looks again at the socket (while QEMU starts) or the process (while it ends).
const POLL: Duration = Duration::from_millis(10);
/// How long a firmware that failed gets to end the simulation itself before it is killed:
/// its exit code says more than a kill does.
const ABORT_GRACE: Duration = Duration::from_secs(1);
/// How long [`MachineDevice::abort`] reads the bytes left in the socket.
const ABORT_DRAIN: Duration = Duration::from_millis(200);
/// Bytes asked of the socket per read when draining it.
const READ_CHUNK: usize = 64 * 1024;

/// The timeouts of a run; an error names the one that fired ([`TimeoutKind`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MachineTimeouts {
    /// QEMU to open its UART socket.
    pub startup: Duration,
    /// One answer or one frame pair. A 640x480 pair takes a few seconds under QEMU's
    /// translator on this project's 2-core machines; the default leaves room for a loaded
    /// machine and `-icount`.
    pub answer: Duration,
    /// The firmware to end the simulation after the last frame.
    pub exit: Duration,
    /// The device to send anything at all. A healthy firmware is never quiet this long: its
    /// stream engine sends each frame's packets as the rows complete, and `hil` prints the
    /// longest silence of every run (well under a second under QEMU at 640x480); a device
    /// silent this long hangs, and the run ends with that error, once.
    pub silence: Duration,
}

impl Default for MachineTimeouts {
    fn default() -> Self {
        Self {
            startup: Duration::from_secs(10),
            answer: Duration::from_secs(120),
            exit: Duration::from_secs(30),
            silence: Duration::from_secs(10),
        }
    }
}

impl MachineTimeouts {
    /// The SoC in the loop's: an hour for an answer and for silence. A 640x480 pair is
    /// minutes of simulation there, and the board itself ends a firmware that hangs (its
    /// watchdog, after twenty line times in which nothing moved), so the host's own limits
    /// only catch a simulator that stopped.
    pub fn soc() -> Self {
        Self {
            answer: Duration::from_secs(3600),
            silence: Duration::from_secs(3600),
            ..Self::default()
        }
    }
}

/// How to run the firmware.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MachineConfig {
    /// The QEMU binary.
    pub qemu: PathBuf,
    /// The firmware ELF (`target/riscv32imc-unknown-none-elf/release/stereocal-firmware`).
    pub elf: PathBuf,
    /// Run with `-icount shift=0` and have the firmware log every image's instruction counts.
    pub count_instructions: bool,
    /// Run the ELF on the SoC in the loop instead of QEMU: the simulator that `cargo build
    /// --release -p stereocal-hil --bin sc-soc-sim` builds as `target/release/sc-soc-sim` (a
    /// real RV32IMAC core, VexRiscv, and both channels' `sc_fabric` on its bus, under
    /// Verilator, with the `virt` machine's RAM, UART and finisher). It takes the same ELF
    /// and frame file and speaks on the same kind of socket; the frame file says the cameras
    /// are wired (`FLAG_WIRED_CAMERAS`), so the firmware drives the real fabric and the
    /// harness's cameras send the images. Its `minstret` counts retired instructions without
    /// `-icount`.
    pub soc: Option<PathBuf>,
    /// On the SoC: the cameras' pixel clock, one clock in this many; `None` keeps the board's
    /// default (32, the stream engine's pace).
    pub pixel_clock_divider: Option<u32>,
    /// The timeouts.
    pub timeouts: MachineTimeouts,
}

impl MachineConfig {
    /// The firmware at `elf`, the default QEMU and timeouts, no instruction counts.
    pub fn new(elf: impl Into<PathBuf>) -> Self {
        Self {
            qemu: DEFAULT_QEMU.into(),
            elf: elf.into(),
            count_instructions: false,
            soc: None,
            pixel_clock_divider: None,
            timeouts: MachineTimeouts::default(),
        }
    }
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MachineEnd {
    /// The machine's exit status, read as the firmware's exit code.
    pub exit: FirmwareExit,
    /// Every byte the firmware sent on its UART.
    pub transcript: Vec<u8>,
    /// What the machine printed on stderr.
    pub stderr: String,
    /// The longest the device was silent while the host waited for it.
    pub longest_silence: Duration,
}

/// The machine's process; dropping it kills a machine that is still running.
struct Process {
    child: Child,
    stderr: Option<JoinHandle<String>>,
}

impl Process {
    /// How QEMU ended, if it has.
    fn try_exit(&mut self) -> Option<FirmwareExit> {
        match self.child.try_wait() {
            Ok(Some(status)) => Some(FirmwareExit::from_status(status)),
            Ok(None) => None,
            // The child cannot be waited for: it is not running as far as we can tell.
            Err(_) => Some(FirmwareExit::Signal),
        }
    }

    /// Waits for QEMU to end until `deadline`.
    fn wait_until(&mut self, deadline: Instant) -> Option<FirmwareExit> {
        loop {
            if let Some(exit) = self.try_exit() {
                return Some(exit);
            }
            if Instant::now() >= deadline {
                return None;
            }
            std::thread::sleep(POLL);
        }
    }

    /// Kills QEMU (if it still runs) and reaps it.
    fn kill(&mut self) -> FirmwareExit {
        if let Some(exit) = self.try_exit() {
            return exit;
        }
        // A kill can only fail when the process is already gone; `wait` reaps it either way.
        let _ = self.child.kill();
        match self.child.wait() {
            Ok(status) => FirmwareExit::from_status(status),
            Err(_) => FirmwareExit::Signal,
        }
    }

    /// What QEMU printed on stderr, less its note that it waits for the socket's client
    /// (printed on every run); only call once it has ended (the reader runs to EOF).
    fn stderr(&mut self) -> String {
        let text = self
            .stderr
            .take()
            .and_then(|reader| reader.join().ok())
            .unwrap_or_default();
        text.lines()
            .filter(|line| !line.contains("QEMU waiting for connection"))
            .collect::<Vec<_>>()
            .join("\n")
    }
}

impl Drop for Process {
    fn drop(&mut self) {
        self.kill();
    }
}

/// The firmware on a machine (QEMU or the SoC simulator), connected over the UART socket.
pub struct MachineDevice {
    // Field order is drop order: the link closes, the machine is killed, then the directory
    // with the socket and the frame file goes.
    link: Recording<UnixLink>,
    process: Process,
    loaded: Vec<PairDigest>,
    submitted: usize,
    timeouts: MachineTimeouts,
    /// When the host began waiting without getting a byte since.
    quiet_since: Option<Instant>,
    /// The longest silence so far.
    longest_silence: Duration,
    /// Set once the device has been silent for [`MachineTimeouts::silence`].
    silent: Option<Duration>,
    _dir: tempfile::TempDir,
}

impl MachineDevice {
    /// Writes `input` into a frame-grabber file, starts QEMU on `config.elf` with it and
    /// connects to the UART. The firmware then waits for the host's Hello and configuration.
    pub fn start(config: &MachineConfig, input: &GrabberInput) -> Result<Self, HilError> {
        let elf_readable = std::fs::File::open(&config.elf).map(drop);
        elf_readable.map_err(|source| HilError::File {
            path: config.elf.clone(),
            source,
        })?;
        let dir = tempfile::Builder::new()
            .prefix("stereocal-hil-")
            .tempdir()
            .map_err(|source| HilError::File {
                path: std::env::temp_dir(),
                source,
            })?;
        let frames = dir.path().join("frames.bin");
        let mut flags = 0;
        if config.count_instructions {
            flags |= FLAG_COUNT_INSTRUCTIONS;
        }
        if config.soc.is_some() {
            flags |= FLAG_WIRED_CAMERAS;
        }
        std::fs::write(&frames, input.to_bytes(flags)).map_err(|source| HilError::File {
            path: frames.clone(),
            source,
        })?;
        let socket = dir.path().join("uart.sock");

        let mut command = match &config.soc {
            Some(sim) => soc_command(sim, config, &socket, &frames),
            None => qemu_command(config, &socket, &frames),
        };
        let program = config.soc.as_ref().unwrap_or(&config.qemu);
        let mut child = command
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|source| HilError::Spawn {
                program: program.clone(),
                source,
            })?;
        let stderr = child.stderr.take().map(|mut pipe| {
            std::thread::spawn(move || {
                let mut text = String::new();
                // Whatever could be read is what the machine said; a broken pipe ends it.
                let _ = pipe.read_to_string(&mut text);
                text
            })
        });
        let mut process = Process { child, stderr };
        let machine = if config.soc.is_some() {
            "the SoC simulator"
        } else {
            "QEMU"
        };

        let deadline = Instant::now() + config.timeouts.startup;
        let stream = loop {
            if let Some(exit) = process.try_exit() {
                return Err(HilError::EndedEarly {
                    exit,
                    stderr: process.stderr(),
                });
            }
            match UnixStream::connect(&socket) {
                Ok(stream) => break stream,
                Err(_) if Instant::now() < deadline => std::thread::sleep(POLL),
                Err(_) => {
                    return Err(HilError::Timeout {
                        kind: TimeoutKind::Startup,
                        limit: config.timeouts.startup,
                        waiting_for: format!(
                            "{machine} to open its UART socket {}",
                            socket.display()
                        ),
                        log: String::new(),
                    })
                }
            }
        };
        Ok(Self {
            link: Recording::new(StreamLink::from_stream(
                stream,
                format!("{machine} UART {}", socket.display()),
            )),
            process,
            loaded: input.digests.clone(),
            submitted: 0,
            timeouts: config.timeouts,
            quiet_since: None,
            longest_silence: Duration::ZERO,
            silent: None,
            _dir: dir,
        })
    }

    /// How long the device had been silent when it was found hung, if it was (see
    /// [`Link::recv`] of this type).
    pub fn silent_for(&self) -> Option<Duration> {
        self.silent
    }

    fn hung(&self, silent: Duration) -> LinkError {
        LinkError::Io {
            link: self.link.inner().name().into(),
            source: io::Error::new(
                io::ErrorKind::TimedOut,
                format!("no byte for {silent:?}: the firmware hangs or the machine stopped"),
            ),
        }
    }

    /// Ends a run that went well: reads the UART to its end and waits for the firmware to
    /// end the simulation ([`MachineTimeouts::exit`]).
    pub fn finish(mut self) -> Result<MachineEnd, HilError> {
        let limit = self.timeouts.exit;
        let deadline = Instant::now() + limit;
        let timeout = |waiting_for: &str| HilError::Timeout {
            kind: TimeoutKind::Exit,
            limit,
            waiting_for: waiting_for.into(),
            log: String::new(),
        };
        let mut buf = vec![0; READ_CHUNK];
        loop {
            match self.recv(&mut buf, deadline) {
                Ok(_) => {}
                Err(LinkError::Closed { .. }) => break,
                Err(LinkError::Timeout { .. }) => {
                    return Err(timeout(
                        "the firmware to close its UART after the last frame",
                    ))
                }
                Err(e) => return Err(e.into()),
            }
        }
        let exit = self
            .process
            .wait_until(deadline)
            .ok_or_else(|| timeout("QEMU to exit after its UART closed"))?;
        Ok(MachineEnd {
            exit,
            transcript: self.link.take_received(),
            stderr: self.process.stderr(),
            longest_silence: self.longest_silence,
        })
    }

    /// Ends a run that failed: gives a failing firmware a moment to end the simulation with
    /// its own exit code, kills QEMU otherwise, and keeps the bytes it had sent.
    pub fn abort(mut self) -> MachineEnd {
        let exit = self
            .process
            .wait_until(Instant::now() + ABORT_GRACE)
            .unwrap_or_else(|| self.process.kill());
        let deadline = Instant::now() + ABORT_DRAIN;
        let mut buf = vec![0; READ_CHUNK];
        while self.recv(&mut buf, deadline).is_ok() {}
        MachineEnd {
            exit,
            transcript: self.link.take_received(),
            stderr: self.process.stderr(),
            longest_silence: self.longest_silence,
        }
    }
}

/// A path as a QEMU option value: a comma there would end the value, `,,` is a literal one.
fn option_value(path: &Path) -> String {
    path.display().to_string().replace(',', ",,")
}

impl Link for MachineDevice {
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.link.send(bytes)
    }

    /// A device that sends nothing for [`MachineTimeouts::silence`] hangs (or its machine
    /// stopped): from then on every receive fails at once with an error, not a timeout, so
    /// the session stops instead of waiting its answer timeout for every remaining frame.
    fn recv(&mut self, buf: &mut [u8], deadline: Instant) -> Result<usize, LinkError> {
        if let Some(silent) = self.silent {
            return Err(self.hung(silent));
        }
        // Silence starts when the host begins to wait after the last byte it got (not at
        // that byte: the host may have been busy since, with bytes waiting in the socket) and
        // goes on across receives that time out.
        let since = *self.quiet_since.get_or_insert_with(Instant::now);
        let watch = since + self.timeouts.silence;
        let result = self.link.recv(buf, deadline.min(watch));
        let now = Instant::now();
        self.longest_silence = self.longest_silence.max(now - since);
        match result {
            Ok(n) => {
                self.quiet_since = None;
                Ok(n)
            }
            Err(LinkError::Timeout { .. }) if now >= watch => {
                let silent = now - since;
                self.silent = Some(silent);
                Err(self.hung(silent))
            }
            Err(e) => Err(e),
        }
    }

    fn answer_timeout(&self) -> Duration {
        self.timeouts.answer
    }
}

impl FrameInput for MachineDevice {
    /// The pairs were loaded at boot; this only checks that the host asks for the pair the
    /// firmware will run next, so host records and device frames cannot drift apart.
    fn submit_pair(
        &mut self,
        left: &[u8],
        right: &[u8],
        timestamp_us: u64,
    ) -> Result<(), LinkError> {
        let digest = PairDigest::of(left, right, timestamp_us);
        if self.loaded.get(self.submitted) != Some(&digest) {
            return Err(LinkError::Io {
                link: self.link.inner().name().into(),
                source: io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!(
                        "pair {} is not the one loaded into the frame region at boot \
                         ({} pairs were loaded)",
                        self.submitted,
                        self.loaded.len()
                    ),
                ),
            });
        }
        self.submitted += 1;
        Ok(())
    }
}

/// QEMU's command line (the module docs).
fn qemu_command(config: &MachineConfig, socket: &Path, frames: &Path) -> Command {
    let mut command = Command::new(&config.qemu);
    command
        .args(["-machine", "virt", "-m", "128M", "-bios", "none"])
        .args(["-display", "none", "-monitor", "none"])
        .arg("-kernel")
        .arg(&config.elf)
        .arg("-chardev")
        .arg(format!(
            "socket,id=uart,path={},server=on,wait=on",
            option_value(socket)
        ))
        .args(["-serial", "chardev:uart"])
        .arg("-device")
        .arg(format!(
            "loader,file={},addr={VIRT_FRAME_REGION:#x}",
            option_value(frames)
        ));
    if config.count_instructions {
        command.args(["-icount", "shift=0"]);
    }
    command
}

/// The SoC simulator's command line (`hdl-interface/soc/sim/sc_soc_sim.cpp`): the same ELF,
/// frame file and socket as QEMU's.
fn soc_command(sim: &Path, config: &MachineConfig, socket: &Path, frames: &Path) -> Command {
    let mut command = Command::new(sim);
    command
        .arg("--elf")
        .arg(&config.elf)
        .arg("--uart")
        .arg(socket)
        .arg("--load")
        .arg(format!("{}@{VIRT_FRAME_REGION:#x}", frames.display()))
        .arg("--frames")
        .arg(frames);
    if let Some(divider) = config.pixel_clock_divider {
        command
            .arg("--pixel-clock-divider")
            .arg(divider.to_string());
    }
    command
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn commas_in_paths_are_doubled_for_qemu() {
        assert_eq!(option_value(Path::new("/tmp/a,b/f")), "/tmp/a,,b/f");
    }

    #[test]
    fn a_missing_emulator_is_named() {
        let elf = tempfile::NamedTempFile::new().unwrap();
        let config = MachineConfig {
            qemu: "/nonexistent/qemu-system-riscv32".into(),
            ..MachineConfig::new(elf.path())
        };
        let err = MachineDevice::start(&config, &GrabberInput::new(4, 2))
            .err()
            .unwrap();
        assert!(matches!(err, HilError::Spawn { .. }), "{err}");
        assert!(err.to_string().contains("qemu-system-misc"), "{err}");
    }
}
