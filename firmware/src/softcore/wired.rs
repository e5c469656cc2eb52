//! The fabric a channel drives: the device model in software (QEMU), or the real fabric on
//! the soft-core's bus with the camera wired to it (the SoC in the loop, whose frame-grabber
//! input sets [`FLAG_WIRED_CAMERAS`](crate::softcore::frame_input::FLAG_WIRED_CAMERAS)).
//! The same ELF carries both; the main loop is generic over [`ChannelFabric`], so a board
//! with the real fabric never builds the model's megabyte of state.

use stereocal_hdl::regs::status;
use stereocal_hdl::{Mmio, PixelIn, RegisterBus};

use crate::fabric::{FabricDevice, FabricModel};
use crate::softcore::instructions::CountedFabric;
use crate::softcore::link::Uart0;
use crate::softcore::soc::CHANNEL_STRIDE;

/// Core clocks a camera's pixel clock may last on the SoC: what the driver's waits for the
/// camera allow per pixel clock. The SoC harness runs the cameras at one pixel clock in 64
/// core clocks (the stream engine's pace) and refuses dividers above this.
pub const MAX_CORE_CLOCKS_PER_PIXEL: u64 = 4096;

/// The real fabric of one channel, at MMIO, its PIXEL_IN wired to a camera.
///
/// The driver's camera stand-in ([`PixelIn`]) does nothing here but wait: the camera sends
/// the frame itself once the fabric is armed. `push` returns at once; `idle(clocks)` waits
/// until the fabric is no longer busy, for at most `clocks` pixel clocks of the slowest
/// camera the board may have, so the driver's bound on a frame's flush still ends a frame
/// that never ends. The clock cycles those waits take are counted apart
/// ([`ChannelFabric::take_wait_cycles`]): they are the camera's and the fabric's time, not
/// the program's work.
pub struct WiredFabric {
    mmio: Mmio,
    waited: u64,
}

impl WiredFabric {
    /// The fabric of camera `camera` (0 left, 1 right).
    ///
    /// # Safety
    /// Only on the SoC in the loop, whose bus has `sc_fabric` of that camera at
    /// [`stereocal_hdl::regs::BASE_ADDRESS`] + `camera` x [`CHANNEL_STRIDE`].
    pub unsafe fn new(camera: usize) -> Self {
        let base = stereocal_hdl::regs::BASE_ADDRESS + camera * CHANNEL_STRIDE;
        // SAFETY: the caller's contract.
        Self {
            mmio: unsafe { Mmio::new(base) },
            waited: 0,
        }
    }
}

impl RegisterBus for WiredFabric {
    fn read(&mut self, offset: u16) -> u32 {
        self.mmio.read(offset)
    }

    fn write(&mut self, offset: u16, value: u32) {
        self.mmio.write(offset, value)
    }
}

impl PixelIn for WiredFabric {
    fn push(&mut self, _pixels: &[u8], _start_of_frame: bool) {}

    fn idle(&mut self, clocks: u32) {
        let budget = u64::from(clocks) * MAX_CORE_CLOCKS_PER_PIXEL;
        let start = riscv::register::mcycle::read64();
        let mut now = start;
        while self.mmio.read_field(&status::BUSY) != 0 && now.wrapping_sub(start) < budget {
            now = riscv::register::mcycle::read64();
        }
        self.waited = self.waited.wrapping_add(now.wrapping_sub(start));
    }
}

/// The device model in software behind a channel on QEMU: its stream engine on the UART,
/// everything it does counted in instructions.
pub type ModelFabric = CountedFabric<FabricDevice<FabricModel, 1280, Uart0>>;

/// The fabric behind a channel's driver, model or real: what the main loop needs of it
/// beyond its registers and PIXEL_IN.
pub trait ChannelFabric: RegisterBus + PixelIn {
    /// Instructions the device model spent since the last call (0 for the real fabric).
    fn take_counted(&self) -> u64;

    /// Instructions the model's stream engine waited for the UART since the last call (0
    /// for the real fabric, whose engine has its own link).
    fn take_link_waited(&mut self) -> u64;

    /// Clock cycles spent waiting for the fabric to finish a frame since the last call (0 for
    /// the model, which does the frame inside the driver's calls).
    fn take_wait_cycles(&mut self) -> u64;
}

impl ChannelFabric for ModelFabric {
    fn take_counted(&self) -> u64 {
        self.take()
    }

    fn take_link_waited(&mut self) -> u64 {
        self.inner_mut().link_mut().take_waited()
    }

    fn take_wait_cycles(&mut self) -> u64 {
        0
    }
}

impl ChannelFabric for WiredFabric {
    fn take_counted(&self) -> u64 {
        0
    }

    fn take_link_waited(&mut self) -> u64 {
        0
    }

    fn take_wait_cycles(&mut self) -> u64 {
        core::mem::take(&mut self.waited)
    }
}
