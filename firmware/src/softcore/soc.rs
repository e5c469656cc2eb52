//! What the SoC in the loop has beyond QEMU's `virt` machine: both channels' fabrics on the
//! bus, and a report port for what the soft-core measured of each image, handed to the board
//! rather than the link, so that the link's bytes stay those of every other device.
//!
//! The board (`hdl-interface/soc/sim/sc_soc_sim.cpp`) has six write-only word registers at
//! [`REPORT_PORT`], the fabric's base address plus two channel strides: FRAME, CAMERA,
//! POINT_OVERFLOWS, SOBEL_OVERFLOWS, BUSY_WAIT_CYCLES and CYCLES. A write of CYCLES completes
//! a record, and the board prints it on its stderr as
//!
//! ```text
//! sc_soc_sim: image frame 3 camera 1 softcore_cycles 4123 busy_wait_cycles 20634573 point_overflows 0 sobel_overflows 0
//! ```
//!
//! which the host reads back ([`ImageReport::parse`]). QEMU's `virt` has nothing there; the
//! firmware writes the port only on the SoC (`FLAG_WIRED_CAMERAS`).

use crate::softcore::instructions::fields;

/// Where camera `c`'s `sc_fabric` sits on the SoC's bus (`hdl-interface/soc/sc_soc.v`):
/// the register map's base address plus `c` times this.
pub const CHANNEL_STRIDE: usize = 0x1_0000;

/// Where the port sits: after both channels' fabrics.
pub const REPORT_PORT: usize = stereocal_hdl::regs::BASE_ADDRESS + 2 * CHANNEL_STRIDE;

/// What the soft-core measured of one image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ImageReport {
    /// Frame id.
    pub frame: u32,
    /// 0 = left, 1 = right.
    pub camera: u8,
    /// The soft-core's clock cycles (`mcycle`) in the frame's driver call, less the cycles it
    /// spent polling STATUS.BUSY while the camera and the fabric did the frame: the program's
    /// own work, which the budget of a real head's soft-core is about.
    pub softcore_cycles: u32,
    /// The cycles the driver spent polling STATUS.BUSY while the camera sent the image and
    /// the fabric finished it: time a real head's core has for other work.
    pub busy_wait_cycles: u32,
    /// Points the fabric's point FIFO dropped in the frame (POINT_OVERFLOW_COUNT's growth).
    pub point_overflows: u32,
    /// Sobel entries the fabric's Sobel FIFO dropped (SOBEL_OVERFLOW_COUNT's growth).
    pub sobel_overflows: u32,
}

impl ImageReport {
    /// Reads a record from a line of the board's stderr; `None` when the line is not one.
    pub fn parse(line: &str) -> Option<Self> {
        let names = [
            "frame",
            "camera",
            "softcore_cycles",
            "busy_wait_cycles",
            "point_overflows",
            "sobel_overflows",
        ];
        let rest = line.strip_prefix("sc_soc_sim: ")?;
        let [frame, camera, cycles, waited, points, sobel] = fields(rest, "image", names)?;
        Some(Self {
            frame: u32::try_from(frame).ok()?,
            camera: u8::try_from(camera).ok()?,
            softcore_cycles: u32::try_from(cycles).ok()?,
            busy_wait_cycles: u32::try_from(waited).ok()?,
            point_overflows: u32::try_from(points).ok()?,
            sobel_overflows: u32::try_from(sobel).ok()?,
        })
    }

    /// Writes the record to the board's port.
    ///
    /// # Safety
    /// Only on the SoC in the loop, whose board has the port at [`REPORT_PORT`].
    #[cfg(target_os = "none")]
    pub unsafe fn write(&self) {
        let words = [
            self.frame,
            self.camera.into(),
            self.point_overflows,
            self.sobel_overflows,
            self.busy_wait_cycles,
            self.softcore_cycles,
        ];
        for (i, word) in words.into_iter().enumerate() {
            // SAFETY: the caller's contract; the registers are word-wide and write-only.
            unsafe { core::ptr::write_volatile((REPORT_PORT + 4 * i) as *mut u32, word) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_board_line_reads_back() {
        let line = "sc_soc_sim: image frame 3 camera 1 softcore_cycles 41234 busy_wait_cycles 7 \
                    point_overflows 2 sobel_overflows 0";
        assert_eq!(
            ImageReport::parse(line),
            Some(ImageReport {
                frame: 3,
                camera: 1,
                softcore_cycles: 41234,
                busy_wait_cycles: 7,
                point_overflows: 2,
                sobel_overflows: 0,
            })
        );
        assert_eq!(ImageReport::parse("sc_soc_sim: cycles 5 seconds 1"), None);
        assert_eq!(ImageReport::parse("image frame 3 camera 1"), None);
    }
}
