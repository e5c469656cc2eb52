//! RTL co-simulation: the Verilated `sc_frontend` (hdl-interface/rtl, built by `build.rs`
//! with the shim in hdl-interface/sim) clocked side by side with the register-level model
//! [`RegisterFrontEnd`], comparing every observation port on every clock.
//!
//! # What is compared
//! Per clock and per octave, the fields of [`ClockProbe`]: the clock enable, the `g[0..4]`
//! wires, the DoG register output, the subsampler output, the point pushed and the Sobel pixel
//! pushed (values and valid strobes); and the `done` output after every rising edge against
//! [`RegisterFrontEnd::octaves_done`], hence the same number of clocks to done. The RTL's data
//! ports count only where their valid bit and the octave's `oct_en` are high (the contract:
//! everything an octave hands out is valid only on its enabled clocks).
//!
//! # Availability
//! Without `verilator` (or before the RTL has an `sc_frontend.v`) the model is not built:
//! [`SKIP`] holds the reason and [`RtlFrontEnd`] does not exist (`cfg(rtl_sim)` unset). Under
//! `CI=true` the build fails instead.

// Without the RTL model only the skip path is compiled.
#![cfg_attr(not(rtl_sim), allow(dead_code, unused_imports))]

use stereocal_firmware::fabric::{ClockProbe, Config, FrontEnd, OctaveProbe, RegisterFrontEnd};

/// Why the RTL model was not built (`None` when it was).
pub const SKIP: Option<&str> = option_env!("STEREOCAL_RTL_SKIP");

/// Counts of valid samples per octave over one frame, for the "not trivially empty" checks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StreamCounts {
    /// Enabled clocks.
    pub en: [u64; 4],
    /// Valid `g[3]` samples.
    pub g3: [u64; 4],
    /// DoG register outputs.
    pub dog: [u64; 4],
    /// Subsampler outputs.
    pub sub: [u64; 4],
    /// Points pushed.
    pub points: [u64; 4],
    /// Sobel pixels pushed.
    pub sobel: [u64; 4],
}

/// Result of one co-simulated frame.
#[derive(Clone, Copy, Debug)]
pub struct FrameRun {
    /// Clocks from the first clock after `start` until `done` (inclusive), equal on both sides.
    pub clocks_to_done: u64,
    /// What flowed, per octave (equal on both sides).
    pub counts: StreamCounts,
}

/// The first difference between the model and the RTL.
#[derive(Clone, Debug)]
pub struct Mismatch {
    /// Clock index counted from 0 = the first clock after `start`.
    pub clock: u64,
    /// Octave, or `None` for `done`.
    pub octave: Option<usize>,
    /// Port / field name.
    pub signal: String,
    /// Rust model's value.
    pub rust: String,
    /// RTL's value.
    pub rtl: String,
    /// Pixels fed so far (including this clock's).
    pub pixels_in: u64,
}

impl std::fmt::Display for Mismatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "clock {}", self.clock)?;
        if let Some(k) = self.octave {
            write!(f, ", octave {k}")?;
        }
        write!(
            f,
            ", signal {}: Rust {} vs RTL {} ({} pixels fed)",
            self.signal, self.rust, self.rtl, self.pixels_in
        )
    }
}

/// First differing signal of one octave's probes, as `(signal, rust, rtl)`.
pub fn diff_octave(r: &OctaveProbe, v: &OctaveProbe) -> Option<(String, String, String)> {
    fn d<T: PartialEq + std::fmt::Debug>(
        name: &str,
        a: &T,
        b: &T,
    ) -> Option<(String, String, String)> {
        (a != b).then(|| (name.to_string(), format!("{a:?}"), format!("{b:?}")))
    }
    d("oct_en", &r.en, &v.en)
        .or_else(|| (0..4).find_map(|i| d(&format!("g[{i}] (g_valid/g_data)"), &r.g[i], &v.g[i])))
        .or_else(|| d("dog (dog_valid/dog_data)", &r.dog, &v.dog))
        .or_else(|| d("sub (sub_valid/sub_data)", &r.sub, &v.sub))
        .or_else(|| d("point (pt_valid/pt_data)", &r.point, &v.point))
        .or_else(|| d("sobel (sb_valid/sb_data)", &r.sobel, &v.sobel))
}

fn count(c: &mut StreamCounts, p: &ClockProbe) {
    for (k, o) in p.octaves.iter().enumerate() {
        c.en[k] += o.en as u64;
        c.g3[k] += o.g[3].is_some() as u64;
        c.dog[k] += o.dog.is_some() as u64;
        c.sub[k] += o.sub.is_some() as u64;
        c.points[k] += o.point.is_some() as u64;
        c.sobel[k] += o.sobel.is_some() as u64;
    }
}

/// Upper bound on the clocks a frame may take after its last pixel before `done`.
pub fn flush_bound(cfg: &Config) -> u64 {
    64 * (cfg.width as u64 + 16) + 10_000
}

/// The pixels of a `width` x `height` image, one per clock.
pub fn back_to_back(img: &[u8]) -> Vec<Option<u8>> {
    img.iter().copied().map(Some).collect()
}

#[cfg(rtl_sim)]
mod ffi {
    use std::ffi::c_int;

    #[repr(C)]
    pub struct SimConfig {
        pub width: u16,
        pub height: u16,
        pub octaves: u8,
        pub edge_ratio: u8,
        pub sobel_scale: u8,
        pub pad: u8,
        pub contrast: u16,
        pub max_offset: u16,
    }

    #[repr(C)]
    #[derive(Default)]
    pub struct SimObs {
        pub en: [u8; 4],
        pub g_valid: [[u8; 4]; 4],
        pub g: [[u16; 4]; 4],
        pub dog_valid: [u8; 4],
        pub dog: [[i16; 3]; 4],
        pub sub_valid: [u8; 4],
        pub sub: [u16; 4],
        pub pt_valid: [u8; 4],
        pub pt: [[u16; 6]; 4],
        pub sb_valid: [u8; 4],
        pub sb_x: [u16; 4],
        pub sb_y: [u16; 4],
        pub sb_mag: [u8; 4],
        pub sb_ori: [u8; 4],
        pub done: u8,
    }

    #[repr(C)]
    pub struct Sim {
        _private: [u8; 0],
    }

    extern "C" {
        pub fn sc_sim_new(rand_seed: u32) -> *mut Sim;
        pub fn sc_sim_free(sim: *mut Sim);
        pub fn sc_sim_start(sim: *mut Sim, cfg: *const SimConfig);
        pub fn sc_sim_clock(sim: *mut Sim, pix_valid: c_int, pix_data: u8, obs: *mut SimObs);
        pub fn sc_sim_obs_size() -> u32;
    }
}

/// The Verilated `sc_frontend`, one instance in its own Verilator context.
#[cfg(rtl_sim)]
pub struct RtlFrontEnd {
    sim: std::ptr::NonNull<ffi::Sim>,
    obs: ffi::SimObs,
}

// The model is owned exclusively and its context is private to it.
#[cfg(rtl_sim)]
unsafe impl Send for RtlFrontEnd {}

#[cfg(rtl_sim)]
impl Drop for RtlFrontEnd {
    fn drop(&mut self) {
        // SAFETY: `sim` came from `sc_sim_new` and is freed once.
        unsafe { ffi::sc_sim_free(self.sim.as_ptr()) }
    }
}

#[cfg(rtl_sim)]
impl Default for RtlFrontEnd {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(rtl_sim)]
impl RtlFrontEnd {
    /// A fresh model (inputs low), every register and memory at 0.
    pub fn new() -> Self {
        Self::with_power_up(0)
    }

    /// A fresh model whose registers and memories power up to random values drawn from
    /// `seed` (0: all zero).
    pub fn with_power_up(seed: u32) -> Self {
        // SAFETY: plain C calls without arguments.
        let size = unsafe { ffi::sc_sim_obs_size() } as usize;
        assert_eq!(
            size,
            std::mem::size_of::<ffi::SimObs>(),
            "sc_sim_obs layout differs between sc_sim.h and rtl.rs"
        );
        // SAFETY: as above.
        let sim = std::ptr::NonNull::new(unsafe { ffi::sc_sim_new(seed) }).expect("sc_sim_new");
        Self {
            sim,
            obs: ffi::SimObs::default(),
        }
    }

    /// The `start` clock with `cfg` on the `cfg_*` inputs.
    pub fn start(&mut self, cfg: &Config) {
        let c = ffi::SimConfig {
            width: cfg.width,
            height: cfg.height,
            octaves: cfg.octaves,
            edge_ratio: cfg.edge_ratio,
            sobel_scale: cfg.sobel_scale,
            pad: 0,
            contrast: cfg.contrast_threshold,
            max_offset: cfg.max_offset,
        };
        // SAFETY: `sim` is live; `c` outlives the call.
        unsafe { ffi::sc_sim_start(self.sim.as_ptr(), &c) }
    }

    /// One clock: the observation ports during it (qualified by `oct_en` and the valid bits)
    /// and `done` after its rising edge.
    pub fn clock(&mut self, pixel: Option<u8>) -> (ClockProbe, bool) {
        // SAFETY: `sim` is live; `obs` is a valid, exclusively borrowed `sc_sim_obs`.
        unsafe {
            ffi::sc_sim_clock(
                self.sim.as_ptr(),
                pixel.is_some() as _,
                pixel.unwrap_or(0),
                &mut self.obs,
            )
        }
        (probe_of(&self.obs), self.obs.done != 0)
    }
}

#[cfg(rtl_sim)]
fn probe_of(o: &ffi::SimObs) -> ClockProbe {
    use stereocal_firmware::fabric::refine::Offset;
    use stereocal_firmware::fabric::{Extremum, SobelEntry};
    let mut p = ClockProbe::IDLE;
    for (k, q) in p.octaves.iter_mut().enumerate() {
        if o.en[k] == 0 {
            continue;
        }
        let on = |b: u8| b != 0;
        q.en = true;
        for i in 0..4 {
            q.g[i] = on(o.g_valid[k][i]).then_some(o.g[k][i]);
        }
        q.dog = on(o.dog_valid[k]).then_some(o.dog[k]);
        q.sub = on(o.sub_valid[k]).then_some(o.sub[k]);
        let pt = o.pt[k];
        q.point = on(o.pt_valid[k]).then_some(Extremum {
            x: pt[0],
            y: pt[1],
            octave: k as u8,
            scale: 1,
            dx: Offset::from_bits(pt[2] as i16),
            dy: Offset::from_bits(pt[3] as i16),
            ds: Offset::from_bits(pt[4] as i16),
            dog: pt[5] as i16,
        });
        q.sobel = on(o.sb_valid[k]).then_some(SobelEntry {
            octave: k as u8,
            orientation: o.sb_ori[k],
            magnitude: o.sb_mag[k],
            x: o.sb_x[k],
            y: o.sb_y[k],
        });
    }
    p
}

/// Starts both sides with `cfg` and runs exactly `stimulus.len()` clocks (`None` = no pixel),
/// comparing every observation signal on every clock and `done` after every clock; returns
/// what flowed. The frame need not be complete (an aborted frame).
#[cfg(rtl_sim)]
pub fn cosim_clocks(
    model: &mut RegisterFrontEnd,
    rtl: &mut RtlFrontEnd,
    cfg: &Config,
    stimulus: &[Option<u8>],
) -> Result<StreamCounts, Box<Mismatch>> {
    let mut run = Lockstep::start(model, rtl, cfg);
    for &pixel in stimulus {
        run.clock(pixel)?;
    }
    Ok(run.counts)
}

/// Runs one frame through `model` and `rtl` side by side: `start` with `cfg`, then one clock
/// per element of `stimulus` (`None` = no pixel), then blanking clocks until both are done.
/// Compares every observation signal on every clock and `done` after every clock.
#[cfg(rtl_sim)]
pub fn cosim_frame(
    model: &mut RegisterFrontEnd,
    rtl: &mut RtlFrontEnd,
    cfg: &Config,
    stimulus: &[Option<u8>],
) -> Result<FrameRun, Box<Mismatch>> {
    let pixels = stimulus.iter().flatten().count();
    assert_eq!(
        pixels,
        cfg.width as usize * cfg.height as usize,
        "one pixel per position"
    );
    let mut run = Lockstep::start(model, rtl, cfg);
    let limit = stimulus.len() as u64 + flush_bound(cfg);
    loop {
        let pixel = stimulus.get(run.clock as usize).copied().flatten();
        let done = run.clock(pixel)?;
        if done && run.clock >= stimulus.len() as u64 {
            return Ok(FrameRun {
                clocks_to_done: run.clock,
                counts: run.counts,
            });
        }
        assert!(
            run.clock < limit,
            "neither side done {} clocks after the last pixel",
            flush_bound(cfg)
        );
    }
}

/// The two sides clocked together.
#[cfg(rtl_sim)]
struct Lockstep<'a> {
    model: &'a mut RegisterFrontEnd,
    rtl: &'a mut RtlFrontEnd,
    counts: StreamCounts,
    pixels_in: u64,
    clock: u64,
}

#[cfg(rtl_sim)]
impl<'a> Lockstep<'a> {
    fn start(model: &'a mut RegisterFrontEnd, rtl: &'a mut RtlFrontEnd, cfg: &Config) -> Self {
        model.start_frame(cfg).expect("valid configuration");
        rtl.start(cfg);
        Self {
            model,
            rtl,
            counts: StreamCounts::default(),
            pixels_in: 0,
            clock: 0,
        }
    }

    /// One clock on both sides; `Ok(done)` when everything matched.
    fn clock(&mut self, pixel: Option<u8>) -> Result<bool, Box<Mismatch>> {
        self.pixels_in += pixel.is_some() as u64;
        self.model.clock(pixel);
        let rust_probe = *self.model.probe();
        // The point and Sobel FIFOs of the model are not the RTL's: keep them drained.
        while self.model.pop_point().is_some() {}
        while self.model.pop_sobel().is_some() {}
        let (rtl_probe, rtl_done) = self.rtl.clock(pixel);
        let (clock, pixels_in) = (self.clock, self.pixels_in);
        let mismatch = |octave, (signal, rust, rtl)| {
            Box::new(Mismatch {
                clock,
                octave,
                signal,
                rust,
                rtl,
                pixels_in,
            })
        };
        for k in 0..4 {
            if let Some(d) = diff_octave(&rust_probe.octaves[k], &rtl_probe.octaves[k]) {
                return Err(mismatch(Some(k), d));
            }
        }
        count(&mut self.counts, &rust_probe);
        let rust_done = self.model.octaves_done();
        if rust_done != rtl_done {
            let d = (
                "done".to_string(),
                rust_done.to_string(),
                rtl_done.to_string(),
            );
            return Err(mismatch(None, d));
        }
        self.clock += 1;
        Ok(rust_done)
    }
}
