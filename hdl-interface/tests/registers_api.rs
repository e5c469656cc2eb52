//! The generated typed interface (`regs_api.rs`) on both transports: the in-memory bank and
//! MMIO over a word array, and through `&mut B` as a generic driver receives it.

use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_hdl::regs::{self, control, output_mode, point_fifo_data, sobel_fifo_data, status};
use stereocal_hdl::regs_api::{PointFifoData, SobelFifoData};
use stereocal_hdl::{Error, Mmio, RegisterBank, RegisterBus, Registers};

#[test]
fn getters_read_the_reset_state() {
    let mut bank = RegisterBank::new();
    assert_eq!(bank.version_magic(), 0x5C01);
    assert_eq!(u32::from(bank.version_major()), regs::VERSION_MAJOR);
    assert_eq!(u32::from(bank.version_minor()), regs::VERSION_MINOR);
    assert!(!bank.control_enable());
    assert!(!bank.status_busy());
    assert_eq!(bank.width_value(), 640);
    assert_eq!(bank.height_value(), 480);
    assert_eq!(bank.octaves_count(), 4);
    assert_eq!(bank.contrast_threshold_value(), 8);
    assert_eq!(bank.edge_threshold_r(), 10);
    assert_eq!(
        bank.output_mode_sobel_output(),
        output_mode::SOBEL_OUTPUT_RESET
    );
    assert_eq!(bank.output_mode_sobel_scale(), 1);
    assert_eq!(bank.point_fifo_level_level(), 0);
    assert_eq!(bank.frame_count_count(), 0);
    assert_eq!(bank.latency_clocks_clocks(), 0);
}

#[test]
fn setters_round_trip_and_keep_the_other_fields() {
    let mut bank = RegisterBank::new();
    bank.set_width_value(1280).unwrap();
    bank.set_octaves_count(2).unwrap();
    bank.set_output_mode_sobel_scale(3).unwrap();
    bank.set_output_mode_sobel_output(SobelOutput::Rows)
        .unwrap();
    assert_eq!(bank.width_value(), 1280);
    assert_eq!(bank.octaves_count(), 2);
    assert_eq!(bank.output_mode_sobel_output(), SobelOutput::Rows);
    assert_eq!(bank.output_mode_sobel_scale(), 3);
    assert_eq!(bank.read(output_mode::OFFSET), 3 << 4);
}

#[test]
fn setters_check_ranges_and_write_nothing_outside_them() {
    let mut bank = RegisterBank::new();
    let low = bank.set_width_value(15);
    assert!(
        matches!(
            low,
            Err(Error::FieldOutOfRange {
                field: "WIDTH.VALUE",
                value: 15,
                ..
            })
        ),
        "{low:?}"
    );
    assert!(bank.set_octaves_count(5).is_err());
    assert!(bank.set_edge_threshold_r(0).is_err());
    assert_eq!(bank.width_value(), 640);
    assert_eq!(bank.octaves_count(), 4);
    assert_eq!(bank.edge_threshold_r(), 10);
}

#[test]
fn clearing_one_flag_leaves_the_others() {
    let mut bank = RegisterBank::new();
    bank.device_set_field(&status::FRAME_DONE, 1).unwrap();
    bank.device_set_field(&status::POINT_OVERFLOW, 1).unwrap();
    bank.device_set_field(&status::BUSY, 1).unwrap();
    assert!(bank.status_frame_done() && bank.status_point_overflow());
    bank.clear_status_frame_done().unwrap();
    assert!(!bank.status_frame_done());
    assert!(bank.status_point_overflow());
    assert!(bank.status_busy());
    assert!(!bank.status_sobel_overflow());
}

#[test]
fn firing_a_strobe_keeps_enable_and_fires_nothing_else() {
    let mut bank = RegisterBank::new();
    bank.set_control_enable(true).unwrap();
    bank.fire_control_frame_arm().unwrap();
    assert!(bank.control_enable());
    assert_eq!(bank.device_take_field(&control::FRAME_ARM), Ok(1));
    assert_eq!(bank.device_take_field(&control::SOFT_RESET), Ok(0));
    bank.fire_control_soft_reset().unwrap();
    assert_eq!(bank.device_take_field(&control::SOFT_RESET), Ok(1));
    assert!(bank.control_enable());
}

/// A bus whose FIFO data registers pop a queue, counting the reads.
struct Fifos {
    points: [u32; 2],
    sobel: [u32; 1],
    point_reads: usize,
    sobel_reads: usize,
}

impl RegisterBus for Fifos {
    fn read(&mut self, offset: u16) -> u32 {
        match offset {
            point_fifo_data::OFFSET => {
                let word = self.points.get(self.point_reads).copied().unwrap_or(0);
                self.point_reads += 1;
                word
            }
            sobel_fifo_data::OFFSET => {
                let word = self.sobel.get(self.sobel_reads).copied().unwrap_or(0);
                self.sobel_reads += 1;
                word
            }
            _ => 0,
        }
    }

    fn write(&mut self, _offset: u16, _value: u32) {}
}

#[test]
fn popping_reads_the_fifo_once_and_types_every_field() {
    let point = (1 << 31) | (1 << 26) | (1 << 24) | (3 << 22) | (59 << 11) | 79;
    let sobel = (1 << 31) | (1 << 14) | (63 << 8) | 200;
    let mut bus = Fifos {
        points: [point, 0],
        sobel: [sobel],
        point_reads: 0,
        sobel_reads: 0,
    };
    let p = bus.pop_point_fifo_data();
    assert_eq!(bus.point_reads, 1);
    assert_eq!(p, PointFifoData(point));
    assert!(p.valid() && p.polarity());
    assert_eq!((p.x(), p.y(), p.octave(), p.scale()), (79, 59, 3, 1));
    let empty = bus.pop_point_fifo_data();
    assert!(!empty.valid());
    assert_eq!(bus.point_reads, 2);

    let s = bus.pop_sobel_fifo_data();
    assert_eq!(bus.sobel_reads, 1);
    assert_eq!(s, SobelFifoData(sobel));
    assert!(s.valid() && s.first());
    assert_eq!((s.magnitude(), s.orientation()), (200, 63));
}

#[test]
fn mmio_gets_the_same_interface() {
    let mut window = [0u32; regs::WINDOW_SIZE as usize / 4];
    {
        // SAFETY: `window` is aligned, WINDOW_SIZE bytes long and outlives `bus`; it is only
        // touched through `bus` in this block.
        let mut bus = unsafe { Mmio::new(window.as_mut_ptr() as usize) };
        bus.set_width_value(320).unwrap();
        bus.set_control_enable(true).unwrap();
        assert_eq!(bus.width_value(), 320);
        assert!(bus.control_enable());
    }
    assert_eq!(window[usize::from(regs::width::OFFSET) / 4], 320);
    assert_eq!(window[usize::from(control::OFFSET) / 4], 1);
}

#[test]
fn generic_code_reaches_it_through_mut_references() {
    fn configure<B: RegisterBus>(mut bus: B) -> Result<(), Error> {
        bus.set_height_value(240)?;
        bus.set_contrast_threshold_value(12)
    }
    let mut bank = RegisterBank::new();
    configure(&mut bank).unwrap();
    assert_eq!(bank.height_value(), 240);
    assert_eq!(bank.contrast_threshold_value(), 12);
}
