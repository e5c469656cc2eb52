//! The stream engine: the fabric block that turns the datapath's two FIFOs into the camera
//! channel's packets on the link, so that no Sobel pixel and no point passes through the
//! soft-core.
//!
//! At a camera's pixel rate a soft-core has a few instructions per pixel; reading the Sobel
//! FIFO through registers alone costs more. The engine sits between the FIFOs and the link's
//! transmitter (the LINK_OUT port) and does per record what a driver would: it batches points
//! into `PointBatch` packets, assembles every octave's Sobel rows in a ring of
//! [`RING_ROWS`] rows, and sends them whole or in segments (`SobelRows`) or cuts the 16x16
//! window around each point (`SobelPatch`); its framer adds the header, CRC-32C, COBS and,
//! when STREAM_CONTROL.FEC is set, the RS(255,239) parity. It also sends the frame's
//! `FrameStart` (from FRAME_ID, TIMESTAMP_* and the geometry latched at FRAME_ARM) and
//! `FrameEnd` (its own counters and the FIFOs' drops), numbering every packet as the camera's
//! wire source. The soft-core's share of a frame is writing those registers, FRAME_ARM, and
//! polling STATUS.BUSY, which stays high until `FrameEnd` is out. `docs/STREAM_ENGINE.md`
//! has the block diagram.
//!
//! # Order of the packets
//! The engine's output is a function of the datapath's output sequence alone, so that every
//! implementation (the model here over either datapath, the RTL, a soft-core of any speed)
//! sends the same bytes: at the end of each line time (the clock after a frame's line of
//! WIDTH pixels has entered, and every WIDTH blanking clocks after the last line) the engine
//! takes what the FIFOs hold at that moment, every point first (in FIFO order), then the Sobel
//! pixels octave by octave, octave 0 first, each octave's in FIFO order (the engine keeps a
//! row ring per octave, so storing them octave by octave changes no pixel; it fixes the
//! order in which rows that complete in the same line time leave); entries that arrive while it works wait for the next line time. Points are
//! batched in arrival order and a batch leaves when it is full; a Sobel row leaves when its
//! last pixel has been taken (segments in column order); a patch leaves when its point has
//! arrived and the rows down to `y + 7` are complete, in point order among the patches a row
//! completes. When the datapath is done the open rows, waiting patches and the last batch
//! leave, then `FrameEnd`.
//!
//! # Faults
//! A record the ring cannot place (a Sobel pixel out of raster order or outside its octave,
//! a point outside its octave: a datapath defect) stops the frame: the engine discards the
//! rest of its records, sends no `FrameEnd`, and STREAM_FAULT says what and where. The
//! driver reports it to the host.

mod engine;
mod patch;
mod point_batch;
mod sobel_ring;

pub use engine::{StreamCounts, StreamEngine, StreamFault, StreamFrame};
pub use patch::MAX_PENDING;
pub use point_batch::wire_point;
pub use sobel_ring::{OutOfOrder, RING_ROWS};

use crate::framing::ByteSink;

/// A LINK_OUT port with nothing attached: what the engine sends is dropped, as bytes driven
/// onto an unconnected port are. A device built for its registers alone (the FIFO tests,
/// the register contract) has this link.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Unwired;

impl ByteSink for Unwired {
    fn write(&mut self, _bytes: &[u8]) {}
}
