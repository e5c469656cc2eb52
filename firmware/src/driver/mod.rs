//! The soft-core driver: configures the fabric through its registers, offers it frames on
//! PIXEL_IN, and runs its frames; the fabric's stream engine turns them into wire packets.
//!
//! One [`Driver`] per camera channel. It speaks to the fabric only through the register map
//! (the generated [`stereocal_hdl::Registers`] API) and its PIXEL_IN port
//! ([`stereocal_hdl::PixelIn`]), so it is generic over what implements those:
//! [`stereocal_hdl::Mmio`] on an FPGA, the device model [`crate::fabric::FabricDevice`] in
//! software (in the soft-core ELF under QEMU and in the host's in-process link). The frame's
//! packets leave on the fabric's own link port, framed and numbered by its stream engine as
//! the camera's source; the driver answers the host's packets through a
//! [`PacketWriter`](crate::framing::PacketWriter) of
//! the device's control source:
//!
//! ```
//! use stereocal_firmware::driver::Driver;
//! use stereocal_firmware::fabric::{FabricDevice, FabricModel};
//! use stereocal_firmware::framing::ByteSink;
//! use stereocal_hdl::FabricConfig;
//! use stereocal_wire::Camera;
//!
//! struct Collect(Vec<u8>);
//! impl ByteSink for Collect {
//!     fn write(&mut self, bytes: &[u8]) {
//!         self.0.extend_from_slice(bytes);
//!     }
//! }
//!
//! type Fabric = FabricDevice<FabricModel<64, 32, 16, 12>, 64, Collect>;
//! let fabric = FabricDevice::with_link(FabricModel::fast(), Collect(Vec::new()));
//! let mut driver: Box<Driver<Fabric, 64>> = Box::new(Driver::new(fabric, Camera::Left));
//! let config = FabricConfig { width: 64, height: 32, octaves: 2, ..FabricConfig::default() };
//! driver.configure(&config)?;
//! let image = vec![128u8; 64 * 32];
//! let summary = driver.process_frame(&image, 0)?;
//! assert_eq!(summary.frame_id, 0);
//! // The fabric's link holds the frame's link frames: FrameStart, its Sobel packets (a flat
//! // image has no points) and FrameEnd.
//! let frames = driver.bus().link().0.iter().filter(|&&b| b == 0).count();
//! assert_eq!((summary.points, frames as u32), (0, 2 + summary.sobel_packets));
//! # Ok::<(), stereocal_firmware::driver::DriverError>(())
//! ```
//!
//! # A frame on the registers
//! The configuration registers are read back and validated; a frame an earlier error left
//! running (or entries it left in the FIFOs) is cleared with CONTROL.SOFT_RESET; the drop
//! counters are read; FRAME_ID and TIMESTAMP_* are written; CONTROL.ENABLE and FRAME_ARM start
//! the frame (STATUS.BUSY must rise). The image is offered on PIXEL_IN row by row (SOF on the
//! first), then blanking line times until STATUS.BUSY falls, which it does once the stream
//! engine has sent `FrameEnd`. The frame's summary comes from the engine's counters
//! (STREAM_POINTS, STREAM_SOBEL_PACKETS, STREAM_PATCHES_DROPPED) and the drop counters'
//! growth since arming; STREAM_FAULT, if set, is the frame's error. The soft-core's work is
//! a few dozen register accesses per frame and the loop that stands in for the camera.
//!
//! # Packets of a frame
//! [`crate::fabric::stream`] says what the engine sends and in which order: `FrameStart`,
//! `PointBatch` packets (up to OUTPUT_MODE.POINTS_PER_BATCH points, in FIFO order; the position
//! in that order is the point's `point_index`), `SobelRows` (rows mode) or `SobelPatch`
//! (patches mode, the reset value), `FrameEnd` with the counts and the drops. Nothing is lost
//! silently: the fabric's FIFO overflows are `dropped_points` / `dropped_sobel`, and a point
//! that gets no patch also counts in `dropped_sobel`; each sets its `FrameEnd` flag.

mod channel;
mod error;

pub use channel::{Driver, FrameSummary, CHANNEL_CAPABILITIES};
pub use error::DriverError;

#[cfg(test)]
mod tests;
