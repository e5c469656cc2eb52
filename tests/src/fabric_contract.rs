//! The contract co-simulation: the same bus accesses and pixels, clock by clock, into the
//! device model ([`FabricDevice::clock`], the register-level datapath behind it) and into the
//! Verilated `sc_fabric` ([`crate::rtl_fabric`]), comparing PIXEL_IN's ready and every word
//! read on every clock.
//!
//! The stimulus is seeded and random: a free-running [`Camera`] (frames of random sizes and
//! content with random gaps, offered whether or not PIXEL_IN is ready, as a camera does) and
//! a [`Schedule`] playing a driver that is sometimes diligent and sometimes careless:
//! random valid configurations, FRAME_ARM (and re-arms while busy), reads of every register
//! of the map and of unmapped or misaligned offsets at random clocks, `w1c` writes to STATUS,
//! configuration writes mid-frame, ENABLE dropped for a while, SOFT_RESET mid-frame or
//! mid-flush, FIFOs left undrained until they overflow, and after most frames both FIFOs
//! drained word by word through POINT_FIFO_* and SOBEL_FIFO_*. The schedule decides from
//! the words it reads, which are the same on both sides until the first mismatch.

use std::collections::VecDeque;
use std::fmt;

use stereocal::driver::register_writes;
use stereocal_firmware::fabric::device::{Access, Beat, Clocked};
use stereocal_firmware::fabric::Config;
use stereocal_hdl::regs::{
    self, control, output_mode, point_fifo_data, point_fifo_dsdog, point_fifo_dxdy,
    sobel_fifo_data, sobel_fifo_position, status, WINDOW_SIZE,
};
use stereocal_hdl::{register_at, FabricConfig};

use crate::rng::Rng;
use crate::rtl_fabric::{W0, W1, W2, W3};

/// A free-running camera on PIXEL_IN: frames in raster order, SOF on the first pixel and EOL
/// on the last of each line, random gaps inside and blanking between frames. It offers each
/// pixel once, whether or not the port is ready.
#[derive(Clone, Debug)]
pub struct Camera {
    rng: Rng,
    width: usize,
    image: Vec<u8>,
    /// Index of the next pixel in `image`.
    at: usize,
    /// Clocks of blanking left before the next frame.
    blank: u64,
    /// Per mille of clocks without a pixel inside a frame.
    gaps: u64,
    /// The size of the next frame.
    next_size: (u16, u16),
}

impl Camera {
    /// A camera that starts with blanking and frames of `width` x `height`.
    pub fn new(seed: u64, width: u16, height: u16) -> Self {
        Self {
            rng: Rng::new(seed),
            width: 0,
            image: Vec::new(),
            at: 0,
            blank: 10,
            gaps: 0,
            next_size: (width, height),
        }
    }

    /// Frames from the next one on are `width` x `height`.
    pub fn resize(&mut self, width: u16, height: u16) {
        self.next_size = (width, height);
    }

    /// What the camera puts on PIXEL_IN this clock.
    pub fn beat(&mut self) -> Option<Beat> {
        if self.at == self.image.len() {
            if self.blank > 0 {
                self.blank -= 1;
                return None;
            }
            self.start_frame();
        }
        if self.at > 0 && self.rng.chance(self.gaps) {
            return None;
        }
        let data = *self.image.get(self.at)?;
        let beat = Beat {
            data,
            sof: self.at == 0,
            eol: (self.at + 1) % self.width == 0,
        };
        self.at += 1;
        if self.at == self.image.len() {
            self.blank = self.rng.range(0, 3 * self.width as u64);
        }
        Some(beat)
    }

    /// A new frame: mostly round blobs on a textured background (a few dozen points), else
    /// noise or a flat field with a few impulses (hardly any), with gaps of 0 to 60 %.
    fn start_frame(&mut self) {
        let (w, h) = (self.next_size.0 as usize, self.next_size.1 as usize);
        let r = &mut self.rng;
        self.image = match r.below(5) {
            0 => (0..w * h).map(|_| r.bits() as u8).collect(),
            1..=3 => r.blob_image(w, h),
            _ => {
                let mut img = vec![r.below(256) as u8; w * h];
                for _ in 0..4 {
                    let i = r.below((w * h) as u64) as usize;
                    img[i] = r.bits() as u8;
                }
                img
            }
        };
        self.width = w;
        self.at = 0;
        self.gaps = [0, 0, 100, 300, 600][r.below(5) as usize];
    }
}

/// A random configuration the driver would write: valid for [`FabricConfig::validate`] and
/// for the model's memories ([`Config::validate`] at `W0` .. `W3`), at most `W0` x 48.
pub fn random_config(r: &mut Rng) -> FabricConfig {
    loop {
        let octaves = r.range(1, 4) as u8;
        let step = 1u64 << (octaves - 1);
        // Mostly at least 32 x 24 (smaller frames hardly have extrema).
        let min = |r: &mut Rng, small: u64| if r.chance(200) { 16 } else { small };
        let side = |r: &mut Rng, min: u64, max: u64| {
            (r.range(min.div_ceil(step), max / step) * step) as u16
        };
        let (min_width, min_height) = (min(r, 32), min(r, 24));
        let config = FabricConfig {
            width: side(r, min_width, W0 as u64),
            height: side(r, min_height, 48),
            octaves,
            contrast_threshold: [0, 0, 16, 64, 256, 1024][r.below(6) as usize] + r.below(16) as u16,
            // Mostly Lowe's 10 and above (a small ratio rejects nearly every extremum).
            edge_ratio: if r.chance(200) {
                r.range(1, 31)
            } else {
                r.range(10, 31)
            } as u8,
            sobel_output: if r.chance(500) {
                output_mode::SobelOutput::Rows
            } else {
                output_mode::SobelOutput::Patches
            },
            sobel_scale: r.below(4) as u8,
            points_per_batch: r.range(1, 128) as u8,
            row_segment: r.range(16, 1280) as u16,
            // Mostly loose bounds (a tight one rejects nearly every extremum).
            max_offset: if r.chance(200) {
                r.range(0, 8191)
            } else {
                r.range(4096, 8191)
            } as u16,
        };
        if config.validate().is_ok() && Config::from(&config).validate([W0, W1, W2, W3]).is_ok() {
            return config;
        }
    }
}

/// The register writes [`FabricConfig::write_to`] makes, in its order.
pub fn config_writes(config: &FabricConfig) -> Vec<(u16, u32)> {
    register_writes(|bus| config.write_to(bus)).expect("a valid configuration")
}

/// Where the schedule's driver is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    /// Writing the configuration, then FRAME_ARM.
    Configure,
    /// The frame runs: random traffic, polling STATUS for its end.
    Running,
    /// Popping points until VALID reads 0.
    DrainPoints,
    /// Popping Sobel pixels until VALID reads 0.
    DrainSobel,
}

/// How a frame's driver behaves.
#[derive(Clone, Copy, Debug)]
struct Habits {
    /// Per mille of clocks with a random read while the frame runs.
    reads: u64,
    /// Per mille of those reads that pop a FIFO.
    pops: u64,
    /// Drain both FIFOs after the frame (otherwise they are left to overflow).
    drain: bool,
    /// The clock of the frame (from FRAME_ARM) at which SOFT_RESET aborts it, if it does.
    abort_at: Option<u64>,
}

/// The driver's side of the stimulus: one bus access (or none) per clock.
#[derive(Clone, Debug)]
pub struct Schedule {
    rng: Rng,
    stage: Stage,
    habits: Habits,
    /// Accesses queued for the next clocks (`None`: a clock without one).
    plan: VecDeque<Option<Access>>,
    /// Clocks since FRAME_ARM.
    frame_clock: u64,
    /// ENABLE as last written.
    enable: bool,
    /// The configuration written last.
    config: FabricConfig,
    /// What it did so far.
    pub stats: Stats,
}

/// What a schedule did, for the test's "not trivially empty" checks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    pub frames_armed: u64,
    pub frames_done: u64,
    pub soft_resets: u64,
    /// Points popped (reads of POINT_FIFO_DATA with VALID).
    pub points_read: u64,
    /// Sobel pixels popped.
    pub sobel_read: u64,
    pub point_overflows: u64,
    pub sobel_overflows: u64,
    pub reads: u64,
}

/// Frames running longer than this many clocks are aborted (a camera frame smaller than the
/// configuration's waits for the next frame's pixels, which is legal but slow).
const FRAME_TIMEOUT: u64 = 40_000;

impl Schedule {
    /// A schedule starting with a configuration.
    pub fn new(seed: u64) -> Self {
        Self {
            rng: Rng::new(seed),
            stage: Stage::Configure,
            habits: Habits {
                reads: 0,
                pops: 0,
                drain: true,
                abort_at: None,
            },
            plan: VecDeque::new(),
            frame_clock: 0,
            enable: false,
            config: FabricConfig::default(),
            stats: Stats::default(),
        }
    }

    /// The access of this clock; the camera follows the configuration it writes.
    pub fn access(&mut self, camera: &mut Camera) -> Option<Access> {
        self.frame_clock += 1;
        if let Some(step) = self.plan.pop_front() {
            if let Some(Access::Write(control::OFFSET, value)) = step {
                if value & control::FRAME_ARM.mask() != 0 {
                    self.frame_clock = 0;
                }
            }
            return step;
        }
        match self.stage {
            Stage::Configure => self.configure(camera),
            Stage::Running => return self.running(),
            Stage::DrainPoints => self
                .plan
                .push_back(Some(Access::Read(point_fifo_data::OFFSET))),
            Stage::DrainSobel => self
                .plan
                .push_back(Some(Access::Read(sobel_fifo_data::OFFSET))),
        }
        self.plan.pop_front().flatten()
    }

    /// What a read returned (the same on both sides).
    pub fn observe(&mut self, access: Access, word: u32) {
        let Access::Read(offset) = access else { return };
        self.stats.reads += 1;
        let valid = word >> 31 != 0;
        self.stats.points_read += u64::from(offset == point_fifo_data::OFFSET && valid);
        self.stats.sobel_read += u64::from(offset == sobel_fifo_data::OFFSET && valid);
        match (self.stage, offset) {
            // Not on the clock right after FRAME_ARM: there BUSY must read 1 unless the same
            // write reset the fabric.
            (Stage::Running, status::OFFSET)
                if word & status::BUSY.mask() == 0 && self.frame_clock > 1 =>
            {
                if word & status::FRAME_DONE.mask() != 0 {
                    self.stats.frames_done += 1;
                }
                self.stats.point_overflows += u64::from(word & status::POINT_OVERFLOW.mask() != 0);
                self.stats.sobel_overflows += u64::from(word & status::SOBEL_OVERFLOW.mask() != 0);
                // Clear the flags (sometimes not all of them), then drain or leave the FIFOs.
                let clear = if self.rng.chance(700) {
                    status::REGISTER.w1c_mask
                } else {
                    self.rng.bits() as u32
                };
                self.plan
                    .push_back(Some(Access::Write(status::OFFSET, clear)));
                self.stage = if self.habits.drain {
                    Stage::DrainPoints
                } else {
                    Stage::Configure
                };
            }
            (Stage::DrainPoints, point_fifo_data::OFFSET) if valid => {
                // The other two words, in either order, sometimes twice.
                let mut words = [point_fifo_dxdy::OFFSET, point_fifo_dsdog::OFFSET];
                if self.rng.chance(500) {
                    words.swap(0, 1);
                }
                for offset in words {
                    self.plan.push_back(Some(Access::Read(offset)));
                    if self.rng.chance(100) {
                        self.plan.push_back(None);
                        self.plan.push_back(Some(Access::Read(offset)));
                    }
                }
            }
            (Stage::DrainPoints, point_fifo_data::OFFSET) => self.stage = Stage::DrainSobel,
            (Stage::DrainSobel, sobel_fifo_data::OFFSET) if valid => {
                self.plan
                    .push_back(Some(Access::Read(sobel_fifo_position::OFFSET)));
            }
            (Stage::DrainSobel, sobel_fifo_data::OFFSET) => {
                // Every register once, then the next frame.
                for r in regs::REGISTERS.iter().filter(|r| !r.pops_on_read) {
                    self.plan.push_back(Some(Access::Read(r.offset)));
                }
                self.stage = Stage::Configure;
            }
            _ => {}
        }
    }

    /// Plans the configuration writes (in random order, with gaps and reads in between) and
    /// FRAME_ARM, then a read of STATUS on the very next clock; picks the frame's habits.
    fn configure(&mut self, camera: &mut Camera) {
        let r = &mut self.rng;
        let config = random_config(r);
        self.config = config;
        // Mostly the camera follows; sometimes it keeps its size (a frame of the wrong size).
        if r.chance(900) {
            camera.resize(config.width, config.height);
        }
        let mut writes = config_writes(&config);
        for i in (1..writes.len()).rev() {
            writes.swap(i, r.below(i as u64 + 1) as usize);
        }
        for (offset, value) in writes {
            for _ in 0..r.below(3) {
                self.plan.push_back(None);
            }
            if r.chance(200) {
                let offset = random_offset(r, 0);
                self.plan.push_back(Some(Access::Read(offset)));
            }
            self.plan.push_back(Some(Access::Write(offset, value)));
        }
        // FRAME_ARM with ENABLE (sometimes without, enabled later; sometimes with
        // SOFT_RESET in the same write, which wins).
        let mut arm = control::FRAME_ARM.mask();
        self.enable = !r.chance(50);
        if self.enable {
            arm |= control::ENABLE.mask();
        }
        if r.chance(20) {
            arm |= control::SOFT_RESET.mask();
        }
        self.plan
            .push_back(Some(Access::Write(control::OFFSET, arm)));
        self.plan.push_back(Some(Access::Read(status::OFFSET)));
        self.stats.frames_armed += 1;
        let lazy = r.chance(300);
        self.habits = Habits {
            reads: if lazy {
                20
            } else {
                [100, 400, 900][r.below(3) as usize]
            },
            pops: if lazy { 0 } else { r.range(100, 900) },
            drain: !lazy,
            abort_at: r.chance(120).then(|| r.range(1, 6000)),
        };
        self.frame_clock = 0;
        self.stage = Stage::Running;
    }

    /// One clock of random traffic while the frame runs.
    fn running(&mut self) -> Option<Access> {
        let r = &mut self.rng;
        let enable = if self.enable {
            control::ENABLE.mask()
        } else {
            0
        };
        if self.habits.abort_at == Some(self.frame_clock) || self.frame_clock > FRAME_TIMEOUT {
            self.stats.soft_resets += 1;
            self.habits.abort_at = None;
            self.frame_clock = 0;
            // A read on the strobe's clock (what SOFT_RESET clears must read cleared);
            // a later STATUS poll sees BUSY low and moves on.
            let offset = if r.chance(300) {
                status::OFFSET
            } else {
                random_offset(r, 300)
            };
            self.plan.push_back(Some(Access::Read(offset)));
            return Some(Access::Write(
                control::OFFSET,
                enable | control::SOFT_RESET.mask(),
            ));
        }
        if !self.enable && r.chance(5) {
            self.enable = true;
            return Some(Access::Write(control::OFFSET, control::ENABLE.mask()));
        }
        if r.chance(2) {
            // ENABLE low for a while: PIXEL_IN not ready.
            self.enable = false;
            return Some(Access::Write(control::OFFSET, 0));
        }
        if r.chance(3) {
            // A re-arm while busy (ignored), or an arm after the frame ended on its own.
            return Some(Access::Write(
                control::OFFSET,
                enable | control::FRAME_ARM.mask(),
            ));
        }
        if r.chance(3) {
            return Some(Access::Write(status::OFFSET, r.bits() as u32));
        }
        if r.chance(2) {
            // A configuration register rewritten mid-frame: the frame's geometry as it is,
            // anything else from another valid configuration (so that a re-arm latches a
            // valid configuration).
            let geometry = [
                regs::width::OFFSET,
                regs::height::OFFSET,
                regs::octaves::OFFSET,
            ];
            let other = config_writes(&random_config(r));
            let writes: Vec<_> = config_writes(&self.config)
                .into_iter()
                .zip(other)
                .map(|(now, other)| {
                    if geometry.contains(&now.0) {
                        now
                    } else {
                        other
                    }
                })
                .collect();
            let (offset, value) = writes[r.below(writes.len() as u64) as usize];
            return Some(Access::Write(offset, value));
        }
        if r.chance(self.habits.reads) {
            let offset = random_offset(r, self.habits.pops);
            return Some(Access::Read(offset));
        }
        if r.chance(30) {
            return Some(Access::Read(status::OFFSET));
        }
        None
    }
}

/// A read offset: a register of the map (a FIFO's pop with `pops` per mille), sometimes
/// misaligned, unmapped or beyond the map.
fn random_offset(r: &mut Rng, pops: u64) -> u16 {
    if r.chance(pops) {
        return if r.chance(300) {
            point_fifo_data::OFFSET
        } else {
            sobel_fifo_data::OFFSET
        };
    }
    if r.chance(30) {
        return r.below(u64::from(WINDOW_SIZE)) as u16;
    }
    let plain: Vec<_> = regs::REGISTERS.iter().filter(|r| !r.pops_on_read).collect();
    plain[r.below(plain.len() as u64) as usize].offset
}

/// The first difference between the device model and the RTL.
#[derive(Clone, Debug)]
pub struct Mismatch {
    /// Clocks since the RTL's reset (0 = the first compared clock).
    pub clock: u64,
    /// The clock's bus access.
    pub access: Option<Access>,
    /// The clock's pixel.
    pub pixel: Option<Beat>,
    /// What differs: a register's name, or PIXEL_IN's ready.
    pub what: String,
    /// The device model's value.
    pub model: String,
    /// The RTL's value.
    pub rtl: String,
}

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "clock {}, access {:?}, pixel {:?}: {}: model {} vs RTL {}",
            self.clock, self.access, self.pixel, self.what, self.model, self.rtl
        )
    }
}

/// The name of the register a read at `offset` addresses, as the RTL decodes it.
pub fn register_name(offset: u16) -> String {
    let word = offset & !3;
    match register_at(word) {
        Some(r) if u32::from(offset) < WINDOW_SIZE => format!("{} (offset {offset:#04x})", r.name),
        _ => format!("no register (offset {offset:#04x})"),
    }
}

/// Compares what one clock showed on both sides.
pub fn compare(
    clock: u64,
    pixel: Option<Beat>,
    access: Option<Access>,
    model: Clocked,
    rtl: Clocked,
) -> Result<(), Box<Mismatch>> {
    let mismatch = |what: String, model: String, rtl: String| {
        Box::new(Mismatch {
            clock,
            access,
            pixel,
            what,
            model,
            rtl,
        })
    };
    if model.ready != rtl.ready {
        return Err(mismatch(
            "PIXEL_IN ready".into(),
            model.ready.to_string(),
            rtl.ready.to_string(),
        ));
    }
    if model.read != rtl.read {
        let name = match access {
            Some(Access::Read(offset)) => register_name(offset),
            _ => "bus_rdata".into(),
        };
        let hex = |w: Option<u32>| w.map_or("none".into(), |w| format!("{w:#010x}"));
        return Err(mismatch(name, hex(model.read), hex(rtl.read)));
    }
    Ok(())
}

/// Runs `clocks` clocks of the schedule seeded with `seed` through a fresh device model and
/// a fresh Verilated `sc_fabric` (its registers and memories powered up to random values
/// drawn from the seed, then reset), comparing every clock; returns what the schedule did.
#[cfg(rtl_sim)]
pub fn run(seed: u64, clocks: u64) -> Result<Stats, Box<Mismatch>> {
    let mut model = crate::rtl_fabric::model_fabric();
    let mut rtl = crate::rtl_fabric::RtlFabric::new(seed as u32);
    let mut camera = Camera::new(seed ^ 0x005e_edca_3e7a, 32, 24);
    let mut schedule = Schedule::new(seed);
    for clock in 0..clocks {
        let pixel = camera.beat();
        let access = schedule.access(&mut camera);
        let shown = model.clock(pixel, access);
        compare(clock, pixel, access, shown, rtl.clock(pixel, access))?;
        if let (Some(access), Some(word)) = (access, shown.read) {
            schedule.observe(access, word);
        }
    }
    Ok(schedule.stats)
}
