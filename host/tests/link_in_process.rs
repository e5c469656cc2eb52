//! The in-process link end to end: the firmware's soft-core driver and fabric model inside
//! the host, configured by the host driver, frames reassembled from the wire bytes. The
//! result is checked against the fabric model run directly on the same image.

use std::time::Duration;

use stereocal::driver::{Driver, DriverError, FrameOutcome, PairOutcome, ReceivedFrame};
use stereocal::features::Gradients;
use stereocal::link::{InProcessLink, Link};
use stereocal_firmware::fabric::{run_frame, Config, Extremum, FastFrontEnd, SobelEntry, SobelRun};
use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_hdl::FabricConfig;
use stereocal_wire::{Camera, ErrorCode};

const T: Duration = Duration::from_secs(1);
const W: u16 = 128;
const H: u16 = 96;

/// Smooth blobs on a grey ramp: plenty of DoG extrema at several scales.
fn image(seed: u32) -> Vec<u8> {
    let mut state = seed.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state
    };
    let blobs: Vec<(f32, f32, f32, f32)> = (0..160)
        .map(|_| {
            let x = (next() % u32::from(W)) as f32;
            let y = (next() % u32::from(H)) as f32;
            let sigma = 1.0 + (next() % 40) as f32 / 10.0;
            let amp = (next() % 240) as f32 - 120.0;
            (x, y, sigma, amp)
        })
        .collect();
    let mut out = Vec::with_capacity(usize::from(W) * usize::from(H));
    for y in 0..H {
        for x in 0..W {
            let mut v = 100.0 + f32::from(x) * 0.3;
            for &(bx, by, s, a) in &blobs {
                let d2 = (f32::from(x) - bx).powi(2) + (f32::from(y) - by).powi(2);
                v += a * (-d2 / (2.0 * s * s)).exp();
            }
            out.push(v.clamp(0.0, 255.0) as u8);
        }
    }
    out
}

fn config(mode: SobelOutput) -> FabricConfig {
    FabricConfig {
        width: W,
        height: H,
        octaves: 3,
        contrast_threshold: 1 << 8,
        edge_ratio: 10,
        sobel_output: mode,
        sobel_scale: 1,
        points_per_batch: 16,
        row_segment: 1280,
        max_offset: 4096,
    }
}

/// What the fabric model itself produces for `image`.
fn reference(config: &FabricConfig, image: &[u8]) -> (Vec<Extremum>, Vec<SobelEntry>) {
    let mut fe: Box<FastFrontEnd<128, 64, 32, 16>> = Box::new(FastFrontEnd::new());
    let (mut points, mut sobel) = (Vec::new(), Vec::new());
    run_frame(
        fe.as_mut(),
        &Config::from(config),
        image,
        &mut |p: &[Extremum]| points.extend_from_slice(p),
        &mut |s: SobelRun<'_>| sobel.extend(s.pixels()),
    )
    .expect("reference run");
    (points, sobel)
}

fn pair(config: &FabricConfig, left: &[u8], right: &[u8]) -> (ReceivedFrame, ReceivedFrame) {
    let mut driver = Driver::new(InProcessLink::new().expect("device"));
    let hello = driver.hello(T).expect("hello");
    assert!(hello
        .capabilities
        .contains(stereocal_wire::Capabilities::SOBEL_ROWS));
    driver.configure(config, T).expect("configure");
    let summaries = driver
        .link_mut()
        .submit_pair(left, right, 42)
        .expect("frames run");
    let outcome = driver.next_pair(T).expect("pair");
    let PairOutcome::Pair { left, right } = outcome else {
        panic!("pair expected, got {outcome:?}");
    };
    let deliver = |f: FrameOutcome| match f {
        FrameOutcome::Delivered(f) => *f,
        FrameOutcome::Damaged(d) => panic!("damaged: {}", d.damage),
    };
    let (left, right) = (deliver(left), deliver(right));
    assert_eq!(
        left.packets,
        2 + summaries[0].sobel_packets
            + summaries[0].points.div_ceil(config.points_per_batch.into())
    );
    assert_eq!(driver.link().pending(), 0);
    assert!(matches!(
        driver.next_frame(Duration::ZERO),
        Err(DriverError::Timeout { .. })
    ));
    assert_eq!(driver.stats().frames_damaged, 0);
    (left, right)
}

fn assert_keypoints_match(frame: &ReceivedFrame, points: &[Extremum]) {
    let k = frame.features.keypoints();
    assert_eq!(k.len(), points.len());
    for (k, p) in k.iter().zip(points) {
        let step = f32::from(1u16 << p.octave);
        let x = (f32::from(p.x) + p.dx.to_num::<f32>()) * step;
        let y = (f32::from(p.y) + p.dy.to_num::<f32>()) * step;
        assert_eq!((k.x, k.y, k.octave), (x, y, p.octave));
    }
}

#[test]
fn rows_mode_round_trip_matches_the_fabric() {
    let (left_img, right_img) = (image(1), image(2));
    let config = config(SobelOutput::Rows);
    let (left, right) = pair(&config, &left_img, &right_img);
    assert_eq!((left.camera, right.camera), (Camera::Left, Camera::Right));
    assert_eq!(left.frame_id, right.frame_id);
    assert_eq!(left.features.timestamp_us, 42);
    for (frame, img) in [(&left, &left_img), (&right, &right_img)] {
        let (points, sobel) = reference(&config, img);
        assert!(
            points.len() >= 10,
            "the test image has {} extrema",
            points.len()
        );
        assert_keypoints_match(frame, &points);
        let Gradients::Planes(planes) = frame.features.gradients() else {
            panic!("planes expected");
        };
        assert!(!planes.is_empty());
        let mut checked = 0;
        for s in &sobel {
            if let Some(plane) = frame.features.plane(s.octave) {
                assert_eq!(
                    plane.get(i32::from(s.x), i32::from(s.y)),
                    Some((s.magnitude, s.orientation)),
                    "octave {} ({}, {})",
                    s.octave,
                    s.x,
                    s.y
                );
                checked += 1;
            }
        }
        let plane_pixels: usize = planes.iter().map(|p| p.magnitude().len()).sum();
        assert_eq!(
            checked, plane_pixels,
            "every plane pixel came from the fabric"
        );
        assert_eq!((frame.dropped_points, frame.dropped_sobel), (0, 0));
    }
}

#[test]
fn patches_mode_round_trip_matches_the_fabric() {
    let img = image(3);
    let config = config(SobelOutput::Patches);
    let (left, _) = pair(&config, &img, &img);
    let (points, sobel) = reference(&config, &img);
    let Gradients::Patches(patches) = left.features.gradients() else {
        panic!("patches expected");
    };
    assert_eq!(patches.len(), left.features.keypoints().len());
    assert_eq!(
        left.features.keypoints().len() as u32 + left.points_without_patch,
        points.len() as u32
    );
    assert!(patches.len() >= 10, "{} patches", patches.len());
    assert_eq!(left.points_without_patch, left.dropped_sobel);
    // Every patch sample is the fabric's Sobel pixel at the point's octave, zero outside.
    let lookup = |octave: u8, x: i32, y: i32| {
        sobel
            .iter()
            .find(|s| s.octave == octave && i32::from(s.x) == x && i32::from(s.y) == y)
            .map_or((0, 0), |s| (s.magnitude, s.orientation))
    };
    for (i, k) in left.features.keypoints().iter().enumerate().step_by(3) {
        let (ox, oy) = k.octave_position();
        let (cx, cy) = (ox.round() as i32, oy.round() as i32);
        for (dx, dy) in [(0, 0), (-8, -8), (7, 7), (3, -5)] {
            assert_eq!(
                left.features.window_sample(i, dx, dy),
                Some(lookup(k.octave, cx + dx, cy + dy)),
                "keypoint {i} offset ({dx}, {dy})"
            );
        }
    }
}

#[test]
fn register_reads_are_answered_and_bad_images_are_refused() {
    let mut link = InProcessLink::new().expect("device");
    let mut driver = Driver::new(&mut link);
    driver.configure(&config(SobelOutput::Rows), T).unwrap();
    let err = driver
        .link_mut()
        .submit(Camera::Left, &[0u8; 10], 0)
        .unwrap_err();
    assert!(err.to_string().contains("Left channel"), "{err}");
    // An address outside the map: the device answers with an ErrorReport, not a value.
    match driver.read_register(0x00FC, T) {
        Err(DriverError::Device { code, detail, .. }) => {
            assert_eq!((code, detail), (ErrorCode::UnknownRegister, 0xFC));
        }
        other => panic!("device error expected, got {other:?}"),
    }
    assert_eq!(
        driver
            .read_register(stereocal_hdl::regs::width::OFFSET, T)
            .unwrap(),
        u32::from(W)
    );
}

/// Everything the link has to read.
fn drain(link: &mut InProcessLink) -> Vec<u8> {
    let mut out = Vec::new();
    let mut buf = vec![0u8; 1 << 16];
    while let Ok(n) = link.recv(&mut buf, std::time::Instant::now()) {
        out.extend_from_slice(&buf[..n]);
    }
    out
}

#[test]
fn a_pair_run_on_two_cores_sends_the_bytes_of_one_camera_after_the_other() {
    let (left, right) = (image(11), image(12));
    for mode in [SobelOutput::Rows, SobelOutput::Patches] {
        let mut streams = Vec::new();
        for concurrent in [true, false] {
            streams.push(three_pairs(mode, concurrent, &left, &right));
        }
        assert!(streams[0].len() > 10_000, "{} bytes", streams[0].len());
        assert!(
            streams[0] == streams[1],
            "{mode:?}: the concurrent pairs' bytes differ"
        );
    }
}

/// The bytes of three pairs, run concurrently or one camera after the other.
fn three_pairs(mode: SobelOutput, concurrent: bool, left: &[u8], right: &[u8]) -> Vec<u8> {
    let mut link = InProcessLink::new().expect("device");
    Driver::new(&mut link).configure(&config(mode), T).unwrap();
    drain(&mut link);
    for frame in 0..3u64 {
        if concurrent {
            link.submit_pair(left, right, frame * 33_333).unwrap();
        } else {
            link.submit(Camera::Left, left, frame * 33_333).unwrap();
            link.submit(Camera::Right, right, frame * 33_333).unwrap();
        }
    }
    drain(&mut link)
}

#[test]
fn a_refused_left_image_leaves_the_cameras_in_step() {
    let mut driver = Driver::new(InProcessLink::new().expect("device"));
    driver.configure(&config(SobelOutput::Rows), T).unwrap();
    let (left, right) = (image(21), image(22));
    let err = driver
        .link_mut()
        .submit_pair(&left[..10], &right, 0)
        .unwrap_err();
    assert!(err.to_string().contains("Left channel"), "{err}");
    driver
        .link_mut()
        .submit_pair(&left, &right, 33_333)
        .unwrap();
    let outcome = driver.next_pair(T).expect("pair");
    let PairOutcome::Pair { left, right } = outcome else {
        panic!("both cameras of frame 0 expected, got {outcome:?}");
    };
    assert_eq!((left.frame_id(), right.frame_id()), (0, 0));
    assert!(matches!(
        (left, right),
        (FrameOutcome::Delivered(_), FrameOutcome::Delivered(_))
    ));
}
