//! The FIFO order is part of the fabric's contract: a program reading the device sees the same
//! words whichever datapath is behind it. The device backed by the fast path and backed by the
//! register-level model (the RTL's clock-for-clock specification) are driven alike, and every
//! register read, STATUS, the FIFO levels, the overflow counters and every popped word, must
//! be the same, at 640x480, 752x480 and 1264x372, on seeded random texture and on a KITTI
//! frame, with the FIFOs drained after every line and with a drain schedule that lets both
//! overflow, under the default and under non-default thresholds.

mod common;

use common::{fit, kitti_image, random_image};
use stereocal_firmware::fabric::fifo_words::{POINT_OFFSETS, SOBEL_OFFSETS};
use stereocal_firmware::fabric::{FabricDevice, FabricModel};
use stereocal_hdl::regs::{
    point_fifo_level, point_overflow_count, sobel_fifo_level, sobel_overflow_count, status,
};
use stereocal_hdl::{PixelIn, RegisterBus, Registers};

type Model = FabricModel<1280, 640, 320, 160>;
type Device = FabricDevice<Model, 1280>;

/// The configuration registers a program writes.
#[derive(Clone, Copy, Debug)]
struct Settings {
    octaves: u8,
    contrast: u16,
    edge_ratio: u8,
    sobel_scale: u8,
    max_offset: u16,
}

/// The registers' reset values: 4 octaves, contrast 1.0, edge ratio 10, Sobel on G1.
const DEFAULTS: Settings = Settings {
    octaves: 4,
    contrast: 1 << 8,
    edge_ratio: 10,
    sobel_scale: 1,
    max_offset: 4096,
};

/// A low contrast threshold, a loose edge ratio and offsets up to 0.8 (many points), Sobel on
/// G2, 3 octaves.
const LOW_THRESHOLDS: Settings = Settings {
    octaves: 3,
    contrast: 0x08,
    edge_ratio: 31,
    sobel_scale: 2,
    max_offset: 6554,
};

/// When the program drains: after every `every`-th line time, at most `points` points and
/// `sobel` Sobel pixels.
#[derive(Clone, Copy, Debug)]
struct Drain {
    every: usize,
    points: usize,
    sobel: usize,
}

/// Everything, after every line.
const EVERY_LINE: Drain = Drain {
    every: 1,
    points: usize::MAX,
    sobel: usize::MAX,
};

/// Now and then and not all: both FIFOs overflow (the point FIFO holds 512 entries, the Sobel
/// FIFO three lines of 1280), the point FIFO one entry at a time.
const BEHIND: Drain = Drain {
    every: 9,
    points: 1,
    sobel: 2500,
};

/// Every register value the program reads, in order, driving a `w x h` frame of `image`
/// through a device on `model`.
fn transcript(model: Model, w: u16, h: u16, image: &[u8], s: Settings, drain: Drain) -> Vec<u32> {
    let mut d: Box<Device> = Box::new(FabricDevice::new(model));
    d.set_width_value(w).unwrap();
    d.set_height_value(h).unwrap();
    d.set_octaves_count(s.octaves).unwrap();
    d.set_contrast_threshold_value(s.contrast).unwrap();
    d.set_edge_threshold_r(s.edge_ratio).unwrap();
    d.set_output_mode_sobel_scale(s.sobel_scale).unwrap();
    d.set_max_offset_value(s.max_offset).unwrap();
    d.set_control_enable(true).unwrap();
    d.fire_control_frame_arm().unwrap();
    let mut log = Vec::new();
    let mut words = Vec::new();
    let mut visit = |d: &mut Device, log: &mut Vec<u32>, line: usize, all: bool| {
        for offset in [
            status::OFFSET,
            point_fifo_level::OFFSET,
            sobel_fifo_level::OFFSET,
            point_overflow_count::OFFSET,
            sobel_overflow_count::OFFSET,
        ] {
            log.push(d.read(offset));
        }
        if !all && line % drain.every != 0 {
            return;
        }
        let limit = |n: usize| if all { usize::MAX } else { n };
        let points = usize::from(d.point_fifo_level_level()).min(limit(drain.points));
        words.resize(points * POINT_OFFSETS.len(), 0);
        d.read_burst(&POINT_OFFSETS, &mut words);
        log.extend_from_slice(&words);
        let sobel = usize::from(d.sobel_fifo_level_level()).min(limit(drain.sobel));
        words.resize(sobel * SOBEL_OFFSETS.len(), 0);
        d.read_burst(&SOBEL_OFFSETS, &mut words);
        log.extend_from_slice(&words);
    };
    let width = usize::from(w);
    for (y, row) in image.chunks_exact(width).enumerate() {
        d.push(row, y == 0);
        visit(&mut d, &mut log, y, false);
    }
    let mut line = image.len() / width;
    while d.status_busy() {
        assert!(line < 8 * usize::from(h), "the frame never finished");
        d.idle(w.into());
        visit(&mut d, &mut log, line, false);
        line += 1;
    }
    visit(&mut d, &mut log, line, true);
    log.extend([
        d.point_fifo_level_level().into(),
        d.point_overflow_count_count(),
        d.sobel_overflow_count_count(),
    ]);
    log
}

/// The fast path's transcript equals the register-level model's; returns the drops counted
/// (points, Sobel pixels).
fn same_transcript(w: u16, h: u16, image: &[u8], s: Settings, drain: Drain) -> (u32, u32) {
    let model = transcript(Model::register_level(), w, h, image, s, drain);
    let fast = transcript(Model::fast(), w, h, image, s, drain);
    if let Some(i) = model.iter().zip(&fast).position(|(a, b)| a != b) {
        panic!(
            "{w}x{h} {s:?} {drain:?}: read {i} of {} differs: model {:#010x}, fast path {:#010x}",
            model.len(),
            model[i],
            fast[i]
        );
    }
    assert_eq!(model.len(), fast.len(), "{w}x{h}: as many reads");
    // The transcript ends with the point FIFO's level after the last drain and the counters.
    let &[level, points, sobel] = &model[model.len() - 3..] else {
        unreachable!("a transcript ends with three reads")
    };
    assert_eq!(level, 0, "{w}x{h}: the last drain empties the FIFO");
    (points, sobel)
}

/// Both schedules and both settings on one image.
fn check(w: u16, h: u16, image: &[u8], kind: &str) {
    let (points, sobel) = same_transcript(w, h, image, DEFAULTS, EVERY_LINE);
    assert_eq!(
        (points, sobel),
        (0, 0),
        "{w}x{h} {kind}: draining every line drops nothing"
    );
    let (points, sobel) = same_transcript(w, h, image, LOW_THRESHOLDS, BEHIND);
    eprintln!("{w}x{h} {kind}: identical reads; falling behind dropped {points} points, {sobel} Sobel pixels");
    assert!(
        points > 0 && sobel > 0,
        "{w}x{h} {kind}: the FIFOs did not overflow"
    );
}

const SIZES: [(u16, u16); 3] = [(640, 480), (752, 480), (1264, 372)];

#[test]
fn random_images_read_the_same_through_either_datapath() {
    for (i, &(w, h)) in SIZES.iter().enumerate() {
        let (wu, hu) = (usize::from(w), usize::from(h));
        check(w, h, &random_image(wu, hu, 19 + i as u64), "random texture");
    }
}

#[test]
fn a_kitti_frame_reads_the_same_through_either_datapath() {
    let Some((img, iw, ih)) = kitti_image() else {
        return;
    };
    for &(w, h) in &SIZES {
        check(w, h, &fit(&img, iw, ih, w.into(), h.into()), "KITTI");
    }
}
