//! The fabric's device model register by register, as `sc_fabric` defines the map: reset
//! values and access types, the frame control (FRAME_ARM, ENABLE, SOF, BUSY, FRAME_DONE,
//! FRAME_COUNT), the FIFOs seen through their pop and holding registers, the overflow flags and
//! counters, LATENCY_CLOCKS and SOFT_RESET.

mod common;

use stereocal_firmware::fabric::fifo_words::{point_from_words, POINT_OFFSETS, SOBEL_OFFSETS};
use stereocal_firmware::fabric::latency::first_pixel_of_last_octave;
use stereocal_firmware::fabric::{
    run_frame, Config, Extremum, FabricDevice, FabricModel, RegisterFrontEnd, SobelEntry,
};
use stereocal_hdl::regs::{self, control, status};
use stereocal_hdl::{PixelIn, RegisterBus, Registers};

type Model = FabricModel<64, 32, 16, 12>;
type Device = FabricDevice<Model, 64>;

const W: u16 = 64;
const H: u16 = 48;

fn device(model: Model) -> Box<Device> {
    Box::new(FabricDevice::new(model))
}

/// Writes a 64 x 48, 3-octave configuration (contrast 1.0) the way the driver does.
fn configure(d: &mut Device) {
    d.set_width_value(W).unwrap();
    d.set_height_value(H).unwrap();
    d.set_octaves_count(3).unwrap();
    d.set_contrast_threshold_value(1 << 8).unwrap();
}

fn config() -> Config {
    Config {
        octaves: 3,
        ..Config::new(W, H)
    }
}

/// Everything the FIFOs gave, popped through the registers.
#[derive(Debug, Default, PartialEq)]
struct Drained {
    points: Vec<Extremum>,
    sobel: Vec<SobelEntry>,
}

impl Drained {
    fn drain(&mut self, d: &mut Device) {
        while d.point_fifo_level_level() > 0 {
            let mut words = [0; 3];
            d.read_burst(&POINT_OFFSETS, &mut words);
            self.points.push(point_from_words(words).expect("a point"));
        }
        while d.sobel_fifo_level_level() > 0 {
            let data = d.pop_sobel_fifo_data();
            assert!(data.valid());
            self.sobel.push(SobelEntry {
                octave: data.octave(),
                orientation: data.orientation(),
                magnitude: data.magnitude(),
                x: d.sobel_fifo_position_x(),
                y: d.sobel_fifo_position_y(),
            });
        }
    }
}

/// Arms, offers `image` a row at a time (draining after each row when `drain`), then blank
/// line times until BUSY falls.
fn run(d: &mut Device, image: &[u8], out: &mut Drained, drain: bool) {
    d.set_control_enable(true).unwrap();
    d.fire_control_frame_arm().unwrap();
    assert!(d.status_busy());
    for (y, row) in image.chunks_exact(usize::from(W)).enumerate() {
        d.push(row, y == 0);
        if drain {
            out.drain(d);
        }
    }
    for _ in 0..1000 {
        if !d.status_busy() {
            return;
        }
        d.idle(W.into());
        if drain {
            out.drain(d);
        }
    }
    panic!("the frame never finished");
}

#[test]
fn registers_come_out_of_reset_with_the_maps_values() {
    let mut d = device(Model::fast());
    for r in regs::REGISTERS {
        let expected = if r.pops_on_read {
            0
        } else {
            r.reset & !r.wo_mask
        };
        assert_eq!(d.read(r.offset), expected, "{}", r.name);
    }
    assert_eq!(d.version_magic(), 0x5C01);
}

#[test]
fn writes_keep_only_writable_bits() {
    let mut d = device(Model::fast());
    for r in regs::REGISTERS {
        if r.pops_on_read || r.offset == control::OFFSET || r.offset == status::OFFSET {
            continue;
        }
        let before = d.read(r.offset);
        d.write(r.offset, u32::MAX);
        assert_eq!(
            d.read(r.offset),
            (before & !r.rw_mask) | r.rw_mask,
            "{}: rw bits take the write, the rest keep their value",
            r.name
        );
    }
    // Unmapped words and offsets past the window read 0 and take no write.
    for offset in [0x74, 0xFC, 0x100, 0xFFFC] {
        d.write(offset, u32::MAX);
        assert_eq!(d.read(offset), 0, "{offset:#x}");
    }
    // The low two address bits are not decoded (the RTL uses addr[7:2]).
    assert_eq!(d.read(regs::width::OFFSET + 1), d.read(regs::width::OFFSET));
}

#[test]
fn strobes_read_zero_and_arm_only_an_idle_fabric() {
    let mut d = device(Model::fast());
    configure(&mut d);
    d.write(control::OFFSET, 0b111 & !control::SOFT_RESET.mask());
    assert_eq!(
        d.read(control::OFFSET),
        control::ENABLE.mask(),
        "strobes read 0"
    );
    assert!(d.status_busy());
    // The frame waits for SOF: pixels without it are discarded.
    let image = common::random_image(usize::from(W), usize::from(H), 5);
    d.push(&image[..usize::from(W)], false);
    d.idle(10_000);
    assert!(d.status_busy());
    // ENABLE low: PIXEL_IN is not ready, the SOF pixel is lost too.
    d.set_control_enable(false).unwrap();
    d.push(&image, true);
    assert!(d.status_busy());
    // A second FRAME_ARM while busy changes nothing; SOFT_RESET in the same write wins.
    d.fire_control_frame_arm().unwrap();
    assert!(d.status_busy());
    d.write(
        control::OFFSET,
        control::FRAME_ARM.mask() | control::SOFT_RESET.mask(),
    );
    assert!(!d.status_busy());
    assert_eq!(d.read(status::OFFSET), 0);
}

#[test]
fn a_frame_through_the_registers_equals_the_models_streams() {
    let image = common::random_image(usize::from(W), usize::from(H), 7);
    // The register-level model run on its own.
    let mut fe = Box::new(RegisterFrontEnd::<64, 32, 16, 12>::new());
    let mut expected = Drained::default();
    run_frame(
        &mut *fe,
        &config(),
        &image,
        &mut |p| expected.points.extend_from_slice(p),
        &mut |s| expected.sobel.extend(s.pixels()),
    )
    .unwrap();
    assert!(!expected.points.is_empty());

    let mut d = device(Model::register_level());
    configure(&mut d);
    let mut got = Drained::default();
    run(&mut d, &image, &mut got, true);
    assert_eq!(got, expected, "same entries in the same order");
    assert_eq!(d.read(status::OFFSET), status::FRAME_DONE.mask());
    assert_eq!(d.frame_count_count(), 1);
    assert_eq!(
        u64::from(d.latency_clocks_clocks()),
        first_pixel_of_last_octave(W, H, 3)
    );
    assert_eq!(
        Some(u64::from(d.latency_clocks_clocks())),
        fe.first_input_clock(2),
        "LATENCY_CLOCKS is the model's own clock count"
    );
    // FRAME_DONE is cleared by writing 1 to it, and only then.
    d.write(status::OFFSET, 0);
    assert!(d.status_frame_done());
    d.clear_status_frame_done().unwrap();
    assert_eq!(d.read(status::OFFSET), 0);

    // The fast path behind the registers: the same entries in the same order.
    let mut fast = device(Model::fast());
    configure(&mut fast);
    let mut fast_got = Drained::default();
    run(&mut fast, &image, &mut fast_got, true);
    assert_eq!(fast_got, got);
    assert_eq!(fast.latency_clocks_clocks(), d.latency_clocks_clocks());
}

#[test]
fn full_fifos_drop_count_and_flag_until_soft_reset() {
    for model in [Model::fast(), Model::register_level()] {
        let mut d = device(model);
        configure(&mut d);
        let image = common::random_image(usize::from(W), usize::from(H), 9);
        let mut nothing = Drained::default();
        run(&mut d, &image, &mut nothing, false);
        let capacity = 3 * W;
        assert_eq!(d.sobel_fifo_level_level(), capacity);
        assert!(d.status_sobel_overflow());
        let dropped = d.sobel_overflow_count_count();
        assert!(dropped > 0);
        // FIFOs and counters survive the next FRAME_ARM (only SOFT_RESET clears them).
        run(&mut d, &image, &mut nothing, false);
        assert_eq!(d.frame_count_count(), 2);
        assert!(d.sobel_overflow_count_count() > dropped);
        // The entry popped is the oldest; its position stays in the holding register.
        let head = d.pop_sobel_fifo_data();
        assert!(head.valid());
        assert_eq!(d.sobel_fifo_level_level(), capacity - 1);
        let position = d.read(regs::sobel_fifo_position::OFFSET);
        assert_eq!(d.read(regs::sobel_fifo_position::OFFSET), position);

        d.fire_control_soft_reset().unwrap();
        for (name, offset) in [
            ("STATUS", status::OFFSET),
            ("POINT_FIFO_LEVEL", regs::point_fifo_level::OFFSET),
            ("SOBEL_FIFO_LEVEL", regs::sobel_fifo_level::OFFSET),
            ("POINT_OVERFLOW_COUNT", regs::point_overflow_count::OFFSET),
            ("SOBEL_OVERFLOW_COUNT", regs::sobel_overflow_count::OFFSET),
            ("FRAME_COUNT", regs::frame_count::OFFSET),
            ("LATENCY_CLOCKS", regs::latency_clocks::OFFSET),
            ("SOBEL_FIFO_POSITION", regs::sobel_fifo_position::OFFSET),
        ] {
            assert_eq!(d.read(offset), 0, "{name} after SOFT_RESET");
        }
        assert_eq!(d.width_value(), W, "the configuration keeps its values");
        // Pops of an empty FIFO read 0 and zero the holding registers.
        assert!(!d.pop_point_fifo_data().valid());
        assert_eq!(d.read(regs::point_fifo_dxdy::OFFSET), 0);
        let mut words = [1; 5];
        d.read_burst(&SOBEL_OFFSETS, &mut words);
        assert_eq!(words, [0; 5]);
    }
}

#[test]
fn pixels_offered_in_pieces_make_the_same_frame() {
    let image = common::random_image(usize::from(W), usize::from(H), 11);
    let mut whole = device(Model::fast());
    configure(&mut whole);
    let mut expected = Drained::default();
    run(&mut whole, &image, &mut expected, true);

    let mut d = device(Model::fast());
    configure(&mut d);
    d.set_control_enable(true).unwrap();
    d.fire_control_frame_arm().unwrap();
    let mut got = Drained::default();
    let (first, rest) = image.split_at(5);
    d.push(first, true);
    for piece in rest.chunks(37) {
        d.push(piece, false);
        got.drain(&mut d);
    }
    // Pixels after the frame's last one are not taken.
    d.push(&image[..100], false);
    while d.status_busy() {
        d.idle(7);
        got.drain(&mut d);
    }
    assert_eq!(got, expected);
}
