//! The fabric as a device: `sc_fabric` (`hdl-interface/rtl/sc_fabric.v`) in software, behind
//! the register map ([`RegisterBus`]) and the PIXEL_IN port ([`PixelIn`]), with its stream
//! engine ([`crate::fabric::stream`]) sending on the LINK_OUT port (a [`ByteSink`]).
//!
//! A program drives [`FabricDevice`] exactly as it drives the RTL: it writes the
//! configuration registers, arms a frame with CONTROL.FRAME_ARM, offers pixels on PIXEL_IN
//! and polls STATUS; the stream engine (STREAM_CONTROL.ENABLE) sends the frame's packets, or,
//! with the engine disabled, the program drains the FIFOs by reading POINT_FIFO_* and
//! SOBEL_FIFO_*. Behind the registers sits any datapath ([`FrontEnd`]): the register-level
//! model, the fast path, [`crate::fabric::FabricModel`] choosing between them at run time, or
//! a test's script.
//!
//! # Registers, as `sc_regs` and `sc_fabric` define them
//! - `rw` configuration lives in a [`RegisterBank`]: the map's masks and reset values, so
//!   reserved bits read 0 and a write keeps only the field bits.
//! - VERSION reads its constant; CONTROL reads ENABLE (its `wo` strobes read 0).
//! - STATUS: BUSY from the frame state; FRAME_DONE, POINT_OVERFLOW and SOBEL_OVERFLOW are
//!   sticky, set by the device and cleared by writing 1 (`w1c`) or by SOFT_RESET.
//! - FIFO levels and overflow counters are the datapath's FIFOs' (counters since the last
//!   SOFT_RESET, saturating); FRAME_COUNT counts frames done (wrapping); LATENCY_CLOCKS below.
//! - A read of POINT_FIFO_DATA or SOBEL_FIFO_DATA pops the head and loads the holding
//!   registers (POINT_FIFO_DXDY, POINT_FIFO_DSDOG, SOBEL_FIFO_POSITION); on an empty FIFO it
//!   reads 0 (VALID clear) and zeroes them. [`crate::fabric::fifo_words`] has the layout.
//! - Offsets inside the window address their word, whatever their low two bits (the RTL
//!   decodes `addr[7:2]`); offsets outside it, and words no register occupies, read 0 and
//!   ignore writes.
//!
//! # Frame control, as `sc_fabric`'s state machine
//! Idle, then (FRAME_ARM, ignored while BUSY; SOFT_RESET in the same write wins) armed:
//! the configuration registers are latched into the datapath and BUSY rises. PIXEL_IN is
//! ready while CONTROL.ENABLE is 1 and the frame still takes pixels; pixels offered when it is
//! not ready are lost, and pixels before the first one with SOF are discarded. The SOF pixel
//! is pixel (0, 0) and the frame is the next WIDTH x HEIGHT pixels (lines are counted by
//! WIDTH; EOL is not checked). After its last pixel the datapath flushes on blanking clocks
//! until it has emitted everything; the stream engine, when enabled, sends what the frame
//! still holds and `FrameEnd`; then BUSY falls, FRAME_DONE is set and FRAME_COUNT counts it.
//! The stream engine takes the FIFOs at the end of each line time, in both time models
//! below, so its packets are the same whichever model and datapath run.
//! SOFT_RESET empties both FIFOs, stops the frame and clears STATUS, the counters, the
//! latency and the holding registers; the configuration registers keep their values.
//!
//! # Two time models
//! The device keeps one state and one register decoding, and offers two ways of passing time.
//!
//! **Ideal** ([`RegisterBus`], [`PixelIn`]): what programs use (the driver, the host's
//! in-process device, the firmware under QEMU), with any datapath. The device has no clock
//! of its own: a clock passes for every pixel offered while a frame runs and for every idle
//! clock of [`PixelIn::idle`]; register accesses fall between clocks and act at once (a
//! FRAME_ARM write arms, a SOFT_RESET write resets, before the next access). The datapath is
//! fed whole lines (a line offered in pieces is gathered first), and the blanking clocks
//! after a frame's last pixel reach it a line time (WIDTH clocks) at a time, since the fast
//! path works by lines; idle clocks inside a frame only delay it. LATENCY_CLOCKS is the
//! clock, counted from the frame's first pixel, at which the last configured octave takes its
//! first input: the register-level model's figure for back-to-back pixels
//! ([`latency::first_pixel_of_last_octave`], checked against the model's clocks by
//! `tests/latency.rs`), stored once that many clocks have passed. This costs a program
//! nothing per clock, and what it observes matches the RTL register for register.
//!
//! **Clock-exact** ([`FabricDevice::clock`], for a datapath that works per clock:
//! [`ClockedFrontEnd`], the register-level model): one call is one `sc_fabric` clock with an
//! optional PIXEL_IN beat and an optional bus access, in the RTL's order of effects, so that
//! a co-simulation can compare every read with the Verilated `sc_fabric`
//! (`tests/tests/rtl_fabric_contract.rs`). The read's value is sampled before the clock's
//! edge, as `bus_rdata` captures it; the clock's pushes meet the FIFOs as they were before
//! the edge's pop; CONTROL's strobes act on the next clock, as `sc_regs` registers them
//! (with what `sc_fabric` shows on that clock, below); a STATUS flag set and cleared on the
//! same clock stays set; LATENCY_CLOCKS counts real clocks, pixel or not, from the frame's
//! first pixel to the last octave's first input.
//!
//! # What a read on a strobe's clock shows
//! `sc_regs` registers CONTROL's strobes, so FRAME_ARM and SOFT_RESET act on the clock after
//! their write. `sc_fabric` makes a read on that clock agree with the write, so a driver may
//! read on the very next clock: STATUS.BUSY is 1 from the clock after an accepted FRAME_ARM,
//! and on SOFT_RESET's clock everything it clears reads cleared (levels, counters,
//! LATENCY_CLOCKS, FIFO heads, holding registers, BUSY), except STATUS's sticky flags, which
//! `sc_regs` holds and which clear at that clock's end.
//!
//! # FIFO order
//! Both FIFOs hold their entries in the RTL's order, whichever datapath is behind the device:
//! by clock, and within a clock octave 0 first (`sc_out_fifo` takes the four octaves' items
//! of a clock in octave order). Between line times the FIFO contents, levels and overflow
//! counters are the register-level model's entry for entry, so a program that reads the
//! same registers between the same line times pops the same words and sees the same drops
//! from either datapath (`tests/fifo_order.rs`).
//!
//! Through the ideal time model, what a program can observe therefore matches the RTL
//! register for register, but not clock for clock: the entries a line time brings arrive
//! together at its end. Through the clock-exact one it matches clock for clock.

mod clock;

pub use clock::{Access, Beat, Clocked};

use stereocal_hdl::regs::stream_fault::Cause;
use stereocal_hdl::regs::{
    control, frame_count, latency_clocks, point_fifo_data, point_fifo_dsdog, point_fifo_dxdy,
    point_fifo_level, point_overflow_count, sobel_fifo_data, sobel_fifo_level, sobel_fifo_position,
    sobel_overflow_count, status, stream_control, stream_fault, stream_patches_dropped,
    stream_points, stream_sobel_packets, version, WINDOW_SIZE,
};
use stereocal_hdl::{PixelIn, RegisterBank, RegisterBus, Registers};
use stereocal_wire::Camera;

use crate::fabric::config::Config;
use crate::fabric::fifo_words::{point_words, sobel_words, SOBEL_OFFSETS};
use crate::fabric::latency;
#[cfg(doc)]
use crate::fabric::output::ClockedFrontEnd;
use crate::fabric::output::{FrontEnd, Overflow};
use crate::fabric::stream::{StreamEngine, StreamFault, StreamFrame, Unwired};
use crate::framing::ByteSink;

/// Where the frame is (`sc_fabric`'s `state`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// No frame: BUSY is 0.
    Idle,
    /// Armed, waiting for the SOF pixel.
    AwaitSof,
    /// Taking the frame's pixels.
    Run,
    /// Every pixel in; the datapath drains on blanking clocks.
    Flush,
}

/// The frame being taken: what FRAME_ARM latched.
#[derive(Clone, Copy, Debug)]
struct Frame {
    width: u16,
    /// OCTAVES.
    octaves: u8,
    /// WIDTH x HEIGHT.
    total: u32,
    /// Pixels taken so far.
    taken: u32,
    /// Clocks since the first pixel (the first pixel is clock 0).
    clock: u64,
    /// LATENCY_CLOCKS of this frame for back-to-back pixels, until it is stored (the
    /// clock-exact time model stores the clock it measures instead).
    latency: Option<u64>,
    /// Blanking clocks not yet handed to the datapath (less than a line).
    blank: u32,
}

/// `sc_fabric` in software over the datapath `F`; `W0` is the longest line it gathers (the
/// datapath's octave-0 line length); its stream engine sends on the link `L`.
pub struct FabricDevice<F, const W0: usize = 1280, L = Unwired> {
    datapath: F,
    stream: StreamEngine<W0, L>,
    registers: RegisterBank,
    phase: Phase,
    frame: Frame,
    /// The line being gathered from PIXEL_IN.
    line: [u8; W0],
    line_len: usize,
    /// STATUS's sticky flags, in their bit positions.
    flags: u32,
    /// The datapath's drop counters when the flags last looked at them.
    drops_seen: Overflow,
    frame_count: u32,
    latency: u32,
    /// POINT_FIFO_DXDY and POINT_FIFO_DSDOG.
    point_hold: [u32; 2],
    /// SOBEL_FIFO_POSITION.
    sobel_hold: u32,
    /// CONTROL's strobes as `sc_regs` holds them on this clock (the clock-exact time model;
    /// the ideal one acts on a write at once and leaves them clear).
    strobes: Strobes,
}

/// CONTROL's `wo` strobes: what the last CONTROL write asked for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Strobes {
    frame_arm: bool,
    soft_reset: bool,
}

/// What a bus read of a word gives, decoded once for both time models.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Sample {
    /// The word, with no side effect.
    Word(u32),
    /// POINT_FIFO_DATA: pops the point FIFO.
    PopPoint,
    /// SOBEL_FIFO_DATA: pops the Sobel FIFO.
    PopSobel,
}

/// What a bus write asks of the device beyond storing, decoded once for both time models.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Written {
    /// Stored (configuration, CONTROL.ENABLE) or ignored.
    Stored,
    /// CONTROL: ENABLE is stored; these are its strobes.
    Control(Strobes),
    /// STATUS: the `w1c` flags written 1.
    ClearFlags(u32),
}

impl<F: FrontEnd, const W0: usize> FabricDevice<F, W0, Unwired> {
    /// The device after power-up with nothing on its LINK_OUT port, for programs that read
    /// the FIFOs through the registers.
    pub fn new(datapath: F) -> Self {
        Self::with_link(datapath, Unwired)
    }
}

impl<F: FrontEnd, const W0: usize, L: ByteSink> FabricDevice<F, W0, L> {
    /// The device after power-up, its stream engine on `link`: registers at their reset
    /// values, no frame, empty FIFOs.
    pub fn with_link(mut datapath: F, link: L) -> Self {
        datapath.reset();
        Self {
            datapath,
            stream: StreamEngine::new(link),
            registers: RegisterBank::new(),
            phase: Phase::Idle,
            frame: Frame {
                width: 0,
                octaves: 0,
                total: 0,
                taken: 0,
                clock: 0,
                latency: None,
                blank: 0,
            },
            line: [0; W0],
            line_len: 0,
            flags: 0,
            drops_seen: Overflow::default(),
            frame_count: 0,
            latency: 0,
            point_hold: [0; 2],
            sobel_hold: 0,
            strobes: Strobes::default(),
        }
    }

    /// The link the stream engine sends on.
    pub fn link(&self) -> &L {
        self.stream.link()
    }

    /// The link, mutably (to take what the stream engine sent).
    pub fn link_mut(&mut self) -> &mut L {
        self.stream.link_mut()
    }

    /// Whether PIXEL_IN takes a pixel now.
    fn ready(&mut self) -> bool {
        matches!(self.phase, Phase::AwaitSof | Phase::Run) && self.registers.control_enable()
    }

    /// FRAME_ARM while idle: latches the configuration and starts the datapath. A
    /// configuration the datapath cannot run (the driver validates before it writes; the RTL
    /// would run it into undefined results) leaves the device idle.
    fn arm(&mut self) {
        let r = &mut self.registers;
        let config = Config {
            width: r.width_value(),
            height: r.height_value(),
            octaves: r.octaves_count(),
            contrast_threshold: r.contrast_threshold_value(),
            edge_ratio: r.edge_threshold_r(),
            sobel_scale: r.output_mode_sobel_scale(),
            max_offset: r.max_offset_value(),
        };
        let drops = self.datapath.overflow();
        if self.datapath.start_frame(&config).is_err() {
            return;
        }
        let r = &mut self.registers;
        if r.stream_control_enable() {
            let frame = StreamFrame {
                frame_id: r.frame_id_value(),
                camera: Camera::from(r.stream_control_camera()),
                timestamp_us: u64::from(r.timestamp_hi_value()) << 32
                    | u64::from(r.timestamp_lo_value()),
                width: config.width,
                height: config.height,
                octaves: config.octaves,
                mode: r.output_mode_sobel_output(),
                sobel_scale: config.sobel_scale,
                points_per_batch: r.output_mode_points_per_batch(),
                row_segment: r.output_mode_row_segment(),
            };
            self.stream.start(frame, drops);
        }
        self.phase = Phase::AwaitSof;
        self.line_len = 0;
        self.frame = Frame {
            width: config.width,
            octaves: config.octaves,
            total: u32::from(config.width) * u32::from(config.height),
            taken: 0,
            clock: 0,
            latency: Some(latency::first_pixel_of_last_octave(
                config.width,
                config.height,
                config.octaves,
            )),
            blank: 0,
        };
    }

    /// SOFT_RESET.
    fn soft_reset(&mut self) {
        self.datapath.reset();
        self.stream.abort();
        self.phase = Phase::Idle;
        self.line_len = 0;
        self.flags = 0;
        self.drops_seen = Overflow::default();
        self.frame_count = 0;
        self.latency = 0;
        self.point_hold = [0; 2];
        self.sobel_hold = 0;
    }

    /// Accounts for `clocks` clocks of the running frame: the latency, the drop flags and the
    /// end of the frame.
    fn advance(&mut self, clocks: u32) {
        self.frame.clock = self.frame.clock.saturating_add(clocks.into());
        if let Some(at) = self.frame.latency {
            if self.frame.clock > at {
                self.latency = u32::try_from(at).unwrap_or(u32::MAX);
                self.frame.latency = None;
            }
        }
        self.note_drops();
        if self.phase == Phase::Flush && self.datapath.frame_done() {
            self.end_frame();
        }
    }

    /// Sets the overflow flags for what the datapath dropped since the last look.
    fn note_drops(&mut self) {
        let drops = self.datapath.overflow();
        if drops.points != self.drops_seen.points {
            self.flags |= status::POINT_OVERFLOW.mask();
        }
        if drops.sobel != self.drops_seen.sobel {
            self.flags |= status::SOBEL_OVERFLOW.mask();
        }
        self.drops_seen = drops;
    }

    /// BUSY falls: the stream engine sends what the frame still holds and `FrameEnd`, then
    /// FRAME_DONE is set and FRAME_COUNT counts the frame.
    fn end_frame(&mut self) {
        self.stream.take(&mut self.datapath);
        self.stream.finish(self.datapath.overflow());
        self.phase = Phase::Idle;
        self.flags |= status::FRAME_DONE.mask();
        self.frame_count = self.frame_count.wrapping_add(1);
    }

    /// Feeds the frame's next pixels to the datapath a line at a time.
    fn feed(&mut self, mut pixels: &[u8]) {
        let width = usize::from(self.frame.width);
        while !pixels.is_empty() && width > 0 {
            let row = if self.line_len == 0 && pixels.len() >= width {
                let Some((row, rest)) = pixels.split_at_checked(width) else {
                    return;
                };
                pixels = rest;
                row
            } else {
                let n = (width - self.line_len).min(pixels.len());
                let (Some((part, rest)), Some(slot)) = (
                    pixels.split_at_checked(n),
                    self.line.get_mut(self.line_len..self.line_len + n),
                ) else {
                    // A line longer than the device gathers: the datapath refused such a
                    // frame when it was armed, so this is not reached.
                    return;
                };
                slot.copy_from_slice(part);
                pixels = rest;
                self.line_len += n;
                if self.line_len < width {
                    return;
                }
                self.line_len = 0;
                match self.line.get(..width) {
                    Some(row) => row,
                    None => return,
                }
            };
            // The row is `width` long and the frame has room for it (`push` counts), so the
            // datapath takes it.
            let _ = self.datapath.push_row(row);
            self.stream.take(&mut self.datapath);
            self.advance(u32::from(self.frame.width));
        }
    }

    /// Pops the point FIFO into POINT_FIFO_DATA's word and the holding registers.
    fn pop_point(&mut self) -> u32 {
        let [data, dxdy, dsdog] = self
            .datapath
            .pop_point()
            .map_or([0; 3], |p| point_words(&p));
        self.point_hold = [dxdy, dsdog];
        data
    }

    /// Pops the Sobel FIFO into SOBEL_FIFO_DATA's word and the holding register.
    fn pop_sobel(&mut self) -> u32 {
        let [data, position] = self
            .datapath
            .pop_sobel()
            .map_or([0; 2], |p| sobel_words(&p));
        self.sobel_hold = position;
        data
    }
}

/// The word `offset` addresses, as the RTL decodes it; `None` outside the window.
fn word(offset: u16) -> Option<u16> {
    (u32::from(offset) < WINDOW_SIZE).then_some(offset & !3)
}

/// A FIFO level as its 16-bit field holds it.
fn level(entries: usize) -> u32 {
    u32::try_from(entries).map_or(u32::from(u16::MAX), |n| n.min(u16::MAX.into()))
}

/// STREAM_FAULT's word for `fault`.
fn fault_word(fault: Option<StreamFault>) -> u32 {
    let (cause, octave, x, y) = match fault {
        None => return 0,
        Some(StreamFault::SobelOrder(p)) => (Cause::SobelOrder, p.octave, p.x, p.y),
        Some(StreamFault::PointOutside { octave, x, y }) => (Cause::PointOutside, octave, x, y),
        Some(StreamFault::Encode) => (Cause::Encode, 0, 0, 0),
    };
    // X and Y keep their low 11 bits, as the register's fields do.
    let put = |field: &stereocal_hdl::Field, value: u32| {
        field
            .bits
            .insert(0, value & field.bits.max_value())
            .unwrap_or(0)
    };
    put(&stream_fault::CAUSE, cause as u32)
        | put(&stream_fault::OCTAVE, u32::from(octave))
        | put(&stream_fault::X, u32::from(x))
        | put(&stream_fault::Y, u32::from(y))
}

impl<F: FrontEnd, const W0: usize, L: ByteSink> FabricDevice<F, W0, L> {
    /// What a read at `offset` gives now: the register decoding of both time models.
    fn sample(&mut self, offset: u16) -> Sample {
        let Some(offset) = word(offset) else {
            return Sample::Word(0);
        };
        Sample::Word(match offset {
            version::OFFSET => version::RESET,
            status::OFFSET => {
                // An arm the strobe makes on this clock counts (always clear when ideal).
                let armed = self.strobes.frame_arm && !self.strobes.soft_reset;
                let busy = u32::from(self.phase != Phase::Idle || armed);
                self.flags | (busy << status::BUSY.bits.lsb)
            }
            point_fifo_level::OFFSET => level(self.datapath.point_level()),
            sobel_fifo_level::OFFSET => level(self.datapath.sobel_level()),
            point_overflow_count::OFFSET => self.datapath.overflow().points,
            sobel_overflow_count::OFFSET => self.datapath.overflow().sobel,
            frame_count::OFFSET => self.frame_count,
            latency_clocks::OFFSET => self.latency,
            // While the stream engine sends a frame the FIFOs are its own: their words read 0
            // and pop nothing.
            point_fifo_data::OFFSET | sobel_fifo_data::OFFSET if self.stream.sending() => 0,
            point_fifo_data::OFFSET => return Sample::PopPoint,
            point_fifo_dxdy::OFFSET => self.point_hold[0],
            point_fifo_dsdog::OFFSET => self.point_hold[1],
            sobel_fifo_data::OFFSET => return Sample::PopSobel,
            sobel_fifo_position::OFFSET => self.sobel_hold,
            stream_points::OFFSET => self.stream.counts().points,
            stream_sobel_packets::OFFSET => self.stream.counts().sobel_packets,
            stream_patches_dropped::OFFSET => self.stream.counts().patches_dropped,
            stream_fault::OFFSET => fault_word(self.stream.fault()),
            // CONTROL and the configuration: stored; other words read 0.
            _ => self.registers.try_read(offset).unwrap_or(0),
        })
    }

    /// Stores a write at `offset` and says what else it asks for: the register decoding of
    /// both time models.
    fn store(&mut self, offset: u16, value: u32) -> Written {
        let Some(offset) = word(offset) else {
            return Written::Stored;
        };
        match offset {
            control::OFFSET => {
                let _ = self.registers.try_write(offset, value);
                Written::Control(Strobes {
                    frame_arm: value & control::FRAME_ARM.mask() != 0,
                    soft_reset: value & control::SOFT_RESET.mask() != 0,
                })
            }
            status::OFFSET => Written::ClearFlags(value & status::REGISTER.w1c_mask),
            stream_control::OFFSET => {
                let _ = self.registers.try_write(offset, value);
                self.stream.set_fec(stream_control::FEC.extract(value) != 0);
                Written::Stored
            }
            // The configuration; the bank ignores writes to `ro` bits and unmapped words.
            _ => {
                let _ = self.registers.try_write(offset, value);
                Written::Stored
            }
        }
    }
}

impl<F: FrontEnd, const W0: usize, L: ByteSink> RegisterBus for FabricDevice<F, W0, L> {
    fn read(&mut self, offset: u16) -> u32 {
        match self.sample(offset) {
            Sample::Word(word) => word,
            Sample::PopPoint => self.pop_point(),
            Sample::PopSobel => self.pop_sobel(),
        }
    }

    /// Bursts over SOBEL_FIFO_DATA and SOBEL_FIFO_POSITION take the datapath's Sobel FIFO's
    /// words at once ([`FrontEnd::drain_sobel_words`]); any other burst is read word by word. Either way the words are those of
    /// [`RegisterBus::read`] one at a time.
    fn read_burst(&mut self, offsets: &[u16], words: &mut [u32]) {
        if offsets != SOBEL_OFFSETS {
            for (word, &offset) in words.iter_mut().zip(offsets.iter().cycle()) {
                *word = self.read(offset);
            }
            return;
        }
        let pairs = words.len() / 2;
        let Some((whole, rest)) = words.split_at_mut_checked(pairs * 2) else {
            return;
        };
        let filled = self.datapath.drain_sobel_words(pairs, whole);
        // Pops of an empty FIFO read 0 and zero the holding register.
        let Some((popped, empty)) = whole.split_at_mut_checked(filled * 2) else {
            return;
        };
        empty.fill(0);
        self.sobel_hold = if empty.is_empty() {
            popped.last().copied().unwrap_or(self.sobel_hold)
        } else {
            0
        };
        for word in rest {
            *word = self.pop_sobel();
        }
    }

    /// The write acts at once (the ideal time model).
    fn write(&mut self, offset: u16, value: u32) {
        match self.store(offset, value) {
            Written::Control(strobes) if strobes.soft_reset => self.soft_reset(),
            Written::Control(strobes) if strobes.frame_arm && self.phase == Phase::Idle => {
                self.arm()
            }
            Written::ClearFlags(flags) => self.flags &= !flags,
            Written::Control(_) | Written::Stored => {}
        }
    }
}

impl<F: FrontEnd, const W0: usize, L: ByteSink> PixelIn for FabricDevice<F, W0, L> {
    fn push(&mut self, pixels: &[u8], start_of_frame: bool) {
        if !self.ready() {
            return;
        }
        if self.phase == Phase::AwaitSof {
            // Only the first pixel can carry SOF: without it, every pixel here is discarded.
            if !start_of_frame || pixels.is_empty() {
                return;
            }
            self.phase = Phase::Run;
        }
        let left = self.frame.total - self.frame.taken;
        let take = pixels
            .len()
            .min(usize::try_from(left).unwrap_or(usize::MAX));
        let Some(pixels) = pixels.get(..take) else {
            return;
        };
        // `take <= left`, a u32.
        self.frame.taken += take as u32;
        if self.frame.taken == self.frame.total {
            self.phase = Phase::Flush;
        }
        self.feed(pixels);
    }

    fn idle(&mut self, clocks: u32) {
        match self.phase {
            Phase::Run => self.advance(clocks),
            Phase::Flush => {
                let width = u32::from(self.frame.width);
                self.frame.blank = self.frame.blank.saturating_add(clocks);
                while self.phase == Phase::Flush && self.frame.blank >= width && width > 0 {
                    self.frame.blank -= width;
                    self.datapath.blank_row();
                    self.stream.take(&mut self.datapath);
                    self.advance(width);
                }
            }
            Phase::Idle | Phase::AwaitSof => {}
        }
    }
}
