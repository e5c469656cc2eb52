//! The driver of one camera channel: its fabric, its registers, its frame counter.

use stereocal_hdl::regs::stream_fault::{self, Cause};
use stereocal_hdl::{register_at, FabricConfig, PixelIn, RegisterBus, Registers};
use stereocal_wire::{
    Camera, Capabilities, ErrorCode, ErrorReportRepr, HelloRepr, PacketRepr, RegisterValueRepr,
    PROTOCOL_VERSION,
};

use crate::driver::error::DriverError;
use crate::fabric::config::MAX_OCTAVES;
use crate::fabric::stream::OutOfOrder;
use crate::fabric::{Config, FrameError, Overflow};
use crate::framing::{ByteSink, PacketWriter};

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

/// Drives one camera channel: configures, arms and polls its fabric through the register
/// map on `B`, and offers the frame's pixels on its PIXEL_IN port. The fabric's stream engine
/// sends the frame's packets on its own link port; the driver's share is per frame.
///
/// `B` is [`stereocal_hdl::Mmio`] next to a real fabric or a
/// [`crate::fabric::FabricDevice`] in software; the driver's code path is the same.
/// `W0` is the widest frame the fabric takes (its octave-0 line length).
pub struct Driver<B: RegisterBus + PixelIn, const W0: usize = 1280> {
    bus: B,
    camera: Camera,
    capabilities: Capabilities,
    next_frame_id: u32,
}

impl<B: RegisterBus + PixelIn, const W0: usize> Driver<B, W0> {
    /// A driver for `camera`'s fabric, reached through `bus` (its registers and PIXEL_IN).
    /// It enables the fabric's stream engine for `camera`; the first frame is number 0.
    pub fn new(mut bus: B, camera: Camera) -> Self {
        // Every field is within its range: a camera is a byte, the flags are bits.
        let _ = bus
            .set_stream_control_camera(u8::from(camera))
            .and_then(|()| bus.set_stream_control_enable(true));
        Self {
            bus,
            camera,
            capabilities: CHANNEL_CAPABILITIES,
            next_frame_id: 0,
        }
    }

    /// Adds capability bits to the `Hello` answer (the soft-core adds `LOG`).
    pub fn with_capabilities(mut self, extra: Capabilities) -> Self {
        self.capabilities = self.capabilities | extra;
        self
    }

    /// The camera this channel serves.
    pub fn camera(&self) -> Camera {
        self.camera
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

    /// Sets whether the fabric's stream engine protects its link frames (STREAM_CONTROL.FEC):
    /// as the host asked in its `Hello`, which one channel answers for the device.
    pub fn set_fec(&mut self, on: bool) -> Result<(), DriverError> {
        self.bus
            .set_stream_control_fec(on)
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

    /// Answers a packet from the host, from the device's control source: `Hello` with `Hello`
    /// (and the link's error correction as the host asks, for the soft-core's writer and the
    /// fabric's stream engine alike), `RegisterRead` with `RegisterValue`, `RegisterWrite`
    /// silently; an unknown register address with
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
                let fec = hello.capabilities.contains(Capabilities::FEC);
                out.set_fec(fec);
                return self.set_fec(fec);
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
    /// configuration its registers hold; the fabric's stream engine sends FrameStart, the
    /// frame's PointBatch and SobelRows/SobelPatch packets (as OUTPUT_MODE.SOBEL_OUTPUT says),
    /// then FrameEnd on its link.
    ///
    /// The driver writes FRAME_ID and TIMESTAMP_*, arms the frame, offers the image row by row
    /// on PIXEL_IN (a camera's part on a head: the loop stands in for it) and polls
    /// STATUS.BUSY through the blanking after the last row; at the end it reads the engine's
    /// counters and STREAM_FAULT. The fabric takes the frame's pixels with CONTROL.ENABLE set;
    /// the driver sets it for the frame and leaves it as it found it, since ENABLE is also the
    /// host's "start" (a head waits for it before grabbing).
    ///
    /// An error before FRAME_ARM leaves nothing sent and the frame number unused; an error
    /// after it leaves the frame without a FrameEnd (the caller reports the error) and its
    /// number used up.
    pub fn process_frame(
        &mut self,
        image: &[u8],
        timestamp_us: u64,
    ) -> Result<FrameSummary, DriverError> {
        let enabled = self.bus.control_enable();
        let result = self.run_frame(image, timestamp_us);
        if !enabled {
            self.bus
                .set_control_enable(false)
                .map_err(DriverError::Registers)?;
        }
        result
    }

    /// [`Self::process_frame`] but for restoring CONTROL.ENABLE.
    fn run_frame(&mut self, image: &[u8], timestamp_us: u64) -> Result<FrameSummary, DriverError> {
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
        let frame_id = self.next_frame_id;
        let drops_before = self.arm(frame_id, timestamp_us)?;
        self.next_frame_id = self.next_frame_id.wrapping_add(1);

        // `read_from` validated WIDTH >= MIN_SIDE; `max(1)` only lets the compiler see that
        // `chunks_exact` cannot be handed 0 (its one panic).
        for (y, row) in image.chunks_exact(width.max(1)).enumerate() {
            self.bus.push(row, y == 0);
        }
        let mut flushed = false;
        for _ in 0..flush_rows(registers.height) {
            self.bus.idle(registers.width.into());
            flushed = !self.bus.status_busy();
            if flushed {
                break;
            }
        }
        if !flushed {
            return Err(DriverError::Frame(FrameError::FlushTimeout));
        }
        stream_fault(self.bus.read(stream_fault::OFFSET))?;
        Ok(FrameSummary {
            frame_id,
            points: self.bus.stream_points_count(),
            sobel_packets: self.bus.stream_sobel_packets_count(),
            overflow: self.drops().since(drops_before),
            patches_dropped: self.bus.stream_patches_dropped_count(),
        })
    }

    /// Arms the fabric for frame `frame_id` captured at `timestamp_us`: first clears what an
    /// abandoned frame left (the frame still running, entries in the FIFOs) with a soft
    /// reset, then writes the frame's number and time, enables PIXEL_IN and fires FRAME_ARM.
    /// Returns the drop counters before the frame.
    fn arm(&mut self, frame_id: u32, timestamp_us: u64) -> Result<Overflow, DriverError> {
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
        bus.set_frame_id_value(frame_id)
            .and_then(|()| bus.set_timestamp_lo_value(timestamp_us as u32))
            .and_then(|()| bus.set_timestamp_hi_value((timestamp_us >> 32) as u32))
            .and_then(|()| bus.set_control_enable(true))
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
}

/// The error STREAM_FAULT's word `word` reports, if any.
fn stream_fault(word: u32) -> Result<(), DriverError> {
    let octave = stream_fault::OCTAVE.extract(word) as u8;
    let x = stream_fault::X.extract(word) as u16;
    let y = stream_fault::Y.extract(word) as u16;
    if stream_fault::OVERRUN.extract(word) != 0 {
        return Err(DriverError::StreamOverrun);
    }
    match Cause::from_bits(stream_fault::CAUSE.extract(word)) {
        Some(Cause::None) | None => Ok(()),
        Some(Cause::SobelOrder) => Err(DriverError::SobelOutOfOrder(OutOfOrder { octave, x, y })),
        Some(Cause::PointOutside) => Err(DriverError::PointOutOfFrame { octave, x, y }),
        Some(Cause::Encode) => Err(DriverError::StreamEncode),
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

#[cfg(test)]
mod stream_fault_tests {
    use super::*;

    #[test]
    fn an_overrun_fails_the_frame_beside_any_cause() {
        assert!(stream_fault(0).is_ok());
        assert!(matches!(
            stream_fault(stream_fault::OVERRUN.mask()),
            Err(DriverError::StreamOverrun)
        ));
        let encode = stream_fault::CAUSE.insert(0, Cause::Encode as u32).unwrap();
        assert!(matches!(
            stream_fault(encode | stream_fault::OVERRUN.mask()),
            Err(DriverError::StreamOverrun)
        ));
        assert!(matches!(
            stream_fault(encode),
            Err(DriverError::StreamEncode)
        ));
    }
}
