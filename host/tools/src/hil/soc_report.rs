//! What the SoC in the loop's board measured, read back from its stderr
//! (`hdl-interface/soc/sim/sc_soc_sim.cpp`): the soft-core's own cycles and the FIFOs' drops
//! per image (the firmware's report port), when each image went in and its packets came out,
//! and the run's clocks and wall time.

use std::collections::BTreeMap;

use stereocal_firmware::softcore::instructions::fields;
use stereocal_firmware::softcore::soc::ImageReport;

/// When one camera image went in and its packets came out, in clocks of the SoC.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ImageTiming {
    /// 0 = left, 1 = right.
    pub camera: u8,
    /// The camera's image index, from 0.
    pub image: u32,
    /// The clock its first pixel went into the fabric.
    pub first_pixel: u64,
    /// The clock its last pixel went in.
    pub last_pixel: u64,
    /// The clock its fabric's LINK_OUT sent its first byte.
    pub first_byte: u64,
    /// The clock LINK_OUT sent its last byte (before the camera's next image).
    pub last_byte: u64,
}

/// How the simulation ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SimEnd {
    /// Clocks simulated.
    pub cycles: u64,
    /// Wall time of the simulation, milliseconds.
    pub millis: u64,
    /// Fabric register reads (each one bus strobe).
    pub fabric_reads: u64,
    /// Fabric register writes.
    pub fabric_writes: u64,
    /// The longest stretch of clocks in which no pixel went in and no byte moved on the link
    /// (what the board's watchdog would have fired on).
    pub longest_still: u64,
    /// The cameras' pixel clock: one clock in this many.
    pub pixel_clock_divider: u64,
}

/// First pixel in to last byte out, the worst image of a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Latency {
    /// Clocks from an image's first pixel into the fabric to the last byte its fabric sent.
    pub first_pixel_to_last_byte: u64,
    /// Clocks from the image's last pixel in to its last byte out: what the packets lag
    /// behind the camera.
    pub last_pixel_to_last_byte: u64,
}

/// Everything the board reported.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SocReport {
    /// The firmware's per-image reports, in the order written.
    pub images: Vec<ImageReport>,
    /// Per camera image, when it went in and came out.
    pub timings: Vec<ImageTiming>,
    /// The final line, when the board got that far.
    pub end: Option<SimEnd>,
}

impl SocReport {
    /// Reads the board's report lines out of its stderr; other lines are ignored.
    pub fn parse(stderr: &str) -> Self {
        let mut report = Self::default();
        for line in stderr.lines() {
            if let Some(image) = ImageReport::parse(line) {
                report.images.push(image);
            } else if let Some(timing) = parse_timing(line) {
                report.timings.push(timing);
            } else if let Some(end) = parse_end(line) {
                report.end = Some(end);
            }
        }
        report
    }

    /// The soft-core's own cycles for the costliest frame pair: both cameras' reports of a
    /// frame added (the budget is per pair, so the worst pair is the figure).
    pub fn softcore_cycles_per_pair(&self) -> Option<u64> {
        self.costliest_pair().map(|(own, _)| own)
    }

    /// The cycles the soft-core polled STATUS.BUSY in the pair of
    /// [`Self::softcore_cycles_per_pair`], its own work plus these being its whole `mcycle`
    /// across the pair's driver calls.
    pub fn busy_wait_cycles_per_pair(&self) -> Option<u64> {
        self.costliest_pair().map(|(_, waited)| waited)
    }

    /// The own and busy-wait cycles of the frame pair with the most own cycles, both
    /// cameras' reports of a frame added.
    fn costliest_pair(&self) -> Option<(u64, u64)> {
        let mut per_frame = BTreeMap::<u32, (u64, u64)>::new();
        for r in &self.images {
            let entry = per_frame.entry(r.frame).or_default();
            entry.0 += u64::from(r.softcore_cycles);
            entry.1 += u64::from(r.busy_wait_cycles);
        }
        per_frame.into_values().max()
    }

    /// Points and Sobel entries the fabrics' FIFOs dropped over the run.
    pub fn fifo_overflows(&self) -> u64 {
        self.images
            .iter()
            .map(|r| u64::from(r.point_overflows) + u64::from(r.sobel_overflows))
            .sum()
    }

    /// Clocks of the longest frame pair: from the left camera's first pixel of a pair to that
    /// of the next pair, the last pair to the end of the run (so every clock the pair costs
    /// the SoC, the firmware's own between frames included).
    pub fn sim_clocks_per_pair(&self) -> Option<u64> {
        let end = self.end?.cycles;
        let mut starts: Vec<u64> = self
            .timings
            .iter()
            .filter(|t| t.camera == 0)
            .map(|t| t.first_pixel)
            .collect();
        starts.sort_unstable();
        starts.push(end);
        // The board's numbers are data: a malformed line may put the end before a start.
        starts.windows(2).map(|w| w[1].saturating_sub(w[0])).max()
    }

    /// The worst image's latency; `None` when no image sent a byte.
    pub fn latency(&self) -> Option<Latency> {
        let sent = self.timings.iter().filter(|t| t.last_byte >= t.first_pixel);
        let first = sent
            .clone()
            .map(|t| t.last_byte.saturating_sub(t.first_pixel))
            .max()?;
        let last = sent
            .map(|t| t.last_byte.saturating_sub(t.last_pixel))
            .max()?;
        Some(Latency {
            first_pixel_to_last_byte: first,
            last_pixel_to_last_byte: last,
        })
    }

    /// Simulated clocks per second of wall time.
    pub fn clocks_per_second(&self) -> Option<f64> {
        let end = self.end?;
        (end.millis > 0).then(|| end.cycles as f64 * 1000.0 / end.millis as f64)
    }
}

fn parse_timing(line: &str) -> Option<ImageTiming> {
    let names = [
        "camera",
        "image",
        "first_pixel",
        "last_pixel",
        "first_byte",
        "last_byte",
    ];
    let rest = line.strip_prefix("sc_soc_sim: ")?;
    let [camera, image, first_pixel, last_pixel, first_byte, last_byte] =
        fields(rest, "timing", names)?;
    Some(ImageTiming {
        camera: u8::try_from(camera).ok()?,
        image: u32::try_from(image).ok()?,
        first_pixel,
        last_pixel,
        first_byte,
        last_byte,
    })
}

fn parse_end(line: &str) -> Option<SimEnd> {
    let names = [
        "cycles",
        "millis",
        "fabric_reads",
        "fabric_writes",
        "longest_still",
        "pixel_clock_divider",
    ];
    let [cycles, millis, fabric_reads, fabric_writes, longest_still, pixel_clock_divider] =
        fields(line, "sc_soc_sim:", names)?;
    Some(SimEnd {
        cycles,
        millis,
        fabric_reads,
        fabric_writes,
        longest_still,
        pixel_clock_divider,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const STDERR: &str = "\
sc_soc_sim: image frame 0 camera 0 softcore_cycles 900 busy_wait_cycles 10 point_overflows 1 sobel_overflows 0
sc_soc_sim: image frame 0 camera 1 softcore_cycles 800 busy_wait_cycles 20 point_overflows 0 sobel_overflows 2
sc_soc_sim: image frame 1 camera 0 softcore_cycles 1000 busy_wait_cycles 40 point_overflows 0 sobel_overflows 0
sc_soc_sim: image frame 1 camera 1 softcore_cycles 1000 busy_wait_cycles 50 point_overflows 0 sobel_overflows 0
some other line
sc_soc_sim: timing camera 0 image 0 first_pixel 100 last_pixel 1100 first_byte 300 last_byte 1500
sc_soc_sim: timing camera 0 image 1 first_pixel 5000 last_pixel 6000 first_byte 5200 last_byte 6100
sc_soc_sim: timing camera 1 image 0 first_pixel 2000 last_pixel 3000 first_byte 2100 last_byte 3900
sc_soc_sim: cycles 9000 millis 3 fabric_reads 10 fabric_writes 4 longest_still 77 pixel_clock_divider 64
";

    #[test]
    fn the_board_lines_give_the_run_figures() {
        let r = SocReport::parse(STDERR);
        assert_eq!(r.images.len(), 4);
        assert_eq!(r.timings.len(), 3);
        assert_eq!(r.softcore_cycles_per_pair(), Some(2000));
        assert_eq!(r.busy_wait_cycles_per_pair(), Some(90));
        assert_eq!(r.fifo_overflows(), 3);
        // Pairs start at 100 and 5000; the run ends at 9000.
        assert_eq!(r.sim_clocks_per_pair(), Some(4900));
        assert_eq!(
            r.latency(),
            Some(Latency {
                first_pixel_to_last_byte: 1900,
                last_pixel_to_last_byte: 900,
            })
        );
        assert_eq!(r.clocks_per_second(), Some(3_000_000.0));
        assert_eq!(r.end.map(|e| e.longest_still), Some(77));
    }

    #[test]
    fn a_board_that_died_early_has_no_end() {
        let r = SocReport::parse("sc_soc_sim: watchdog: nothing moved\n");
        assert_eq!(r, SocReport::default());
        assert_eq!(r.sim_clocks_per_pair(), None);
        assert_eq!(r.softcore_cycles_per_pair(), None);
    }
}
