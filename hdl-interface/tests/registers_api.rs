//! The generated typed interface (`regs_api.rs`) on both transports: the in-memory bank and
//! MMIO over a word array, and through `&mut B` as a generic driver receives it.

use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_hdl::regs::{
    self, control, output_mode, point_fifo_data, point_fifo_dsdog, point_fifo_dxdy,
    sobel_fifo_data, sobel_fifo_position, status,
};
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
    assert_eq!(bank.contrast_threshold_value(), 8 << 8);
    assert_eq!(bank.max_offset_value(), 4096);
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
    // The packing fields keep their reset values: 1280-pixel segments, 16 points per batch.
    assert_eq!(bank.output_mode_points_per_batch(), 16);
    assert_eq!(bank.output_mode_row_segment(), 1280);
    assert_eq!(
        bank.read(output_mode::OFFSET),
        1280 << 16 | 16 << 8 | 3 << 4
    );
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

/// A bus whose FIFO data registers pop a queue, counting the reads; a pop loads the entry's
/// other words into holding registers (zero when the FIFO was empty), as the fabric does.
struct Fifos {
    /// Point entries: word 0, DXDY, DSDOG.
    points: [[u32; 3]; 2],
    /// Sobel entries: word 0, position.
    sobel: [[u32; 2]; 1],
    point_reads: usize,
    sobel_reads: usize,
    point_hold: [u32; 2],
    sobel_hold: u32,
}

impl RegisterBus for Fifos {
    fn read(&mut self, offset: u16) -> u32 {
        match offset {
            point_fifo_data::OFFSET => {
                let entry = self.points.get(self.point_reads).copied().unwrap_or([0; 3]);
                self.point_reads += 1;
                self.point_hold = [entry[1], entry[2]];
                entry[0]
            }
            point_fifo_dxdy::OFFSET => self.point_hold[0],
            point_fifo_dsdog::OFFSET => self.point_hold[1],
            sobel_fifo_data::OFFSET => {
                let entry = self.sobel.get(self.sobel_reads).copied().unwrap_or([0; 2]);
                self.sobel_reads += 1;
                self.sobel_hold = entry[1];
                entry[0]
            }
            sobel_fifo_position::OFFSET => self.sobel_hold,
            _ => 0,
        }
    }

    fn write(&mut self, _offset: u16, _value: u32) {}
}

#[test]
fn popping_reads_the_fifo_once_and_types_every_field() {
    let point = (1 << 31) | (1 << 24) | (3 << 22) | (1023 << 11) | 1279;
    // dx = -0.5, dy = 0.25, ds = -1/8192, dog = -3.5 grey levels.
    let dxdy = (0x0800 << 16) | 0xF000;
    let dsdog = (0xFC80 << 16) | 0xFFFF;
    let sobel = (1 << 31) | (2 << 14) | (63 << 8) | 200;
    let position = (239 << 16) | 319;
    let mut bus = Fifos {
        points: [[point, dxdy, dsdog], [0; 3]],
        sobel: [[sobel, position]],
        point_reads: 0,
        sobel_reads: 0,
        point_hold: [0; 2],
        sobel_hold: 0,
    };
    let p = bus.pop_point_fifo_data();
    assert_eq!(bus.point_reads, 1);
    assert_eq!(p, PointFifoData(point));
    assert!(p.valid());
    assert_eq!((p.x(), p.y(), p.octave(), p.scale()), (1279, 1023, 3, 1));
    assert_eq!(
        (
            bus.point_fifo_dxdy_dx() as i16,
            bus.point_fifo_dxdy_dy() as i16
        ),
        (-4096, 2048)
    );
    assert_eq!(
        (
            bus.point_fifo_dsdog_ds() as i16,
            bus.point_fifo_dsdog_dog() as i16
        ),
        (-1, -896)
    );
    assert_eq!(bus.point_reads, 1, "holding registers do not pop");
    let empty = bus.pop_point_fifo_data();
    assert!(!empty.valid());
    assert_eq!(bus.point_reads, 2);
    assert_eq!(
        (bus.point_fifo_dxdy_dx(), bus.point_fifo_dsdog_dog()),
        (0, 0)
    );

    let s = bus.pop_sobel_fifo_data();
    assert_eq!(bus.sobel_reads, 1);
    assert_eq!(s, SobelFifoData(sobel));
    assert!(s.valid());
    assert_eq!((s.magnitude(), s.orientation(), s.octave()), (200, 63, 2));
    assert_eq!(
        (bus.sobel_fifo_position_x(), bus.sobel_fifo_position_y()),
        (319, 239)
    );
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
        bus.set_contrast_threshold_value(12 << 8)
    }
    let mut bank = RegisterBank::new();
    configure(&mut bank).unwrap();
    assert_eq!(bank.height_value(), 240);
    assert_eq!(bank.contrast_threshold_value(), 12 << 8);
}
