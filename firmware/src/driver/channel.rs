//! The driver of one camera channel: its fabric, its registers, its frame counter.

use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_hdl::{register_at, FabricConfig, PixelIn, RegisterBus, Registers};
use stereocal_wire::{
    Camera, Capabilities, ErrorCode, ErrorReportRepr, FrameEndFlags, FrameEndRepr, FrameStartRepr,
    HelloRepr, PacketRepr, PointBatchRepr, Records, RegisterValueRepr, SobelPatchRepr, SobelPixel,
    SobelRowsRepr, Source, PATCH_PIXELS, PROTOCOL_VERSION,
};

use crate::driver::error::DriverError;
use crate::driver::fifo_reader::FifoReader;
use crate::driver::numbering::Numbering;
use crate::driver::patch::{PatchQueue, PendingPatch, HALF};
use crate::driver::point_batch::{wire_point, PointBatch};
use crate::driver::sink::{ByteSink, PacketWriter};
use crate::driver::sobel_ring::{Completed, SobelRing};
use crate::fabric::config::MAX_OCTAVES;
use crate::fabric::{Config, Extremum, FrameError, Overflow, SobelRun};

/// What a channel can send, as announced in its `Hello`.
pub const CHANNEL_CAPABILITIES: Capabilities = Capabilities(
    Capabilities::POINTS.0
        | Capabilities::SOBEL_ROWS.0
        | Capabilities::SOBEL_PATCHES.0
        | Capabilities::REGISTERS.0
        | Capabilities::FEC.0,
);

/// What one frame produced and lost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameSummary {
    /// The frame's number (as in FrameStart/FrameEnd).
    pub frame_id: u32,
    /// Points sent in `PointBatch` packets.
    pub points: u32,
    /// `SobelRows` or `SobelPatch` packets sent.
    pub sobel_packets: u32,
    /// Records the fabric's FIFOs dropped.
    pub overflow: Overflow,
    /// Points that got no patch (their rows had left the ring, or the patch queue was full).
    pub patches_dropped: u32,
}

/// Per-frame state.
#[derive(Clone, Copy, Debug)]
struct FrameState {
    id: u32,
    mode: SobelOutput,
    sobel_scale: u8,
    /// Most pixels per `SobelRows` packet.
    row_segment: u16,
    points: u32,
    sobel_packets: u32,
    patches_dropped: u32,
}

/// Drives one camera channel: configures, arms, polls and drains its fabric through the
/// register map on `B` (offering the frame's pixels on its PIXEL_IN port), and sends what
/// comes out of the FIFOs as wire packets.
///
/// `B` is [`stereocal_hdl::Mmio`] next to a real fabric or a
/// [`crate::fabric::FabricDevice`] in software; the driver's code path is the same.
/// `W0` is the widest frame the driver's Sobel ring holds (the fabric's octave-0 line length).
/// The driver is large (the ring holds 32 rows per octave); on the host, box it.
pub struct Driver<B: RegisterBus + PixelIn, const W0: usize = 1280> {
    bus: B,
    capabilities: Capabilities,
    next_frame_id: u32,
    reader: FifoReader,
    output: FrameOutput<W0>,
}

/// Everything of a channel but its fabric and FIFO buffers: what turns the fabric's streams
/// into packets. Kept apart so a drain can hand it the entries it pops.
struct FrameOutput<const W0: usize> {
    camera: Camera,
    /// The channel's source (its camera's) and its packets' numbers.
    numbering: Numbering,
    frame: FrameState,
    ring: SobelRing<W0>,
    patches: PatchQueue,
    batch: PointBatch,
    patch: [SobelPixel; PATCH_PIXELS],
}

impl<B: RegisterBus + PixelIn, const W0: usize> Driver<B, W0> {
    /// A driver for `camera`'s fabric, reached through `bus` (its registers and PIXEL_IN).
    /// The first frame is number 0.
    pub fn new(bus: B, camera: Camera) -> Self {
        Self {
            bus,
            capabilities: CHANNEL_CAPABILITIES,
            next_frame_id: 0,
            reader: FifoReader::new(),
            output: FrameOutput {
                camera,
                numbering: Numbering::new(Source::channel(camera)),
                frame: FrameState {
                    id: 0,
                    mode: SobelOutput::Patches,
                    sobel_scale: 0,
                    row_segment: u16::MAX,
                    points: 0,
                    sobel_packets: 0,
                    patches_dropped: 0,
                },
                ring: SobelRing::new(),
                patches: PatchQueue::new(),
                batch: PointBatch::new(),
                patch: [SobelPixel::default(); PATCH_PIXELS],
            },
        }
    }

    /// Adds capability bits to the `Hello` answer (the soft-core adds `LOG`).
    pub fn with_capabilities(mut self, extra: Capabilities) -> Self {
        self.capabilities = self.capabilities | extra;
        self
    }

    /// The camera this channel serves.
    pub fn camera(&self) -> Camera {
        self.output.camera
    }

    /// The channel's source and the number its next packet will carry.
    pub fn numbering(&self) -> &Numbering {
        &self.output.numbering
    }

    /// The number the next frame will get.
    pub fn next_frame_id(&self) -> u32 {
        self.next_frame_id
    }

    /// The fabric's bus.
    pub fn bus(&self) -> &B {
        &self.bus
    }

    /// The fabric's bus, mutably.
    pub fn bus_mut(&mut self) -> &mut B {
        &mut self.bus
    }

    /// Validates `config` and writes it to the fabric's registers.
    pub fn configure(&mut self, config: &FabricConfig) -> Result<(), DriverError> {
        config
            .write_to(&mut self.bus)
            .map_err(DriverError::Registers)
    }

    /// Writes a register on the host's behalf; `false` (and nothing written) when no register
    /// lives at `addr`.
    pub fn write_register(&mut self, addr: u16, value: u32) -> bool {
        let mapped = is_register(addr);
        if mapped {
            self.bus.write(addr, value);
        }
        mapped
    }

    /// Answers a packet from the host, from the device's control source: `Hello` with `Hello`, `RegisterRead` with
    /// `RegisterValue`, `RegisterWrite` silently; an unknown register address with
    /// `ErrorReport(UnknownRegister)`, a device-to-host kind with an `ErrorReport` naming the
    /// kind. An `ErrorReport` from the host needs no answer.
    pub fn handle_host_packet<S: ByteSink>(
        &mut self,
        packet: &PacketRepr<'_>,
        out: &mut PacketWriter<S>,
    ) -> Result<(), DriverError> {
        let answer = match *packet {
            PacketRepr::Hello(hello) => {
                // The answer goes out as the link spoke so far; what follows is protected
                // when the host asked for it.
                let answer = PacketRepr::Hello(HelloRepr {
                    version: PROTOCOL_VERSION,
                    capabilities: self.capabilities,
                });
                out.send(&answer).map_err(DriverError::Encode)?;
                out.set_fec(hello.capabilities.contains(Capabilities::FEC));
                return Ok(());
            }
            PacketRepr::RegisterWrite(w) => {
                if self.write_register(w.addr, w.value) {
                    return Ok(());
                }
                unknown_register(w.addr)
            }
            PacketRepr::RegisterRead(r) if is_register(r.addr) => {
                PacketRepr::RegisterValue(RegisterValueRepr {
                    addr: r.addr,
                    value: self.bus.read(r.addr),
                })
            }
            PacketRepr::RegisterRead(r) => unknown_register(r.addr),
            PacketRepr::ErrorReport(_) => return Ok(()),
            ref other => PacketRepr::ErrorReport(ErrorReportRepr {
                code: ErrorCode::UnexpectedKind,
                detail: u32::from(u8::from(other.kind())),
            }),
        };
        out.send(&answer).map_err(DriverError::Encode)
    }

    /// Runs one `width * height` image (raster order, 8-bit grey) through the fabric with the
    /// configuration its registers hold, and sends FrameStart, the frame's PointBatch and
    /// SobelRows/SobelPatch packets (as OUTPUT_MODE.SOBEL_OUTPUT says), then FrameEnd.
    ///
    /// The fabric takes the frame's pixels with CONTROL.ENABLE set; the driver sets it for
    /// the frame and leaves it as it found it, since ENABLE is also the host's "start" (a head
    /// waits for it before grabbing).
    ///
    /// An error before FrameStart sends nothing and leaves the frame number unused; an error
    /// after it leaves the frame without a FrameEnd (the caller reports the error) and its
    /// number used up.
    pub fn process_frame<S: ByteSink>(
        &mut self,
        image: &[u8],
        timestamp_us: u64,
        out: &mut PacketWriter<S>,
    ) -> Result<FrameSummary, DriverError> {
        let enabled = self.bus.control_enable();
        let result = self.run_frame(image, timestamp_us, out);
        if !enabled {
            self.bus
                .set_control_enable(false)
                .map_err(DriverError::Registers)?;
        }
        result
    }

    /// [`Self::process_frame`] but for restoring CONTROL.ENABLE.
    fn run_frame<S: ByteSink>(
        &mut self,
        image: &[u8],
        timestamp_us: u64,
        out: &mut PacketWriter<S>,
    ) -> Result<FrameSummary, DriverError> {
        let registers = FabricConfig::read_from(&mut self.bus).map_err(DriverError::Registers)?;
        if usize::from(registers.width) > W0 {
            return Err(DriverError::TooWide {
                width: registers.width,
                max: W0,
            });
        }
        let width = usize::from(registers.width);
        let expected = width * usize::from(registers.height);
        if image.len() != expected {
            return Err(DriverError::ImageSize {
                expected,
                got: image.len(),
            });
        }
        // What the fabric cannot run (its last octave would be under 3 x 3) is refused here:
        // the RTL does not check the configuration it latches.
        Config::from(&registers)
            .validate(octave_widths(W0))
            .map_err(DriverError::FabricConfig)?;
        let drops_before = self.arm()?;
        self.output
            .ring
            .start(registers.width, registers.height, registers.octaves);
        self.output.patches.clear();
        self.output.batch.start(registers.points_per_batch);
        self.output.frame = FrameState {
            id: self.next_frame_id,
            mode: registers.sobel_output,
            sobel_scale: registers.sobel_scale,
            row_segment: registers.row_segment,
            points: 0,
            sobel_packets: 0,
            patches_dropped: 0,
        };
        self.next_frame_id = self.next_frame_id.wrapping_add(1);

        send(
            out,
            &mut self.output.numbering,
            &PacketRepr::FrameStart(FrameStartRepr {
                frame_id: self.output.frame.id,
                camera: self.output.camera,
                width: registers.width,
                height: registers.height,
                octaves: registers.octaves,
                timestamp_us,
            }),
        )?;
        // `read_from` validated WIDTH >= MIN_SIDE; `max(1)` only lets the compiler see that
        // `chunks_exact` cannot be handed 0 (its one panic).
        for (y, row) in image.chunks_exact(width.max(1)).enumerate() {
            self.bus.push(row, y == 0);
            self.drain(out)?;
        }
        let mut flushed = false;
        for _ in 0..flush_rows(registers.height) {
            self.bus.idle(registers.width.into());
            self.drain(out)?;
            flushed = !self.bus.status_busy();
            if flushed {
                break;
            }
        }
        if !flushed {
            return Err(DriverError::Frame(FrameError::FlushTimeout));
        }
        for completed in self.output.ring.finish().into_iter().flatten() {
            self.output.rows_completed(completed, out)?;
        }
        while let Some(patch) = self.output.patches.take_first(|_| true) {
            self.output.send_patch(&patch, out)?;
        }
        self.output.send_points(out)?;

        let overflow = self.drops().since(drops_before);
        let dropped_sobel = overflow
            .sobel
            .saturating_add(self.output.frame.patches_dropped);
        let mut flags = FrameEndFlags(0);
        if overflow.points > 0 {
            flags = flags | FrameEndFlags::POINT_FIFO_OVERFLOW;
        }
        if dropped_sobel > 0 {
            flags = flags | FrameEndFlags::SOBEL_FIFO_OVERFLOW;
        }
        send(
            out,
            &mut self.output.numbering,
            &PacketRepr::FrameEnd(FrameEndRepr {
                frame_id: self.output.frame.id,
                camera: self.output.camera,
                point_count: self.output.frame.points,
                sobel_count: self.output.frame.sobel_packets,
                flags,
                dropped_points: overflow.points,
                dropped_sobel,
            }),
        )?;
        Ok(FrameSummary {
            frame_id: self.output.frame.id,
            points: self.output.frame.points,
            sobel_packets: self.output.frame.sobel_packets,
            overflow,
            patches_dropped: self.output.frame.patches_dropped,
        })
    }

    /// Arms the fabric for a frame: first clears what an abandoned frame left (the frame
    /// still running, entries in the FIFOs) with a soft reset, then enables PIXEL_IN and fires
    /// FRAME_ARM. Returns the drop counters before the frame.
    fn arm(&mut self) -> Result<Overflow, DriverError> {
        let bus = &mut self.bus;
        if bus.status_busy()
            || bus.point_fifo_level_level() != 0
            || bus.sobel_fifo_level_level() != 0
        {
            bus.fire_control_soft_reset()
                .map_err(DriverError::Registers)?;
        }
        let drops = self.drops();
        let bus = &mut self.bus;
        bus.set_control_enable(true)
            .and_then(|()| bus.fire_control_frame_arm())
            .map_err(DriverError::Registers)?;
        if !bus.status_busy() {
            return Err(DriverError::NotArmed);
        }
        Ok(drops)
    }

    /// The fabric's drop counters (since its last reset).
    fn drops(&mut self) -> Overflow {
        Overflow {
            points: self.bus.point_overflow_count_count(),
            sobel: self.bus.sobel_overflow_count_count(),
        }
    }

    /// Empties both FIFOs, points first.
    fn drain<S: ByteSink>(&mut self, out: &mut PacketWriter<S>) -> Result<(), DriverError> {
        let Self {
            bus,
            reader,
            output,
            ..
        } = self;
        reader.drain_points(bus, &mut |point| output.on_point(point, out))?;
        reader.drain_sobel(bus, &mut |run| output.on_sobel(run, out))
    }
}

impl<const W0: usize> FrameOutput<W0> {
    fn on_point<S: ByteSink>(
        &mut self,
        point: &Extremum,
        out: &mut PacketWriter<S>,
    ) -> Result<(), DriverError> {
        let outside = DriverError::PointOutOfFrame {
            octave: point.octave,
            x: point.x,
            y: point.y,
        };
        let Some(rows) = self.ring.rows(point.octave) else {
            return Err(outside);
        };
        let (width, height) = rows.dims();
        let done = rows.next_row();
        if point.x >= width || point.y >= height {
            return Err(outside);
        }
        let index = self.frame.points;
        self.frame.points = self.frame.points.saturating_add(1);
        if self.batch.push(wire_point(point)) {
            self.send_points(out)?;
        }
        if self.frame.mode != SobelOutput::Patches {
            return Ok(());
        }
        let Ok(index) = u16::try_from(index) else {
            // SobelPatch numbers points with 16 bits; later points cannot be referenced.
            self.frame.patches_dropped = self.frame.patches_dropped.saturating_add(1);
            return Ok(());
        };
        let pending = PendingPatch {
            index,
            octave: point.octave,
            x: point.x,
            y: point.y,
        };
        if done >= pending.rows_needed_before(height) {
            self.send_patch(&pending, out)
        } else if self.patches.push(pending).is_err() {
            self.frame.patches_dropped = self.frame.patches_dropped.saturating_add(1);
            Ok(())
        } else {
            Ok(())
        }
    }

    /// Stores a run of the Sobel stream, sending what each row it completes makes ready
    /// before storing the pixels after it.
    fn on_sobel<S: ByteSink>(
        &mut self,
        mut run: SobelRun<'_>,
        out: &mut PacketWriter<S>,
    ) -> Result<(), DriverError> {
        while !run.is_empty() {
            let (taken, completed) = self
                .ring
                .push_run(&run)
                .map_err(DriverError::SobelOutOfOrder)?;
            if let Some(completed) = completed {
                self.rows_completed(completed, out)?;
            }
            run = run.split_at(taken).1;
        }
        Ok(())
    }

    /// Sends completed rows (rows mode) or the patches they made ready (patch mode).
    fn rows_completed<S: ByteSink>(
        &mut self,
        completed: Completed,
        out: &mut PacketWriter<S>,
    ) -> Result<(), DriverError> {
        let octave = completed.octave;
        match self.frame.mode {
            SobelOutput::Rows => {
                for row in completed.rows {
                    // A row whose every pixel the FIFO dropped is not sent (FrameEnd counts it).
                    let Some(pixels) = self.ring.row(octave, row) else {
                        continue;
                    };
                    // Validated at least MIN_SIDE, so never 0.
                    let segment = usize::from(self.frame.row_segment).max(1);
                    for (i, part) in pixels.chunks(segment).enumerate() {
                        send(
                            out,
                            &mut self.numbering,
                            &PacketRepr::SobelRows(SobelRowsRepr {
                                frame_id: self.frame.id,
                                camera: self.camera,
                                octave,
                                scale: self.frame.sobel_scale,
                                row,
                                // A row is at most MAX_WIDTH pixels, which fits a u16.
                                x: (i * segment) as u16,
                                pixels: Records::Values(part),
                            }),
                        )?;
                        self.frame.sobel_packets = self.frame.sobel_packets.saturating_add(1);
                    }
                }
            }
            SobelOutput::Patches => {
                let Some(rows) = self.ring.rows(octave) else {
                    return Ok(());
                };
                let (done, (_, height)) = (rows.next_row(), rows.dims());
                while let Some(patch) = self
                    .patches
                    .take_first(|p| p.octave == octave && done >= p.rows_needed_before(height))
                {
                    self.send_patch(&patch, out)?;
                }
            }
        }
        Ok(())
    }

    /// Cuts and sends one patch, or counts it when its top rows have left the ring.
    fn send_patch<S: ByteSink>(
        &mut self,
        patch: &PendingPatch,
        out: &mut PacketWriter<S>,
    ) -> Result<(), DriverError> {
        let top_held = self.ring.rows(patch.octave).is_some_and(|rows| {
            patch.first_row() >= rows.oldest_row() && patch.first_row() < rows.dims().1
        });
        if !top_held {
            self.frame.patches_dropped = self.frame.patches_dropped.saturating_add(1);
            return Ok(());
        }
        self.ring.window(
            patch.octave,
            i32::from(patch.x) - i32::from(HALF),
            i32::from(patch.y) - i32::from(HALF),
            &mut self.patch,
        );
        send(
            out,
            &mut self.numbering,
            &PacketRepr::SobelPatch(SobelPatchRepr {
                frame_id: self.frame.id,
                camera: self.camera,
                point_index: patch.index,
                octave: patch.octave,
                scale: self.frame.sobel_scale,
                x: patch.x,
                y: patch.y,
                pixels: Records::Values(&self.patch),
            }),
        )?;
        self.frame.sobel_packets = self.frame.sobel_packets.saturating_add(1);
        Ok(())
    }

    /// Sends the collected points, if any.
    fn send_points<S: ByteSink>(&mut self, out: &mut PacketWriter<S>) -> Result<(), DriverError> {
        if self.batch.points().is_empty() {
            return Ok(());
        }
        send(
            out,
            &mut self.numbering,
            &PacketRepr::PointBatch(PointBatchRepr {
                frame_id: self.frame.id,
                camera: self.camera,
                points: Records::Values(self.batch.points()),
            }),
        )?;
        self.batch.clear();
        Ok(())
    }
}

/// Line lengths of the octaves of a fabric whose octave 0 holds `w0` pixels.
fn octave_widths(w0: usize) -> [usize; MAX_OCTAVES] {
    [w0, w0.div_ceil(2), w0.div_ceil(4), w0.div_ceil(8)]
}

/// Blank rows after the last input row within which the fabric must have emitted everything:
/// octave `k` drains in about `10 * 2^k` input rows, so `4 * height + 64` is generous (the
/// bound the fabric's own `run_frame` uses).
fn flush_rows(height: u16) -> u32 {
    4 * u32::from(height) + 64
}

fn is_register(addr: u16) -> bool {
    addr % 4 == 0 && register_at(addr).is_some()
}

fn unknown_register(addr: u16) -> PacketRepr<'static> {
    PacketRepr::ErrorReport(ErrorReportRepr {
        code: ErrorCode::UnknownRegister,
        detail: u32::from(addr),
    })
}

/// Sends one of the channel's packets, as its source.
fn send<S: ByteSink>(
    out: &mut PacketWriter<S>,
    numbering: &mut Numbering,
    packet: &PacketRepr<'_>,
) -> Result<(), DriverError> {
    out.send_from(numbering, packet)
        .map_err(DriverError::Encode)
}
