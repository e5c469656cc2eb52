//! What the front end costs on the soft-core, in instructions.
//!
//! The fabric does the front end in hardware; this module measures what the same work would
//! cost as software on the soft-core, the thesis' table 4.4 question asked of our code. On the
//! bare-metal target `CountedFabric` wraps the fabric's device model and adds up the
//! `minstret` deltas of every register access and every call of its PIXEL_IN port: the
//! datapath's computation and the model's side of the bus, which is hardware on the real head.
//! What stays with the driver is its own work around each access (on a board, the load or
//! store itself). The UART sink counts its waits for the transmitter apart (`link::Uart0`). Under
//! QEMU `-icount shift=0`, `minstret` counts retired instructions exactly, so the front-end
//! count is the same on every run. The UART wait depends on how fast the host reads, and the
//! driver's count carries the few instructions around each wait, so it varies by a few
//! hundred in tens of millions.
//!
//! With [`FLAG_COUNT_INSTRUCTIONS`](super::frame_input::FLAG_COUNT_INSTRUCTIONS) the firmware
//! logs one [`InstructionReport`] per image as a defmt `println` (a `Log` packet); the host
//! decodes it with the ELF's defmt table and reads it back with [`InstructionReport::parse`].
//! The text format lives here, next to both its writer and its reader:
//!
//! ```text
//! instructions: frame 3 camera 1 pixels 19200 front_end 1234567 driver 765432 uart_wait 0
//! kernels: pixels 19200 gaussian 456789 dog 12345 sobel_cordic 67890
//! ```
//! The second line ([`KernelReport`], once per run, on the first left image) splits the
//! front end the way the thesis' table 4.4 profile does: the fast path's own row kernels,
//! each run over every row of the image as octave 0 runs them (the four 5-tap Gaussians as a
//! row and a column pass each, the three DoG rows, Sobel and CORDIC on one scale).

/// The instruction counts of one image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InstructionReport {
    /// Frame id.
    pub frame: u32,
    /// 0 = left, 1 = right.
    pub camera: u8,
    /// Pixels of the image.
    pub pixels: u32,
    /// Instructions inside the fabric model (the work the fabric does in hardware: the
    /// datapath, and the stream engine building, framing and writing the frame's packets),
    /// its waits for the UART transmitter excluded.
    pub front_end: u64,
    /// The rest of `process_frame`: the driver's register accesses around the frame and the
    /// loop that offers the image's rows (the soft-core's own work).
    pub driver: u64,
    /// Instructions spent waiting for the UART transmitter, by the soft-core and by the
    /// stream engine's stand-in.
    pub uart_wait: u64,
}

/// The numbers of a report line `PREFIX name value name value ...`, in `names` order;
/// `None` unless the line is exactly that. Every report of the soft-core and of the SoC
/// board (`softcore::soc`) has this form, so one reader serves them all.
pub fn fields<const N: usize>(text: &str, prefix: &str, names: [&str; N]) -> Option<[u64; N]> {
    let mut words = text.split_whitespace();
    if words.next()? != prefix {
        return None;
    }
    let mut values = [0; N];
    for (value, name) in values.iter_mut().zip(names) {
        if words.next()? != name {
            return None;
        }
        *value = words.next()?.parse().ok()?;
    }
    words.next().is_none().then_some(values)
}

impl InstructionReport {
    /// Reads a report from a decoded log message; `None` when `text` is not one.
    pub fn parse(text: &str) -> Option<Self> {
        let names = [
            "frame",
            "camera",
            "pixels",
            "front_end",
            "driver",
            "uart_wait",
        ];
        let [frame, camera, pixels, front_end, driver, uart_wait] =
            fields(text, "instructions:", names)?;
        Some(Self {
            frame: u32::try_from(frame).ok()?,
            camera: u8::try_from(camera).ok()?,
            pixels: u32::try_from(pixels).ok()?,
            front_end,
            driver,
            uart_wait,
        })
    }

    /// Front-end instructions per pixel.
    pub fn front_end_per_pixel(&self) -> f64 {
        self.front_end as f64 / f64::from(self.pixels.max(1))
    }

    /// Driver instructions per pixel.
    pub fn driver_per_pixel(&self) -> f64 {
        self.driver as f64 / f64::from(self.pixels.max(1))
    }
}

/// Octave 0's row kernels over one image, in instructions (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct KernelReport {
    /// Pixels of the image.
    pub pixels: u32,
    /// The four Gaussian scales, row and column passes.
    pub gaussian: u64,
    /// The three difference-of-Gaussian rows.
    pub dog: u64,
    /// Sobel and the CORDIC magnitude/orientation on one scale.
    pub sobel_cordic: u64,
}

impl KernelReport {
    /// Reads a report from a decoded log message; `None` when `text` is not one.
    pub fn parse(text: &str) -> Option<Self> {
        let names = ["pixels", "gaussian", "dog", "sobel_cordic"];
        let [pixels, gaussian, dog, sobel_cordic] = fields(text, "kernels:", names)?;
        Some(Self {
            pixels: u32::try_from(pixels).ok()?,
            gaussian,
            dog,
            sobel_cordic,
        })
    }

    /// `instructions` per pixel of the image.
    pub fn per_pixel(&self, instructions: u64) -> f64 {
        instructions as f64 / f64::from(self.pixels.max(1))
    }
}

#[cfg(target_os = "none")]
pub use counted::{instret, log, log_kernels, measure_kernels, CountedFabric};

#[cfg(target_os = "none")]
mod counted {
    use core::cell::Cell;
    use core::hint::black_box;

    use super::{InstructionReport, KernelReport};
    use crate::fabric::fast::{column_filter, cordic_row, dog_row, row_filter, sobel_row};
    use crate::fabric::taps::GAUSS_TAPS;
    use stereocal_hdl::{PixelIn, RegisterBus};

    /// Widest row [`measure_kernels`] takes: the fabric's octave-0 line length.
    const MAX_WIDTH: usize = 1280;

    /// Instructions retired since reset (`minstret`/`minstreth`).
    pub fn instret() -> u64 {
        riscv::register::minstret::read64()
    }

    /// Sends `report` as a log packet in the format [`InstructionReport::parse`] reads.
    pub fn log(report: &InstructionReport) {
        defmt::println!(
            "instructions: frame {=u32} camera {=u8} pixels {=u32} front_end {=u64} driver {=u64} uart_wait {=u64}",
            report.frame,
            report.camera,
            report.pixels,
            report.front_end,
            report.driver,
            report.uart_wait
        );
    }

    /// Sends `report` as a log packet in the format [`KernelReport::parse`] reads.
    pub fn log_kernels(report: &KernelReport) {
        defmt::println!(
            "kernels: pixels {=u32} gaussian {=u64} dog {=u64} sobel_cordic {=u64}",
            report.pixels,
            report.gaussian,
            report.dog,
            report.sobel_cordic
        );
    }

    /// Runs octave 0's row kernels over every row of `image` (`width` pixels a row) and
    /// counts their instructions; `None` for rows wider than the fabric's.
    ///
    /// Each row gets the kernel calls octave 0 makes for it in the fast path, on rows of the
    /// same length: per scale a row pass into a ring of five rows and a column pass over the
    /// ring (one ring here where the fast path keeps one per scale: the same instructions),
    /// each scale's output feeding the next; three DoG rows of neighbouring scales; Sobel
    /// over three rows and CORDIC. `black_box` keeps the optimiser from dropping results
    /// nobody reads.
    pub fn measure_kernels(image: &[u8], width: usize) -> Option<KernelReport> {
        if width == 0 || width > MAX_WIDTH {
            return None;
        }
        let w = width;
        let mut input = [0u16; MAX_WIDTH];
        let mut ring = [[0u32; MAX_WIDTH]; 5];
        let mut scales = [[0u16; MAX_WIDTH]; 4];
        let mut dog = [0i16; MAX_WIDTH];
        let (mut sx, mut sy) = ([0i32; MAX_WIDTH], [0i32; MAX_WIDTH]);
        let (mut magnitude, mut orientation) = ([0u8; MAX_WIDTH], [0u8; MAX_WIDTH]);
        let mut report = KernelReport {
            pixels: u32::try_from(image.len()).ok()?,
            gaussian: 0,
            dog: 0,
            sobel_cordic: 0,
        };
        for (y, row) in image.chunks_exact(w).enumerate() {
            for (d, &p) in input.iter_mut().zip(row) {
                *d = u16::from(p) << 8;
            }
            let start = instret();
            for (i, taps) in GAUSS_TAPS.iter().enumerate() {
                let (done, rest) = scales.split_at_mut(i);
                let src = match done.last() {
                    Some(previous) => &previous[..w],
                    None => &input[..w],
                };
                row_filter(taps, src, &mut ring[y % 5][..w]);
                let [r0, r1, r2, r3, r4] = &ring;
                column_filter(
                    taps,
                    [&r0[..w], &r1[..w], &r2[..w], &r3[..w], &r4[..w]],
                    &mut rest[0][..w],
                );
                black_box(&mut rest[0]);
            }
            report.gaussian += instret().wrapping_sub(start);

            let start = instret();
            for i in 0..3 {
                dog_row(&scales[i][..w], &scales[i + 1][..w], &mut dog[..w]);
                black_box(&mut dog);
            }
            report.dog += instret().wrapping_sub(start);

            let start = instret();
            sobel_row(
                [&scales[0][..w], &scales[1][..w], &scales[2][..w]],
                &mut sx[..w],
                &mut sy[..w],
            );
            cordic_row(
                &sx[..w],
                &sy[..w],
                &mut magnitude[..w],
                &mut orientation[..w],
            );
            black_box((&mut magnitude, &mut orientation));
            report.sobel_cordic += instret().wrapping_sub(start);
        }
        Some(report)
    }

    /// A fabric whose every register access and PIXEL_IN call is counted in instructions.
    ///
    /// The count is a `Cell` so it can be taken through the driver's shared `bus()`
    /// accessor.
    pub struct CountedFabric<D> {
        inner: D,
        instructions: Cell<u64>,
    }

    impl<D> CountedFabric<D> {
        /// Wraps `inner`; the count starts at 0.
        pub const fn new(inner: D) -> Self {
            Self {
                inner,
                instructions: Cell::new(0),
            }
        }

        /// Instructions counted since the last call.
        pub fn take(&self) -> u64 {
            self.instructions.take()
        }

        /// The wrapped fabric (calls through it are not counted).
        pub fn inner_mut(&mut self) -> &mut D {
            &mut self.inner
        }

        fn counted<R>(&mut self, f: impl FnOnce(&mut D) -> R) -> R {
            let start = instret();
            let result = f(&mut self.inner);
            let spent = instret().wrapping_sub(start);
            self.instructions
                .set(self.instructions.get().wrapping_add(spent));
            result
        }
    }

    impl<D: RegisterBus> RegisterBus for CountedFabric<D> {
        fn read(&mut self, offset: u16) -> u32 {
            self.counted(|d| d.read(offset))
        }

        fn write(&mut self, offset: u16, value: u32) {
            self.counted(|d| d.write(offset, value))
        }

        fn read_burst(&mut self, offsets: &[u16], words: &mut [u32]) {
            self.counted(|d| d.read_burst(offsets, words))
        }
    }

    impl<D: PixelIn> PixelIn for CountedFabric<D> {
        fn push(&mut self, pixels: &[u8], start_of_frame: bool) {
            self.counted(|d| d.push(pixels, start_of_frame))
        }

        fn idle(&mut self, clocks: u32) {
            self.counted(|d| d.idle(clocks))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_logged_text_parses() {
        let text = "instructions: frame 3 camera 1 pixels 19200 front_end 1234567 driver 765432 \
                    uart_wait 9";
        assert_eq!(
            InstructionReport::parse(text),
            Some(InstructionReport {
                frame: 3,
                camera: 1,
                pixels: 19_200,
                front_end: 1_234_567,
                driver: 765_432,
                uart_wait: 9,
            })
        );
    }

    #[test]
    fn the_kernel_line_parses() {
        let text = "kernels: pixels 19200 gaussian 456789 dog 12345 sobel_cordic 67890";
        let report = KernelReport::parse(text).unwrap();
        assert_eq!(
            report,
            KernelReport {
                pixels: 19_200,
                gaussian: 456_789,
                dog: 12_345,
                sobel_cordic: 67_890,
            }
        );
        assert_eq!(report.per_pixel(38_400), 2.0);
        assert_eq!(InstructionReport::parse(text), None);
        assert_eq!(KernelReport::parse("kernels: pixels 1"), None);
    }

    #[test]
    fn other_messages_are_not_reports() {
        for text in [
            "",
            "panic: at src/main.rs",
            "instructions: frame 3",
            "instructions: frame 3 camera 1 pixels 2 front_end 4 driver 5 uart_wait 6 extra",
            "instructions: frame x camera 1 pixels 2 front_end 4 driver 5 uart_wait 6",
            "instructions: frame 3 camera 300 pixels 2 front_end 4 driver 5 uart_wait 6",
            "instructions: frame 3 camera 1 pixels 2 front_end 4 total 5",
        ] {
            assert_eq!(InstructionReport::parse(text), None, "{text:?}");
        }
    }
}
