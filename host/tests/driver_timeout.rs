//! Deadlines: each wait of the driver ends in a typed timeout that says what it waited for.
#![cfg(unix)]

mod driver_fixture;

use std::io::Write;
use std::os::unix::net::UnixStream;
use std::time::{Duration, Instant};

use driver_fixture::{frame_packets, FrameSpec, Wire};
use stereocal::driver::{Driver, DriverError, Waiting};
use stereocal::link::{Link, LinkError, StreamLink};
use stereocal_hdl::regs;
use stereocal_wire::Camera;

const SHORT: Duration = Duration::from_millis(50);

/// A driver over one end of a socket pair; the other end is a device that stays silent
/// (unless the test writes to it).
fn silent_device() -> (Driver<StreamLink<UnixStream>>, UnixStream) {
    let (host, device) = UnixStream::pair().unwrap();
    (
        Driver::new(StreamLink::from_stream(host, "unix pair")),
        device,
    )
}

#[test]
fn link_receive_times_out_at_its_deadline() {
    let (host, _device) = UnixStream::pair().unwrap();
    let mut link = StreamLink::from_stream(host, "unix pair");
    let start = Instant::now();
    let err = link.recv(&mut [0u8; 8], start + SHORT).unwrap_err();
    assert!(start.elapsed() >= SHORT);
    match err {
        LinkError::Timeout { link, waited } => {
            assert_eq!(link, "unix pair");
            assert!(waited >= SHORT - Duration::from_millis(2), "{waited:?}");
        }
        other => panic!("timeout expected, got {other}"),
    }
}

#[test]
fn hello_times_out_naming_the_hello() {
    let (mut driver, _device) = silent_device();
    let err = driver.hello(SHORT).unwrap_err();
    assert!(matches!(
        err,
        DriverError::Timeout {
            waiting_for: Waiting::Hello,
            timeout: SHORT
        }
    ));
    assert_eq!(
        err.to_string(),
        "timed out after 50ms waiting for the device's Hello"
    );
}

#[test]
fn register_read_times_out_naming_the_register() {
    let (mut driver, _device) = silent_device();
    let err = driver
        .read_register(regs::width::OFFSET, SHORT)
        .unwrap_err();
    assert!(matches!(
        err,
        DriverError::Timeout {
            waiting_for: Waiting::RegisterValue { addr: 0x0C },
            ..
        }
    ));
    assert!(err.to_string().contains("register 0x000c"), "{err}");
}

#[test]
fn frame_wait_times_out_naming_the_frame_in_progress() {
    let (mut driver, _device) = silent_device();
    assert!(matches!(
        driver.next_frame(SHORT),
        Err(DriverError::Timeout {
            waiting_for: Waiting::Frame { in_progress: None },
            ..
        })
    ));

    let (mut driver, mut device) = silent_device();
    let mut wire = Wire::new();
    let packets = frame_packets(&FrameSpec::small(12, Camera::Right));
    for p in &packets[..4] {
        wire.push(&p.repr());
    }
    device.write_all(&wire.bytes).unwrap();
    let err = driver.next_frame(SHORT).unwrap_err();
    assert!(
        matches!(
            err,
            DriverError::Timeout {
                waiting_for: Waiting::Frame {
                    in_progress: Some((12, Camera::Right, 4))
                },
                ..
            }
        ),
        "{err}"
    );
    assert_eq!(
        err.to_string(),
        "timed out after 50ms waiting for the end of frame 12 Right (4 packets received)"
    );
    // The rest arrives late: the frame is still assembled.
    let mut rest = Wire::new();
    for _ in 0..4 {
        rest.lose(&packets[0].repr());
    }
    for p in &packets[4..] {
        rest.push(&p.repr());
    }
    device.write_all(&rest.bytes).unwrap();
    let frame = driver
        .next_frame(SHORT)
        .unwrap()
        .delivered()
        .expect("delivered");
    assert_eq!(frame.frame_id, 12);
}
