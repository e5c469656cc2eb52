//! The Verilated `sc_fabric` (hdl-interface/rtl, built by `build.rs` with the shim
//! hdl-interface/sim/sc_fabric_sim.cpp at the sizes of [`W0`] .. [`SOBEL_DEPTH`]) and the
//! device model of the same sizes, [`ModelFabric`]: the two sides of the contract
//! co-simulation ([`crate::fabric_contract`]).
//!
//! Without `verilator` the model is not built ([`crate::rtl::SKIP`] says why) and
//! [`RtlFabric`] does not exist.

// Without the RTL model only the sizes are compiled.
#![cfg_attr(not(rtl_sim), allow(dead_code, unused_imports))]

use stereocal_firmware::fabric::device::{Access, Beat, Clocked};
use stereocal_firmware::fabric::{FabricDevice, RegisterFrontEnd};

/// Octave 0's line memories (`sc_fabric`'s W0): frames up to 64 pixels wide.
pub const W0: usize = 64;
/// Octave 1's.
pub const W1: usize = 32;
/// Octave 2's.
pub const W2: usize = 16;
/// Octave 3's (at least 12, the alignment FIFOs' minimum).
pub const W3: usize = 12;
/// The point FIFO's depth (`POINT_DEPTH`): a frame here brings a few points, often more.
pub const POINT_DEPTH: usize = 8;
/// The Sobel FIFO's depth (`SOBEL_DEPTH`): 3 lines of octave 0, as the model's.
pub const SOBEL_DEPTH: usize = 3 * W0;

/// The device model at the RTL's sizes, clocked through [`FabricDevice::clock`].
pub type ModelFabric = FabricDevice<RegisterFrontEnd<W0, W1, W2, W3, POINT_DEPTH>, W0>;

/// A fresh device model (after power-up: the state `sc_fabric` has after `rst`).
pub fn model_fabric() -> Box<ModelFabric> {
    Box::new(FabricDevice::new(RegisterFrontEnd::new()))
}

#[cfg(rtl_sim)]
mod ffi {
    #[repr(C)]
    #[derive(Debug, PartialEq, Eq)]
    pub struct Params {
        pub w0: u32,
        pub w1: u32,
        pub w2: u32,
        pub w3: u32,
        pub point_depth: u32,
        pub sobel_depth: u32,
    }

    #[repr(C)]
    #[derive(Default)]
    pub struct In {
        pub bus_wdata: u32,
        pub bus_addr: u8,
        pub bus_we: u8,
        pub bus_re: u8,
        pub pixel_valid: u8,
        pub pixel_data: u8,
        pub pixel_sof: u8,
        pub pixel_eol: u8,
        pub rst: u8,
        pub pix_ce: u8,
        pub link_ready: u8,
    }

    #[repr(C)]
    #[derive(Default)]
    pub struct Out {
        pub bus_rdata: u32,
        pub pixel_ready: u8,
        pub link_valid: u8,
        pub link_data: u8,
        pub pad: u8,
    }

    #[repr(C)]
    pub struct Sim {
        _private: [u8; 0],
    }

    extern "C" {
        pub fn sc_fabric_sim_new(rand_seed: u32) -> *mut Sim;
        pub fn sc_fabric_sim_free(sim: *mut Sim);
        pub fn sc_fabric_sim_clock(sim: *mut Sim, input: *const In, out: *mut Out);
        pub fn sc_fabric_sim_params() -> Params;
        pub fn sc_fabric_sim_in_size() -> u32;
        pub fn sc_fabric_sim_out_size() -> u32;
    }
}

/// The Verilated `sc_fabric`, one instance in its own Verilator context.
#[cfg(rtl_sim)]
pub struct RtlFabric {
    sim: std::ptr::NonNull<ffi::Sim>,
}

// The model is owned exclusively and its context is private to it.
#[cfg(rtl_sim)]
unsafe impl Send for RtlFabric {}

#[cfg(rtl_sim)]
impl Drop for RtlFabric {
    fn drop(&mut self) {
        // SAFETY: `sim` came from `sc_fabric_sim_new` and is freed once.
        unsafe { ffi::sc_fabric_sim_free(self.sim.as_ptr()) }
    }
}

#[cfg(rtl_sim)]
impl RtlFabric {
    /// A model whose registers and memories power up to random values drawn from `seed`
    /// (0: all zero), then reset: a clock with `rst` high and the clock after it (on which
    /// `sc_frontend` latches the configuration's reset values), both without a bus access
    /// or a pixel. It then holds what the device model holds after [`model_fabric`].
    pub fn new(seed: u32) -> Self {
        // SAFETY: plain C calls without arguments.
        let (params, in_size, out_size) = unsafe {
            (
                ffi::sc_fabric_sim_params(),
                ffi::sc_fabric_sim_in_size() as usize,
                ffi::sc_fabric_sim_out_size() as usize,
            )
        };
        assert_eq!(
            (in_size, out_size),
            (
                std::mem::size_of::<ffi::In>(),
                std::mem::size_of::<ffi::Out>()
            ),
            "sc_fabric_in / sc_fabric_out layout differs between sc_fabric_sim.h and rtl_fabric.rs"
        );
        let sizes = [W0, W1, W2, W3, POINT_DEPTH, SOBEL_DEPTH].map(|n| n as u32);
        assert_eq!(
            params,
            ffi::Params {
                w0: sizes[0],
                w1: sizes[1],
                w2: sizes[2],
                w3: sizes[3],
                point_depth: sizes[4],
                sobel_depth: sizes[5],
            },
            "tests/build.rs built sc_fabric with other sizes than rtl_fabric.rs models"
        );
        // SAFETY: a plain C call.
        let sim = std::ptr::NonNull::new(unsafe { ffi::sc_fabric_sim_new(seed) })
            .expect("sc_fabric_sim_new");
        let mut rtl = Self { sim };
        rtl.step(&ffi::In {
            rst: 1,
            pix_ce: 1,
            ..ffi::In::default()
        });
        rtl.step(&ffi::In {
            pix_ce: 1,
            ..ffi::In::default()
        });
        rtl
    }

    fn step(&mut self, input: &ffi::In) -> ffi::Out {
        let mut out = ffi::Out::default();
        // SAFETY: `sim` is live; `input` and `out` are valid for the call.
        unsafe { ffi::sc_fabric_sim_clock(self.sim.as_ptr(), input, &mut out) };
        out
    }

    /// One clock with `pixel` on PIXEL_IN and `access` on the bus, every clock a pixel clock;
    /// what it shows, as [`FabricDevice::clock`] returns it.
    pub fn clock(&mut self, pixel: Option<Beat>, access: Option<Access>) -> Clocked {
        self.clock_linked(pixel, access, true, true).0
    }

    /// One clock with `pixel` on PIXEL_IN, `access` on the bus, `pix_ce` (whether this clock
    /// is a pixel clock) and LINK_OUT's ready; what it shows, and the byte LINK_OUT sent on
    /// it.
    pub fn clock_linked(
        &mut self,
        pixel: Option<Beat>,
        access: Option<Access>,
        pix_ce: bool,
        link_ready: bool,
    ) -> (Clocked, Option<u8>) {
        let beat = pixel.unwrap_or_default();
        let (bus_addr, bus_wdata, bus_we, bus_re) = match access {
            // The bus carries 8 address bits: offsets beyond the window alias into it, so
            // the schedule keeps its offsets inside.
            Some(Access::Read(offset)) => (offset as u8, 0, 0, 1),
            Some(Access::Write(offset, value)) => (offset as u8, value, 1, 0),
            None => (0, 0, 0, 0),
        };
        let out = self.step(&ffi::In {
            bus_wdata,
            bus_addr,
            bus_we,
            bus_re,
            pixel_valid: pixel.is_some() as u8,
            pixel_data: beat.data,
            pixel_sof: beat.sof as u8,
            pixel_eol: beat.eol as u8,
            rst: 0,
            pix_ce: pix_ce as u8,
            link_ready: link_ready as u8,
        });
        let sent = (out.link_valid != 0 && link_ready).then_some(out.link_data);
        (
            Clocked {
                ready: out.pixel_ready != 0,
                read: (bus_re != 0).then_some(out.bus_rdata),
            },
            sent,
        )
    }
}
