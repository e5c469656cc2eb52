//! The stream engine's packets are a function of the datapath's output alone: the device run
//! by the driver through the ideal time model (whole lines, accesses between them) and run
//! clock by clock through the clock-exact model (pixels with random gaps, the arm and the
//! polls on clocks of their own, the datapath flushing on every blanking clock) send the same
//! bytes, in rows and patches mode, with small batches and segments and with parity.

mod common;

use common::random_image;
use stereocal_firmware::driver::Driver;
use stereocal_firmware::fabric::device::{Access, Beat};
use stereocal_firmware::fabric::{FabricDevice, RegisterFrontEnd};
use stereocal_firmware::framing::ByteSink;
use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_hdl::regs::{control, status};
use stereocal_hdl::{FabricConfig, Registers};
use stereocal_wire::Camera;

/// The link: every byte the engine sends.
#[derive(Default)]
struct Collect(Vec<u8>);

impl ByteSink for Collect {
    fn write(&mut self, bytes: &[u8]) {
        self.0.extend_from_slice(bytes);
    }
}

type Datapath = RegisterFrontEnd<160, 80, 40, 20>;
type Device = FabricDevice<Datapath, 160, Collect>;

const WIDTH: u16 = 160;
const HEIGHT: u16 = 96;
const TIMESTAMP_US: u64 = 0x1_2345_6789;

fn config(mode: SobelOutput) -> FabricConfig {
    FabricConfig {
        width: WIDTH,
        height: HEIGHT,
        octaves: 3,
        contrast_threshold: 2 << 8,
        sobel_output: mode,
        points_per_batch: 8,
        row_segment: 48,
        ..FabricConfig::default()
    }
}

fn device() -> Device {
    FabricDevice::with_link(Datapath::new(), Collect::default())
}

/// The driver's frame, on the ideal time model.
fn ideal(config: &FabricConfig, fec: bool, image: &[u8]) -> Vec<u8> {
    let mut driver: Box<Driver<Device, 160>> = Box::new(Driver::new(device(), Camera::Right));
    driver.configure(config).unwrap();
    driver.set_fec(fec).unwrap();
    let summary = driver.process_frame(image, TIMESTAMP_US).unwrap();
    assert!(
        summary.points > 0 && summary.sobel_packets > 0,
        "{summary:?}"
    );
    std::mem::take(&mut driver.bus_mut().link_mut().0)
}

/// The same frame clock by clock: pixels with gaps drawn from `seed`, BUSY polled until the
/// engine is done.
fn clocked(config: &FabricConfig, fec: bool, image: &[u8], seed: u64) -> Vec<u8> {
    let mut d = device();
    config.write_to(&mut d).unwrap();
    d.set_stream_control_camera(1).unwrap();
    d.set_stream_control_enable(true).unwrap();
    d.set_stream_control_fec(fec).unwrap();
    d.set_frame_id_value(0).unwrap();
    d.set_timestamp_lo_value(TIMESTAMP_US as u32).unwrap();
    d.set_timestamp_hi_value((TIMESTAMP_US >> 32) as u32)
        .unwrap();
    let arm = control::ENABLE.mask() | control::FRAME_ARM.mask();
    d.clock(None, Some(Access::Write(control::OFFSET, arm)));
    let mut state = seed;
    let mut gap = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 60) < 5
    };
    let mut pixels = image.iter().enumerate().peekable();
    while let Some(&(i, &data)) = pixels.peek() {
        if gap() {
            d.clock(None, Some(Access::Read(status::OFFSET)));
            continue;
        }
        let beat = Beat {
            data,
            sof: i == 0,
            eol: (i + 1) % usize::from(WIDTH) == 0,
        };
        if d.clock(Some(beat), None).ready {
            pixels.next();
        }
    }
    let busy = |word: u32| status::BUSY.extract(word) != 0;
    let mut polls = 0;
    while d
        .clock(None, Some(Access::Read(status::OFFSET)))
        .read
        .is_some_and(busy)
    {
        polls += 1;
        assert!(
            polls < 100 * usize::from(WIDTH) * usize::from(HEIGHT),
            "BUSY stays 1"
        );
    }
    std::mem::take(&mut d.link_mut().0)
}

#[test]
fn the_clocked_device_sends_the_drivers_bytes() {
    let image = random_image(usize::from(WIDTH), usize::from(HEIGHT), 11);
    for (mode, fec, seed) in [
        (SobelOutput::Rows, false, 1),
        (SobelOutput::Patches, false, 2),
        (SobelOutput::Patches, true, 3),
    ] {
        let config = config(mode);
        let ideal = ideal(&config, fec, &image);
        let clocked = clocked(&config, fec, &image, seed);
        assert!(!ideal.is_empty());
        assert!(
            ideal == clocked,
            "{mode:?}, FEC {fec}: {} bytes ideal, {} clocked, first difference at {:?}",
            ideal.len(),
            clocked.len(),
            ideal.iter().zip(&clocked).position(|(a, b)| a != b)
        );
    }
}
