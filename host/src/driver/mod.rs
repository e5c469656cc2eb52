//! The host side of the link: Hello, configuration, and camera frames reassembled from wire
//! packets into [`FeatureFrame`](crate::features::FeatureFrame)s.
//!
//! ```no_run
//! # use std::time::Duration;
//! # use stereocal::driver::{Driver, PairOutcome};
//! # use stereocal::link::TcpLink;
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let mut driver = Driver::new(TcpLink::tcp("127.0.0.1:4444")?);
//! let t = Duration::from_secs(2);
//! driver.hello(t)?;
//! driver.configure(&stereocal_hdl::FabricConfig::default(), t)?;
//! match driver.next_pair(t)? {
//!     PairOutcome::Pair { left, right } => { /* each Delivered or Damaged */ }
//!     PairOutcome::Single(lone) => { /* its partner was lost without a trace */ }
//! }
//! println!("{:?}", driver.stats());
//! # Ok(()) }
//! ```
//!
//! Every byte the link delivers goes through one [`Accumulator`]; decoded packets go to the
//! frame assembler (`assembler.rs`, the state machine with the damage rules). The driver
//! only adds requests (Hello, register writes and reads), deadlines and queues.

mod assembler;
mod config;
mod damage;
mod error;
mod gradients;
mod keypoint;
mod salvage;
mod stats;

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use stereocal_hdl::{FabricConfig, Registers};
use stereocal_wire::{
    encode, Accumulator, Camera, EncodersRepr, ErrorReportRepr, FeedResult, HelloRepr, PacketRepr,
    RegisterReadRepr, RegisterWriteRepr, Source, MAX_ENCODED_LEN, MAX_PROTECTED_LEN,
    PROTOCOL_VERSION,
};

pub use assembler::{DamagedFrame, FrameOutcome, LogFrame, ReceivedFrame};
pub use config::writes as register_writes;
pub use damage::{ContentError, Damage, DamageCounts, PacketRef};
pub use error::{DriverError, Waiting};
pub use keypoint::keypoint;
pub use salvage::{Salvage, MAX_LOST_FRACTION};
pub use stats::LinkStats;

use crate::link::{Link, LinkError};
use crate::subpixel::SubpixelConfig;
use assembler::{Event, FrameAssembler};

/// Bytes asked of the link per receive call.
const RECEIVE_CHUNK: usize = 64 * 1024;
/// Log frames kept when nobody takes them; older ones are discarded and counted.
const LOG_QUEUE_LIMIT: usize = 65_536;
/// Capabilities the host announces: it takes everything the device can send.
const HOST_CAPABILITIES: stereocal_wire::Capabilities = stereocal_wire::Capabilities(
    stereocal_wire::Capabilities::POINTS.0
        | stereocal_wire::Capabilities::SOBEL_ROWS.0
        | stereocal_wire::Capabilities::SOBEL_PATCHES.0
        | stereocal_wire::Capabilities::LOG.0
        | stereocal_wire::Capabilities::REGISTERS.0,
);

/// Both cameras of one frame, or one camera whose partner left no trace.
#[derive(Debug, Clone, PartialEq)]
pub enum PairOutcome {
    /// Left and right of the same frame id, each delivered or damaged.
    Pair {
        /// The left camera's frame.
        left: FrameOutcome,
        /// The right camera's frame.
        right: FrameOutcome,
    },
    /// A frame whose partner never arrived (or an unknown camera value).
    Single(FrameOutcome),
}

impl PairOutcome {
    /// The frame id.
    pub fn frame_id(&self) -> u32 {
        match self {
            Self::Pair { left, .. } => left.frame_id(),
            Self::Single(f) => f.frame_id(),
        }
    }

    /// Link bytes of the pair (both frames, as received).
    pub fn wire_bytes(&self) -> u64 {
        match self {
            Self::Pair { left, right } => left.wire_bytes() + right.wire_bytes(),
            Self::Single(f) => f.wire_bytes(),
        }
    }

    /// Both frames, when both were delivered.
    pub fn delivered(self) -> Option<(ReceivedFrame, ReceivedFrame)> {
        match self {
            Self::Pair { left, right } => Some((left.delivered()?, right.delivered()?)),
            Self::Single(_) => None,
        }
    }
}

/// Unclaimed device `ErrorReport`s kept (the newest).
const MAX_DEVICE_ERRORS: usize = 64;

/// Unclaimed `Encoders` readings kept (the newest): two seconds of captures at 30 fps, far
/// more than the pairs a session has in flight, so a reading waits for its pair however the
/// link interleaves them, and a head whose readings nobody takes cannot grow the host.
const MAX_ENCODER_READINGS: usize = 64;

/// An `ErrorReport` the device sent outside a request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DeviceReport {
    /// Sequence number of the packet, in the device's control source.
    pub seq: u16,
    /// The report.
    pub report: ErrorReportRepr,
}

/// The host driver over a link `L`.
pub struct Driver<L: Link> {
    link: L,
    accumulator: Box<Accumulator<{ MAX_PROTECTED_LEN - 1 }>>,
    /// Ask the device for forward error correction in `Hello`.
    request_fec: bool,
    rx: Vec<u8>,
    rx_pos: usize,
    rx_len: usize,
    /// Link bytes consumed since the last complete link frame.
    wire_pending: usize,
    assembler: FrameAssembler,
    tx: Vec<u8>,
    tx_seq: u16,
    frames: VecDeque<FrameOutcome>,
    pending_pair: Option<FrameOutcome>,
    hellos: VecDeque<HelloRepr>,
    register_values: VecDeque<(u16, u32)>,
    device_errors: VecDeque<DeviceReport>,
    logs: VecDeque<LogFrame>,
    encoders: VecDeque<EncodersRepr>,
}

impl<L: Link> Driver<L> {
    /// A driver over `link`; nothing is sent yet.
    pub fn new(link: L) -> Self {
        Self {
            link,
            accumulator: Box::new(Accumulator::new()),
            request_fec: false,
            rx: vec![0; RECEIVE_CHUNK],
            rx_pos: 0,
            rx_len: 0,
            wire_pending: 0,
            assembler: FrameAssembler::new(Some(SubpixelConfig::default().reach_px())),
            tx: vec![0; MAX_ENCODED_LEN],
            tx_seq: 0,
            frames: VecDeque::new(),
            pending_pair: None,
            hellos: VecDeque::new(),
            register_values: VecDeque::new(),
            device_errors: VecDeque::new(),
            encoders: VecDeque::new(),
            logs: VecDeque::new(),
        }
    }

    /// The link (e.g. to hand the in-process device its images).
    pub fn link(&self) -> &L {
        &self.link
    }

    /// The link, mutably.
    pub fn link_mut(&mut self) -> &mut L {
        &mut self.link
    }

    /// Gives the link back.
    pub fn into_link(self) -> L {
        self.link
    }

    /// Counters since the driver was created.
    pub fn stats(&self) -> &LinkStats {
        &self.assembler.stats
    }

    /// The device's log frames received so far (oldest first), emptying the queue.
    pub fn take_logs(&mut self) -> Vec<LogFrame> {
        self.logs.drain(..).collect()
    }

    /// `ErrorReport`s the device sent outside a request, emptying the list.
    pub fn take_device_errors(&mut self) -> Vec<DeviceReport> {
        self.device_errors.drain(..).collect()
    }

    /// The head's `Encoders` reading of capture `frame_id`, if it arrived; readings of this
    /// and older captures (ids wrap: within half the id space behind) are dropped, as no pair
    /// will ask for them again.
    pub fn take_encoders(&mut self, frame_id: u32) -> Option<EncodersRepr> {
        let mut found = None;
        self.encoders.retain(|e| {
            if e.frame_id == frame_id {
                found = Some(*e);
            }
            frame_id.wrapping_sub(e.frame_id) > u32::MAX / 2
        });
        found
    }

    /// Whether the next [`Driver::hello`] asks the device to protect its link frames by
    /// forward error correction ([`stereocal_wire::fec`]): 7.7 % more bytes on the link, and
    /// up to 8 damaged bytes in each 255 repaired. A device that can answers with
    /// [`Capabilities::FEC`](stereocal_wire::Capabilities::FEC) and protects every link frame
    /// after its answer; one that cannot keeps sending plain frames, and so does the host's
    /// side of the link.
    pub fn request_fec(&mut self, on: bool) {
        self.request_fec = on;
    }

    /// The largest fraction of a camera frame's keypoints the link may cost it and the frame
    /// still be delivered (salvaged); [`MAX_LOST_FRACTION`] unless set. A larger limit
    /// delivers more frames of a noisy link, whose estimates then stray further from what the
    /// intact frames would give.
    pub fn set_loss_limit(&mut self, fraction: f64) {
        self.assembler.loss_limit = Some(fraction.clamp(0.0, 1.0));
    }

    /// The estimator's sub-pixel refinement reach ([`SubpixelConfig::reach_px`]; `None` when
    /// it does not refine): a salvaged frame's keypoints with a lost full-resolution pixel
    /// within it count against the loss limit, since their matches cannot be refined. The
    /// default refinement's unless set.
    pub fn set_refinement_reach(&mut self, reach: Option<usize>) {
        self.assembler.refinement_reach = reach;
    }

    /// Whether the device's link frames are taken as protected by forward error correction.
    pub fn fec(&self) -> bool {
        self.accumulator.fec()
    }

    /// Sends the host's `Hello` and waits for the device's (one already received counts).
    pub fn hello(&mut self, timeout: Duration) -> Result<HelloRepr, DriverError> {
        let fec = if self.request_fec {
            stereocal_wire::Capabilities::FEC
        } else {
            stereocal_wire::Capabilities(0)
        };
        self.send(&PacketRepr::Hello(HelloRepr {
            version: PROTOCOL_VERSION,
            capabilities: HOST_CAPABILITIES | fec,
        }))?;
        let deadline = Instant::now() + timeout;
        let hello = loop {
            if let Some(hello) = self.hellos.pop_front() {
                break hello;
            }
            self.pump(deadline, timeout, Waiting::Hello)?;
        };
        if hello.version < PROTOCOL_VERSION {
            return Err(DriverError::Version {
                device: hello.version,
                host: PROTOCOL_VERSION,
            });
        }
        Ok(hello)
    }

    /// Writes one register (no answer expected).
    pub fn write_register(&mut self, addr: u16, value: u32) -> Result<(), DriverError> {
        self.send(&PacketRepr::RegisterWrite(RegisterWriteRepr {
            addr,
            value,
        }))
    }

    /// Reads one register.
    pub fn read_register(&mut self, addr: u16, timeout: Duration) -> Result<u32, DriverError> {
        self.register_values.clear();
        self.send(&PacketRepr::RegisterRead(RegisterReadRepr { addr }))?;
        let deadline = Instant::now() + timeout;
        // Counted, not indexed: the list drops its oldest reports when full, so an index taken
        // now could point past a report that arrives during the request.
        let reported_before = self.assembler.stats.device_errors;
        loop {
            if let Some(i) = self.register_values.iter().position(|&(a, _)| a == addr) {
                let (_, value) = self.register_values.remove(i).unwrap_or((addr, 0));
                return Ok(value);
            }
            let since = (self.assembler.stats.device_errors - reported_before) as usize;
            // The first report since the request (the oldest kept, had more arrived than the
            // list holds) answers it; it and the later ones leave the list.
            let first = self.device_errors.len().saturating_sub(since);
            if let Some(e) = self.device_errors.get(first).copied() {
                self.device_errors.truncate(first);
                return Err(DriverError::Device {
                    code: e.report.code,
                    detail: e.report.detail,
                    seq: e.seq,
                });
            }
            self.pump(deadline, timeout, Waiting::RegisterValue { addr })?;
        }
    }

    /// Writes the fabric configuration (width, height, octaves, thresholds, output mode)
    /// and reads every written register back. Nothing is sent when `config` is invalid.
    pub fn configure(
        &mut self,
        config: &FabricConfig,
        timeout: Duration,
    ) -> Result<(), DriverError> {
        let plan = config::plan(config).map_err(DriverError::Config)?;
        for &(addr, value) in &plan.writes {
            self.write_register(addr, value)?;
        }
        for &(addr, expected) in &plan.read_back {
            let read = self.read_register(addr, timeout)?;
            if read != expected {
                return Err(DriverError::ReadBack {
                    addr,
                    written: expected,
                    read,
                });
            }
        }
        Ok(())
    }

    /// Sets `CONTROL.ENABLE`: the device starts taking frames.
    pub fn enable(&mut self) -> Result<(), DriverError> {
        let writes =
            config::writes(|bus| bus.set_control_enable(true)).map_err(DriverError::Config)?;
        for (addr, value) in writes {
            self.write_register(addr, value)?;
        }
        Ok(())
    }

    /// The next camera frame, delivered or damaged.
    pub fn next_frame(&mut self, timeout: Duration) -> Result<FrameOutcome, DriverError> {
        if let Some(frame) = self.pending_pair.take() {
            return Ok(frame);
        }
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(frame) = self.frames.pop_front() {
                return Ok(frame);
            }
            let waiting = Waiting::Frame { in_progress: None };
            self.pump(deadline, timeout, waiting)?;
        }
    }

    /// The next frame pair: frames are paired by frame id, left with right. A frame whose
    /// partner left no trace (both its packets and its FrameStart were lost) comes alone.
    pub fn next_pair(&mut self, timeout: Duration) -> Result<PairOutcome, DriverError> {
        let deadline = Instant::now() + timeout;
        let first = self.next_frame(timeout)?;
        if !matches!(first.camera(), Camera::Left | Camera::Right) {
            return Ok(PairOutcome::Single(first));
        }
        let second = self.next_frame(deadline.saturating_duration_since(Instant::now()))?;
        let partners = second.frame_id() == first.frame_id()
            && matches!(
                (first.camera(), second.camera()),
                (Camera::Left, Camera::Right) | (Camera::Right, Camera::Left)
            );
        if !partners {
            self.pending_pair = Some(second);
            return Ok(PairOutcome::Single(first));
        }
        let (left, right) = if first.camera() == Camera::Left {
            (first, second)
        } else {
            (second, first)
        };
        Ok(PairOutcome::Pair { left, right })
    }

    /// Encodes and sends one request.
    fn send(&mut self, packet: &PacketRepr<'_>) -> Result<(), DriverError> {
        let frame = encode(Source::Control, self.tx_seq, packet, &mut self.tx)
            .map_err(DriverError::Encode)?;
        self.link.send(frame).map_err(DriverError::Link)?;
        self.assembler.stats.bytes_sent += frame.len() as u64;
        self.tx_seq = self.tx_seq.wrapping_add(1);
        Ok(())
    }

    /// Decodes buffered bytes, or receives more, until at least one event was sorted into
    /// its queue.
    fn pump(
        &mut self,
        deadline: Instant,
        timeout: Duration,
        waiting: Waiting,
    ) -> Result<(), DriverError> {
        loop {
            if self.decode_buffered() {
                return Ok(());
            }
            match self.link.recv(&mut self.rx, deadline) {
                Ok(n) => {
                    self.rx_pos = 0;
                    self.rx_len = n.min(self.rx.len());
                    self.assembler.stats.bytes_received += self.rx_len as u64;
                }
                Err(LinkError::Timeout { .. }) => {
                    // Bytes decoded while waiting may have opened a frame.
                    let waiting_for = match waiting {
                        Waiting::Frame { .. } => Waiting::Frame {
                            in_progress: self.assembler.in_progress(),
                        },
                        other => other,
                    };
                    return Err(DriverError::Timeout {
                        waiting_for,
                        timeout,
                    });
                }
                Err(e) => return Err(DriverError::Link(e)),
            }
        }
    }

    /// Feeds buffered bytes to the accumulator until an event comes out or the buffer is
    /// empty; returns whether an event came out.
    fn decode_buffered(&mut self) -> bool {
        while self.rx_pos < self.rx_len {
            let input = &self.rx[self.rx_pos..self.rx_len];
            let mut fec = None;
            let (rest_len, frame_len) = match self.accumulator.feed(input) {
                FeedResult::Consumed => (0, None),
                FeedResult::OverFull(rest) => {
                    let wire = self.wire_pending + input.len() - rest.len();
                    self.assembler.over_long(wire);
                    (rest.len(), Some(wire))
                }
                FeedResult::DecodeError {
                    error,
                    header,
                    remaining,
                } => {
                    let wire = self.wire_pending + input.len() - remaining.len();
                    self.assembler.undecodable(error, header, wire);
                    (remaining.len(), Some(wire))
                }
                FeedResult::Success {
                    header,
                    packet,
                    remaining,
                } => {
                    let wire = self.wire_pending + input.len() - remaining.len();
                    // The device's `Hello` says whether the link frames after it are
                    // protected: when the host asked and the device can.
                    fec = match packet {
                        PacketRepr::Hello(h) => Some(
                            self.request_fec
                                && h.capabilities.contains(stereocal_wire::Capabilities::FEC),
                        ),
                        _ => None,
                    };
                    self.assembler.packet(&header, &packet, wire);
                    (remaining.len(), Some(wire))
                }
            };
            if let Some(on) = fec {
                self.accumulator.set_fec(on);
            }
            self.assembler.stats.fec_blocks_repaired = self.accumulator.fec_blocks_repaired();
            let consumed = self.rx_len - self.rx_pos - rest_len;
            // Bytes of a link frame that is not complete yet count towards that frame.
            self.wire_pending = match frame_len {
                Some(_) => 0,
                None => self.wire_pending + consumed,
            };
            self.rx_pos = self.rx_len - rest_len;
            if self.sort_events() {
                return true;
            }
        }
        false
    }

    /// Moves the assembler's events into the driver's queues; whether there were any.
    fn sort_events(&mut self) -> bool {
        let mut any = false;
        while let Some(event) = self.assembler.pop_event() {
            any = true;
            match event {
                Event::Frame(f) => self.frames.push_back(f),
                Event::Hello(h) => self.hellos.push_back(h),
                Event::RegisterValue(v) => self.register_values.push_back((v.addr, v.value)),
                Event::Log(log) => {
                    if self.logs.len() >= LOG_QUEUE_LIMIT {
                        self.logs.pop_front();
                        self.assembler.stats.logs_discarded += 1;
                    }
                    self.logs.push_back(log);
                }
                Event::DeviceError { seq, report } => {
                    // A device that reports on every frame while nobody takes the reports
                    // must not grow the host without bound: the oldest go first.
                    if self.device_errors.len() >= MAX_DEVICE_ERRORS {
                        self.device_errors.pop_front();
                    }
                    self.device_errors.push_back(DeviceReport { seq, report })
                }
                Event::Encoders(e) => {
                    if self.encoders.len() >= MAX_ENCODER_READINGS {
                        self.encoders.pop_front();
                    }
                    self.encoders.push_back(e);
                }
            }
        }
        any
    }
}
