//! How a session guards its frames against a damaging link: the packing the device uses,
//! forward error correction, and how much loss a frame may have and still be estimated.
//!
//! A clean link (a short cable, a socket on one machine) wants the fewest bytes: whole Sobel
//! rows, the register defaults, no parity. A noisy one (a long cable, a radio) wants each
//! damaged packet to cost little and most damage repaired: `docs/RELIABILITY.md` measures both
//! over the same faults.

use stereocal_hdl::FabricConfig;

use crate::driver::MAX_LOST_FRACTION;

/// The link's protection, applied when a session opens its device.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkProtection {
    /// Ask the device for forward error correction of its link frames
    /// ([`stereocal_wire::fec`]): 7.7 % more bytes, up to 8 damaged bytes per 255 repaired.
    pub fec: bool,
    /// Most points per `PointBatch` packet (OUTPUT_MODE.POINTS_PER_BATCH).
    pub points_per_batch: u8,
    /// Most pixels per `SobelRows` packet (OUTPUT_MODE.ROW_SEGMENT).
    pub row_segment: u16,
    /// The largest fraction of a camera frame's keypoints the link may cost it and the frame
    /// still be estimated ([`crate::driver::Driver::set_loss_limit`]).
    pub loss_limit: f64,
}

impl LinkProtection {
    /// For a clean link: the register defaults (whole rows), no parity, and a frame that
    /// lost any keypoint or Sobel pixel dropped (one that lost only its `FrameEnd` is still
    /// delivered). A whole lost row costs 1 to 8 % of a frame's keypoints at once, too many
    /// for a salvaged estimate to stay within its own sigma of the intact pair's: salvage is
    /// the noisy guard's, whose packets cost a fraction of that.
    pub fn clean() -> Self {
        let defaults = FabricConfig::default();
        Self {
            fec: false,
            points_per_batch: defaults.points_per_batch,
            row_segment: defaults.row_segment,
            loss_limit: 0.0,
        }
    }

    /// For a noisy link: parity on every link frame, packets small enough that one lost
    /// costs under the loss limit, and frames salvaged up to [`MAX_LOST_FRACTION`]. A
    /// 64-pixel row segment costs the keypoints within 80 of a
    /// 320- to 1280-pixel row's columns (a quarter to a sixteenth of a whole row's cost) for
    /// 26 bytes of overhead per 128 of pixels; an 8-point batch costs 8 of the 200 to 500
    /// points a frame carries, under half the limit, for 20 bytes per 112.
    pub fn noisy() -> Self {
        Self {
            fec: true,
            points_per_batch: 8,
            row_segment: 64,
            loss_limit: MAX_LOST_FRACTION,
        }
    }

    /// `config` with this protection's packing.
    pub fn pack(&self, config: FabricConfig) -> FabricConfig {
        FabricConfig {
            points_per_batch: self.points_per_batch,
            row_segment: self.row_segment,
            ..config
        }
    }
}

impl Default for LinkProtection {
    fn default() -> Self {
        Self::clean()
    }
}
