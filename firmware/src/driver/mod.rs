//! The soft-core driver: configures the fabric through its registers, offers it frames on
//! PIXEL_IN, and turns its point and Sobel FIFOs into wire packets.
//!
//! One [`Driver`] per camera channel. It speaks to the fabric only through the register map
//! (the generated [`stereocal_hdl::Registers`] API and FIFO bursts of
//! [`stereocal_hdl::RegisterBus::read_burst`]) and its PIXEL_IN port
//! ([`stereocal_hdl::PixelIn`]), so it is generic over what implements those:
//! [`stereocal_hdl::Mmio`] on an FPGA, the device model [`crate::fabric::FabricDevice`] in
//! software (in the soft-core ELF under QEMU and in the host's in-process link). It writes
//! into any [`ByteSink`] through a [`PacketWriter`]; the channel numbers its packets as its
//! camera's source ([`Numbering`]), the writer the device's control packets:
//!
//! ```
//! use stereocal_firmware::driver::{ByteSink, Driver, PacketWriter};
//! use stereocal_firmware::fabric::{FabricDevice, FabricModel};
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
//! type Fabric = FabricDevice<FabricModel<64, 32, 16, 12>, 64>;
//! let mut driver: Box<Driver<Fabric, 64>> =
//!     Box::new(Driver::new(FabricDevice::new(FabricModel::fast()), Camera::Left));
//! let config = FabricConfig { width: 64, height: 32, octaves: 2, ..FabricConfig::default() };
//! driver.configure(&config)?;
//! let mut link = PacketWriter::new(Collect(Vec::new()));
//! let image = vec![128u8; 64 * 32];
//! let summary = driver.process_frame(&image, 0, &mut link)?;
//! assert_eq!(summary.frame_id, 0);
//! // link.sink().0 now holds FrameStart, the frame's packets and FrameEnd, COBS-framed.
//! # Ok::<(), stereocal_firmware::driver::DriverError>(())
//! ```
//!
//! # A frame on the registers
//! The configuration registers are read back and validated; a frame an earlier error left
//! running (or entries it left in the FIFOs) is cleared with CONTROL.SOFT_RESET; the drop
//! counters are read; CONTROL.ENABLE and FRAME_ARM start the frame (STATUS.BUSY must rise).
//! Each image row is offered on PIXEL_IN (SOF on the first) and both FIFOs drained; then
//! blanking line times, each followed by a drain, until STATUS.BUSY falls. The frame's drops
//! are the counters' growth since arming.
//!
//! # Packets of a frame
//! `FrameStart`; then, as the FIFOs are drained after every input row and blanking row,
//! `PointBatch` packets (up to 128 points, in FIFO order; the position in that order is the
//! point's `point_index`) and either `SobelRows` (OUTPUT_MODE.SOBEL_OUTPUT = ROWS: every row of
//! every octave's Sobel image, when it is complete) or `SobelPatch` (PATCHES, the reset value:
//! the 16x16 window around each point, cut from a ring of the last 32 Sobel rows per octave
//! once the rows below the point have arrived; outside the image the pixels are zero); finally
//! `FrameEnd` with the point and Sobel packet counts and the drops. Nothing is lost silently:
//! the fabric's FIFO overflows are `dropped_points` / `dropped_sobel`, and a point that gets no
//! patch (its rows left the ring, or the patch queue was full) also counts in `dropped_sobel`;
//! each sets its `FrameEnd` flag.

mod channel;
mod error;
mod fifo_reader;
mod numbering;
mod patch;
mod point_batch;
mod sink;
mod sobel_ring;

pub use channel::{Driver, FrameSummary, CHANNEL_CAPABILITIES};
pub use error::DriverError;
pub use numbering::Numbering;
pub use patch::MAX_PENDING;
pub use sink::{ByteSink, PacketWriter};
pub use sobel_ring::{OutOfOrder, RING_ROWS};

#[cfg(test)]
mod tests;
