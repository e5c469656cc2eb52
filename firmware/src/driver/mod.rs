//! The soft-core driver: configures the fabric through its registers, feeds it frames, and
//! turns its point and Sobel FIFOs into wire packets.
//!
//! One [`Driver`] per camera channel. It is generic over the register bus
//! ([`stereocal_hdl::RegisterBus`]: the in-memory [`stereocal_hdl::RegisterBank`] next to the
//! model, [`stereocal_hdl::Mmio`] on an FPGA) and the front end ([`crate::fabric::FrontEnd`]:
//! [`FabricModel`] picks the fast path or the register-level model at run time), and writes
//! into any [`ByteSink`] through a [`PacketWriter`] that numbers the packets. The same code
//! runs in the soft-core ELF and in the host's in-process link:
//!
//! ```
//! use stereocal_firmware::driver::{ByteSink, Driver, FabricModel, PacketWriter};
//! use stereocal_hdl::{FabricConfig, RegisterBank};
//! use stereocal_wire::Camera;
//!
//! struct Collect(Vec<u8>);
//! impl ByteSink for Collect {
//!     fn write(&mut self, bytes: &[u8]) {
//!         self.0.extend_from_slice(bytes);
//!     }
//! }
//!
//! let mut driver: Box<Driver<RegisterBank, FabricModel<64, 32, 16, 12>, 64>> =
//!     Box::new(Driver::new(RegisterBank::new(), FabricModel::fast(), Camera::Left));
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
mod front_end;
mod patch;
mod point_batch;
mod sink;
mod sobel_ring;

pub use channel::{fabric_config, Driver, FrameSummary, CHANNEL_CAPABILITIES};
pub use error::{DriverError, ERROR_FRAME_FAILED, ERROR_INVALID_CONFIG, ERROR_UNEXPECTED_KIND};
pub use front_end::FabricModel;
pub use patch::MAX_PENDING;
pub use sink::{ByteSink, PacketWriter};
pub use sobel_ring::{OutOfOrder, RING_ROWS};

#[cfg(test)]
mod tests;
