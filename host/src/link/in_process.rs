//! The device inside the host: the firmware's soft-core driver on the fabric's device model, one channel
//! per camera, called synchronously.
//!
//! This is the default link of `stereocal run/eval/demo`: the same firmware code as the ELF,
//! the same wire bytes as QEMU or a board, without a process or a socket in between. Images
//! go in through [`InProcessLink::submit_pair`]; the device's packets collect in an outbox
//! that [`Link::recv`] hands out. The fabric runs its fast path unless
//! [`InProcessLink::register_level`] asks for the clock-level model.
//!
//! The two cameras' channels run on two cores at once ([`InProcessLink::submit_pair`]) and
//! their packets are queued left camera first, as the soft-core sends them. Each channel's
//! fabric sends its frames on a link port of its own (its stream engine's outbox here),
//! numbered as the camera's wire source, so the bytes equal the soft-core's whichever channel
//! finishes first, and nothing rewrites a channel's frames.
//!
//! Register writes from the host go to both channels (the head's two fabrics are configured
//! alike); `Hello` and register reads are answered by the left channel, so each request gets
//! one answer, as from a single device.

use std::time::Instant;

use stereocal_firmware::driver::{Driver as Channel, DriverError as ChannelError, FrameSummary};
use stereocal_firmware::fabric::{FabricDevice, FabricModel};
use stereocal_firmware::framing::{ByteSink, PacketWriter};
use stereocal_hdl::regs::control;
use stereocal_hdl::RegisterBus;
use stereocal_wire::{Accumulator, Camera, EncodersRepr, FeedResult, PacketRepr, MAX_ENCODED_LEN};

use super::{Link, LinkError};

/// Name in errors.
const NAME: &str = "in-process";

/// One camera's channel at the fabric's full size (1280-pixel lines): the firmware's driver on
/// the registers of the fabric's device model, whose stream engine sends into an outbox.
type FullChannel = Channel<FabricDevice<FabricModel, 1280, Outbox>, 1280>;

/// The device's output, waiting for the host to read it.
#[derive(Debug, Default)]
struct Outbox {
    bytes: Vec<u8>,
    read: usize,
}

impl ByteSink for Outbox {
    fn write(&mut self, bytes: &[u8]) {
        self.bytes.extend_from_slice(bytes);
    }
}

impl Outbox {
    /// Empties the outbox and keeps its allocations.
    fn clear(&mut self) {
        self.bytes.clear();
        self.read = 0;
    }

    /// Moves `bytes` to the end of the outbox, leaving `bytes` empty. An outbox the host has
    /// read to the end trades buffers instead (see [`Self::take_into`]).
    fn append(&mut self, bytes: &mut Vec<u8>) {
        if self.read == self.bytes.len() {
            self.clear();
            std::mem::swap(&mut self.bytes, bytes);
        } else {
            self.bytes.append(bytes);
        }
    }

    /// Moves the unread bytes into `out`. An empty `out` trades buffers with the outbox
    /// instead: a pair is megabytes, and the buffers keep their sizes as they go round.
    fn take_into(&mut self, out: &mut Vec<u8>) {
        if out.is_empty() && self.read == 0 {
            std::mem::swap(out, &mut self.bytes);
        } else {
            out.extend_from_slice(self.bytes.get(self.read..).unwrap_or_default());
        }
        self.clear();
    }
}

/// The fabric model and the soft-core driver of both cameras, in this process.
pub struct InProcessLink {
    left: Box<FullChannel>,
    right: Box<FullChannel>,
    writer: PacketWriter<Outbox>,
    inbox: Box<Accumulator<{ MAX_ENCODED_LEN - 1 }>>,
}

impl InProcessLink {
    /// Both channels on the fabric's fast path (bit-exact with the register-level model).
    pub fn new() -> Result<Self, LinkError> {
        Self::with_model(FabricModel::fast)
    }

    /// Both channels on the register-level model (one clock per pixel; much slower).
    pub fn register_level() -> Result<Self, LinkError> {
        Self::with_model(FabricModel::register_level)
    }

    fn with_model(model: fn() -> FabricModel) -> Result<Self, LinkError> {
        Ok(Self {
            left: boxed_channel(Camera::Left, model)?,
            right: boxed_channel(Camera::Right, model)?,
            writer: PacketWriter::new(Outbox::default()),
            inbox: Box::new(Accumulator::new()),
        })
    }

    /// Runs one camera's image (raster order, 8-bit grey, the configured size) through its
    /// channel; the frame's packets wait in the outbox.
    pub fn submit(
        &mut self,
        camera: Camera,
        image: &[u8],
        timestamp_us: u64,
    ) -> Result<FrameSummary, LinkError> {
        let channel = match camera {
            Camera::Left => &mut self.left,
            Camera::Right => &mut self.right,
            Camera::Unknown(c) => {
                return Err(LinkError::Device(format!("no camera channel {c}")));
            }
        };
        let result = channel.process_frame(image, timestamp_us);
        self.writer
            .sink_mut()
            .append(&mut channel.bus_mut().link_mut().bytes);
        result.map_err(|e| channel_error(camera, &e))
    }

    /// Runs a stereo pair: the frame's packets of both cameras wait in the outbox, the left
    /// camera's first, the two frames carry the same frame id.
    ///
    /// The channels run concurrently, each fabric's stream engine into an outbox of its own,
    /// numbering its packets as its source; the two outboxes then join the link's as they are,
    /// left first: the
    /// bytes are those of running the two one after the other, as the soft-core does.
    /// Run one after the other, a left frame refused before its `FrameStart` (a wrong image
    /// size; register errors refuse both alike) would leave the right camera unrun and both
    /// frame numbers unused: images of different sizes therefore run one after the other, and
    /// any other failure leaves both channels past the frame, their frame numbers in step.
    /// What a failed channel sent stays in the outbox, beside the other channel's frame, as
    /// the soft-core sends on with the next camera after reporting a failure; the left
    /// failure is returned first.
    pub fn submit_pair(
        &mut self,
        left: &[u8],
        right: &[u8],
        timestamp_us: u64,
    ) -> Result<[FrameSummary; 2], LinkError> {
        if left.len() != right.len() {
            return Ok([
                self.submit(Camera::Left, left, timestamp_us)?,
                self.submit(Camera::Right, right, timestamp_us)?,
            ]);
        }
        let Self {
            left: left_channel,
            right: right_channel,
            writer,
            ..
        } = self;
        let (left_result, right_result) = rayon::join(
            || left_channel.process_frame(left, timestamp_us),
            || right_channel.process_frame(right, timestamp_us),
        );
        for channel in [left_channel, right_channel] {
            writer
                .sink_mut()
                .append(&mut channel.bus_mut().link_mut().bytes);
        }
        let left_summary = left_result.map_err(|e| channel_error(Camera::Left, &e))?;
        let right_summary = right_result.map_err(|e| channel_error(Camera::Right, &e))?;
        Ok([left_summary, right_summary])
    }

    /// Sends a reading of the head's joint encoders, as a head whose firmware reads them
    /// does: a control packet of the device, before or after the capture's camera frames.
    pub fn send_encoders(&mut self, reading: EncodersRepr) -> Result<(), LinkError> {
        self.writer
            .send(&PacketRepr::Encoders(reading))
            .map_err(|e| LinkError::Device(format!("encoders reading: {e}")))
    }

    /// Whether the host has set CONTROL.ENABLE: a head with its own cameras (the firmware's
    /// main loop, a board) starts grabbing then, so a stand-in for one waits for it.
    pub fn enabled(&mut self) -> bool {
        self.left.bus_mut().read_field(&control::ENABLE) != 0
    }

    /// Bytes the device sent that the host has not read yet.
    pub fn pending(&self) -> usize {
        self.writer.sink().bytes.len() - self.writer.sink().read
    }
}

/// Stack of the thread that builds a channel.
const BUILD_STACK: usize = 16 << 20;

/// Builds a channel on the heap.
///
/// A channel is about half a megabyte of fixed arrays (the firmware allocates nothing), and
/// an unoptimised build moves it through the stack a few times before it lands in the box:
/// more than a 2 MiB test thread has. A short-lived thread with a roomy stack builds it.
fn boxed_channel(
    camera: Camera,
    model: fn() -> FabricModel,
) -> Result<Box<FullChannel>, LinkError> {
    let builder = std::thread::Builder::new()
        .name("in-process channel".into())
        .stack_size(BUILD_STACK);
    let build = move || {
        let fabric = FabricDevice::with_link(model(), Outbox::default());
        Box::new(Channel::new(fabric, camera))
    };
    builder
        .spawn(build)
        .map_err(|e| LinkError::Device(format!("cannot start the {camera:?} channel: {e}")))?
        .join()
        .map_err(|_| LinkError::Device(format!("building the {camera:?} channel failed")))
}

fn channel_error(camera: Camera, e: &ChannelError) -> LinkError {
    LinkError::Device(format!("{camera:?} channel: {e}"))
}

impl Link for InProcessLink {
    /// Decodes the host's packets and lets the device answer them at once. Undecodable
    /// bytes are dropped, as the soft-core's receiver drops them.
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        let mut window = bytes;
        while !window.is_empty() {
            let (result, rest) = match self.inbox.feed(window) {
                FeedResult::Consumed => (Ok(()), &window[window.len()..]),
                FeedResult::OverFull(rest) => (Ok(()), rest),
                FeedResult::DecodeError { remaining, .. } => (Ok(()), remaining),
                FeedResult::Success {
                    packet, remaining, ..
                } => {
                    // Writes go to both channels; the left one answers every request.
                    if let PacketRepr::RegisterWrite(w) = packet {
                        self.right.write_register(w.addr, w.value);
                    }
                    let answered = self
                        .left
                        .handle_host_packet(&packet, &mut self.writer)
                        .map_err(|e| channel_error(Camera::Left, &e));
                    // A `Hello` sets the link's error correction; the right camera's frames
                    // take the same link.
                    let answered = match packet {
                        PacketRepr::Hello(_) => answered.and_then(|()| {
                            self.right
                                .set_fec(self.writer.fec())
                                .map_err(|e| channel_error(Camera::Right, &e))
                        }),
                        _ => answered,
                    };
                    (answered, remaining)
                }
            };
            result?;
            window = rest;
        }
        Ok(())
    }

    /// Moves every byte the device sent and the host has not read into `out` at once.
    fn take_sent(&mut self, out: &mut Vec<u8>) -> Result<(), LinkError> {
        self.writer.sink_mut().take_into(out);
        Ok(())
    }

    /// Hands out what the device sent. The device only runs when it is given work, so an
    /// empty outbox is a timeout at once: nothing can arrive by waiting.
    fn recv(&mut self, buf: &mut [u8], deadline: Instant) -> Result<usize, LinkError> {
        let _ = deadline;
        let outbox = self.writer.sink_mut();
        let pending = &outbox.bytes[outbox.read..];
        if pending.is_empty() {
            return Err(LinkError::Timeout {
                link: NAME.into(),
                waited: std::time::Duration::ZERO,
            });
        }
        let n = pending.len().min(buf.len());
        buf[..n].copy_from_slice(&pending[..n]);
        outbox.read += n;
        if outbox.read == outbox.bytes.len() {
            // Everything read: reuse the allocation for the next frame.
            outbox.clear();
        }
        Ok(n)
    }
}
