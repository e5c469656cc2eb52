//! The clock-exact time model of [`FabricDevice`]: one call, one `sc_fabric` clock (the
//! parent module's docs compare the two time models).

use crate::fabric::output::ClockedFrontEnd;
use crate::framing::ByteSink;

use super::{FabricDevice, Phase, Sample, Strobes, Written};

/// A pixel on PIXEL_IN for one clock (TVALID high; `None` on a clock without one).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Beat {
    /// The grey level.
    pub data: u8,
    /// Start of frame: the pixel (0, 0) of a frame.
    pub sof: bool,
    /// End of line; `sc_fabric` counts lines by WIDTH and does not check it.
    pub eol: bool,
}

/// A bus access on one clock: `sc_regs`' one-clock `bus_re` or `bus_we` strobe.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    /// A read of the word at this byte offset.
    Read(u16),
    /// A write of the value to the word at this byte offset.
    Write(u16, u32),
}

/// What one clock shows outside the device.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Clocked {
    /// PIXEL_IN's TREADY during the clock: whether the clock's pixel, if any, was taken.
    pub ready: bool,
    /// The word a read returned: `bus_rdata` from the next clock on (`None` without a read).
    pub read: Option<u32>,
}

impl<F: ClockedFrontEnd, const W0: usize, L: ByteSink> FabricDevice<F, W0, L> {
    /// One `sc_fabric` clock with an optional pixel and an optional bus access, in the RTL's
    /// order of effects:
    /// - everything the clock shows (the read's word, PIXEL_IN's ready, the datapath's
    ///   `done`) is what the device held before the clock's edge;
    /// - CONTROL's strobes act on the clock after their write, as `sc_regs` registers them:
    ///   FRAME_ARM (ignored while BUSY) latches the configuration the registers held before
    ///   that clock's edge; SOFT_RESET's clock already shows what it clears as cleared except
    ///   the sticky flags, which clear at the clock's end;
    /// - a STATUS flag set on the clock a write clears it stays set;
    /// - pixels before SOF are discarded, pixels offered while not ready are lost;
    /// - the datapath advances one clock on every clock from the frame's first pixel until
    ///   it is done, pixel or not, and its pushes meet the FIFOs before the clock's pop, so
    ///   a pop frees its slot for the next clock only;
    /// - LATENCY_CLOCKS is stored on the clock the last octave takes its first input;
    /// - the stream engine, when enabled, takes the FIFOs at the end of each line time: on
    ///   the clock that takes a line's last pixel, and every WIDTH clocks after the last line.
    ///
    /// A configuration the datapath refuses at FRAME_ARM leaves the device idle (the driver
    /// validates before it writes; the RTL would run it into undefined results).
    pub fn clock(&mut self, pixel: Option<Beat>, access: Option<Access>) -> Clocked {
        let strobes = self.strobes;
        if strobes.soft_reset {
            let flags = self.flags;
            self.soft_reset();
            self.flags = flags;
        }
        // Before the edge.
        let phase = self.phase;
        let ready = self.ready();
        let sample = match access {
            Some(Access::Read(offset)) => Some(self.sample(offset)),
            Some(Access::Write(..)) | None => None,
        };
        let points_held = self.datapath.point_level() != 0;
        let sobel_held = self.datapath.sobel_level() != 0;
        let frame_end = phase == Phase::Flush && self.datapath.octaves_done();
        let feed = pixel
            .filter(|beat| ready && (phase == Phase::Run || beat.sof))
            .map(|beat| beat.data);

        // The edge.
        if strobes.frame_arm && !strobes.soft_reset && phase == Phase::Idle {
            self.arm();
        }
        if strobes.soft_reset {
            self.flags = 0;
        }
        self.strobes = Strobes::default();
        match access.map(|access| match access {
            Access::Write(offset, value) => self.store(offset, value),
            Access::Read(_) => Written::Stored,
        }) {
            Some(Written::Control(next)) => self.strobes = next,
            Some(Written::ClearFlags(flags)) => self.flags &= !flags,
            Some(Written::Stored) | None => {}
        }
        if feed.is_some() {
            self.frame.taken = self.frame.taken.saturating_add(1);
            self.phase = if self.frame.taken >= self.frame.total {
                Phase::Flush
            } else {
                Phase::Run
            };
        }
        if frame_end {
            self.end_frame();
        } else if matches!(phase, Phase::Run | Phase::Flush) || feed.is_some() {
            self.datapath.clock(feed);
            if self.line_time_ends(feed.is_some()) {
                self.stream.take(&mut self.datapath);
            }
            self.note_drops();
            if self.frame.latency.is_some() {
                let last = usize::from(self.frame.octaves.saturating_sub(1));
                if let Some(at) = self.datapath.first_input_clock(last) {
                    self.latency = u32::try_from(at).unwrap_or(u32::MAX);
                    self.frame.latency = None;
                }
            }
        }
        let read = sample.map(|sample| match sample {
            Sample::Word(word) => word,
            Sample::PopPoint if points_held => self.pop_point(),
            Sample::PopSobel if sobel_held => self.pop_sobel(),
            // A pop of an empty FIFO reads 0, zeroes the holding registers and leaves the
            // clock's pushes alone.
            Sample::PopPoint => {
                self.point_hold = [0; 2];
                0
            }
            Sample::PopSobel => {
                self.sobel_hold = 0;
                0
            }
        });
        Clocked { ready, read }
    }

    /// Whether the clock just run ends a line time of the frame: it took the line's last
    /// pixel, or it is the WIDTH-th blanking clock since the last line time of the flush.
    fn line_time_ends(&mut self, took_pixel: bool) -> bool {
        let width = u32::from(self.frame.width).max(1);
        if took_pixel {
            return self.frame.taken % width == 0;
        }
        if self.phase != Phase::Flush {
            return false;
        }
        self.frame.blank = self.frame.blank.saturating_add(1);
        let ends = self.frame.blank >= width;
        if ends {
            self.frame.blank = 0;
        }
        ends
    }
}
