//! The driver over real byte streams to a fake device thread: TCP, Unix socket, and a
//! pseudo-terminal standing in for a serial port.

mod driver_fixture;

use std::io::{Read, Write};
use std::net::TcpListener;
use std::thread;
use std::time::Duration;

use driver_fixture::{device, FrameSpec};
use stereocal::driver::{Driver, PairOutcome};
use stereocal::link::{Link, StreamLink, TcpLink};
use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_hdl::FabricConfig;
use stereocal_wire::Camera;

const T: Duration = Duration::from_secs(5);

fn frames() -> Vec<FrameSpec> {
    (1..=2)
        .flat_map(|id| {
            [
                FrameSpec::small(id, Camera::Left),
                FrameSpec::small(id, Camera::Right),
            ]
        })
        .collect()
}

/// Hello, configuration with read-back, enable, then two frame pairs.
fn session(link: impl Link) {
    let mut driver = Driver::new(link);
    let hello = driver.hello(T).expect("device Hello");
    assert_eq!(hello.version, stereocal_wire::PROTOCOL_VERSION);
    let config = FabricConfig {
        width: 32,
        height: 16,
        octaves: 2,
        contrast_threshold: 4 << 8,
        edge_ratio: 10,
        sobel_output: SobelOutput::Rows,
        sobel_scale: 1,
        points_per_batch: 16,
        row_segment: 1280,
        max_offset: 4096,
    };
    driver
        .configure(&config, T)
        .expect("configuration reads back");
    driver.enable().expect("enable");
    for id in 1..=2 {
        match driver.next_pair(T).expect("pair") {
            PairOutcome::Pair { left, right } => {
                assert_eq!((left.frame_id(), right.frame_id()), (id, id));
                let left = left.delivered().expect("left delivered");
                let right = right.delivered().expect("right delivered");
                assert_eq!(left.features.keypoints().len(), 2);
                assert_eq!(right.features.plane(1).map(|p| p.width()), Some(16));
            }
            other => panic!("pair expected, got {other:?}"),
        }
    }
    let s = driver.stats();
    assert_eq!(
        (s.frames_delivered, s.frames_damaged, s.undecodable),
        (4, 0, 0)
    );
    assert!(s.bytes_sent > 0 && s.bytes_received > 4 * s.mean_frame_bytes() as u64);
}

/// Runs `session` against a device thread on `device_side`.
fn run<S: Read + Write + Send + 'static>(mut device_side: S, link: impl Link) {
    let frames = frames();
    let device = thread::spawn(move || device::serve(&mut device_side, &frames));
    session(link);
    // The driver (and its end of the stream) is gone: the device sees the close.
    let received = device.join().expect("device thread");
    // Hello, 7 writes, 7 reads (the configuration registers, MAX_OFFSET included), enable.
    assert_eq!(received, 16);
}

#[test]
fn tcp_loopback_round_trip() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let accept = thread::spawn(move || listener.accept().map(|(s, _)| s));
    let link = TcpLink::tcp(&addr.to_string()).expect("connect");
    let device_side = accept.join().unwrap().unwrap();
    run(device_side, link);
}

#[cfg(unix)]
#[test]
fn unix_socket_round_trip() {
    use std::os::unix::net::UnixListener;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("qemu.sock");
    let listener = UnixListener::bind(&path).unwrap();
    let accept = thread::spawn(move || listener.accept().map(|(s, _)| s));
    let link = StreamLink::unix(&path).expect("connect");
    let device_side = accept.join().unwrap().unwrap();
    run(device_side, link);
}

#[cfg(unix)]
#[test]
fn serial_port_round_trip_over_a_pseudo_terminal() {
    use serialport::{SerialPort, TTYPort};
    let (master, slave) = TTYPort::pair().expect("pseudo-terminal pair");
    let link = StreamLink::from_stream(Box::new(slave) as Box<dyn SerialPort>, "serial pty");
    run(master, link);
}

#[test]
fn connecting_to_nothing_names_the_link() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    drop(listener);
    let err = TcpLink::tcp(&addr.to_string()).unwrap_err();
    assert!(
        err.to_string()
            .starts_with(&format!("tcp {addr}: cannot open")),
        "{err}"
    );
    let err = StreamLink::serial("/dev/stereocal-no-such-port", 115_200).unwrap_err();
    assert!(
        err.to_string()
            .contains("serial /dev/stereocal-no-such-port"),
        "{err}"
    );
}

#[test]
fn closed_peer_is_reported() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let accept = thread::spawn(move || listener.accept().map(|(s, _)| s));
    let mut link = TcpLink::tcp(&addr.to_string()).unwrap();
    let mut device_side = accept.join().unwrap().unwrap();
    device_side.write_all(&[1, 2, 3]).unwrap();
    drop(device_side);
    let mut buf = [0u8; 16];
    let deadline = std::time::Instant::now() + T;
    assert_eq!(link.recv(&mut buf, deadline).unwrap(), 3);
    assert!(matches!(
        link.recv(&mut buf, deadline),
        Err(stereocal::link::LinkError::Closed { .. })
    ));
}
