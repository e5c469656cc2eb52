//! The in-process device in a thread of its own: the same bytes as called in turn, pairs
//! submitted ahead of the reads, a refused pair reported on the next read, and a read with
//! nothing under way a timeout at once.

use std::time::{Duration, Instant};

use stereocal::driver::{Driver, FrameOutcome, PairOutcome};
use stereocal::link::{FrameInput, InProcessLink, Link, LinkError, Threaded};
use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_hdl::FabricConfig;

const T: Duration = Duration::from_secs(5);
const W: u16 = 96;
const H: u16 = 64;

/// A textured image: diagonal stripes modulated by a slow ramp, different per seed.
fn image(seed: u32) -> Vec<u8> {
    (0..u32::from(H))
        .flat_map(|y| {
            (0..u32::from(W)).map(move |x| {
                let stripe = ((x * 7 + y * 3 + seed * 11) % 23) * 9;
                (stripe + x / 2 + y) as u8
            })
        })
        .collect()
}

fn config() -> FabricConfig {
    FabricConfig {
        width: W,
        height: H,
        octaves: 3,
        contrast_threshold: 1 << 8,
        sobel_output: SobelOutput::Rows,
        ..FabricConfig::default()
    }
}

/// Everything `link` has to read.
fn drain(link: &mut impl Link) -> Vec<u8> {
    let mut out = Vec::new();
    let mut buf = vec![0u8; 1 << 12];
    loop {
        match link.recv(&mut buf, Instant::now() + T) {
            Ok(n) => out.extend_from_slice(&buf[..n]),
            Err(LinkError::Timeout { .. }) => return out,
            Err(e) => panic!("{e}"),
        }
    }
}

/// The bytes of configuring `device` and running three pairs through it, all submitted before
/// the first byte is read.
fn three_pairs(mut device: impl Link + FrameInput) -> Vec<u8> {
    Driver::new(&mut device).configure(&config(), T).unwrap();
    let mut bytes = drain(&mut device);
    for frame in 0..3u32 {
        device
            .submit_pair(
                &image(2 * frame),
                &image(2 * frame + 1),
                u64::from(frame) * 33_333,
            )
            .unwrap();
    }
    bytes.extend(drain(&mut device));
    bytes
}

#[test]
fn a_threaded_device_sends_the_bytes_of_the_device_called_in_turn() {
    let direct = three_pairs(InProcessLink::new().unwrap());
    let threaded = three_pairs(Threaded::new(InProcessLink::new().unwrap(), "test").unwrap());
    assert!(direct.len() > 10_000, "{} bytes", direct.len());
    assert!(direct == threaded, "the threaded device's bytes differ");
}

#[test]
fn pairs_submitted_ahead_come_back_in_order() {
    let device = Threaded::new(InProcessLink::new().unwrap(), "test").unwrap();
    assert_eq!(device.lookahead(), 1);
    let mut driver = Driver::new(device);
    driver.configure(&config(), T).unwrap();
    for frame in 0..2u32 {
        driver
            .link_mut()
            .submit_pair(&image(frame), &image(frame + 7), u64::from(frame) * 33_333)
            .unwrap();
    }
    for id in 0..2 {
        let outcome = driver.next_pair(T).expect("pair");
        let PairOutcome::Pair { left, right } = outcome else {
            panic!("pair {id} expected, got {outcome:?}");
        };
        assert_eq!((left.frame_id(), right.frame_id()), (id, id));
        assert!(matches!(
            (left, right),
            (FrameOutcome::Delivered(_), FrameOutcome::Delivered(_))
        ));
    }
}

#[test]
fn a_refused_pair_is_reported_by_the_next_read_and_an_idle_device_times_out_at_once() {
    let mut device = Threaded::new(InProcessLink::new().unwrap(), "test").unwrap();
    Driver::new(&mut device).configure(&config(), T).unwrap();
    drain(&mut device);
    // The submission itself only queues the pair; the left channel refuses the short image.
    device.submit_pair(&[0u8; 10], &image(1), 0).unwrap();
    let mut buf = [0u8; 64];
    let err = loop {
        match device.recv(&mut buf, Instant::now() + T) {
            Ok(_) => continue,
            Err(e) => break e,
        }
    };
    assert!(err.to_string().contains("Left channel"), "{err}");
    let start = Instant::now();
    let err = device
        .recv(&mut buf, Instant::now() + T)
        .expect_err("nothing to read");
    assert!(matches!(err, LinkError::Timeout { .. }), "{err}");
    assert!(
        start.elapsed() < Duration::from_secs(1),
        "{:?}",
        start.elapsed()
    );
}
