//! A device's byte stream, damaged packet by packet, into a whole host session: the driver's
//! reassembly, the Sobel planes and keypoints it builds, pairing, the estimator and the
//! filter. Nothing may panic, and every record must be well formed.
//!
//! The wire fuzz target (`shared/fuzz`) already feeds the decoder arbitrary bytes; what it
//! cannot reach is a packet that is well framed but wrong in what it says: a Sobel row past
//! the frame's end, a keypoint of an octave the fabric does not have, a FrameEnd whose counts
//! disagree, a frame that starts twice. So the input here is a list of edits to the packets
//! of a real stream (the in-process device's answer to a session's handshake and to two
//! pairs of the renderer's lab scene, each of which it estimates; made once at start-up):
//! each edit sets a byte, truncates, drops or repeats one packet. Edits that remove or shorten
//! packets are legal input (damaged frames come back as gaps); a packet whose length field
//! disagrees with its length, or whose fields are out of range, must be refused with a typed
//! error and never panic. The packets are then framed again, so every edit reaches the host
//! as a packet that decodes as far as its fields allow (the wire crate skips its CRC check
//! under `cfg(fuzzing)`), and the stream is played back in chunks whose size the input also
//! picks. The empty input (no edits) replays the stream as the device sent it. The session
//! salvages every frame it can (loss limit 1), so a dropped or corrupted packet takes the
//! salvage paths into the estimator.
#![no_main]

use std::sync::OnceLock;
use std::time::Duration;

use libfuzzer_sys::fuzz_target;
use stereocal::calib::Calibration;
use stereocal::link::{InProcessLink, LinkProtection, OwnCameras, Recording, ReplayLink};
use stereocal::output::record::FrameStatus;
use stereocal::session::{Session, SessionConfig};
use stereocal_synth::{SceneKind, Sequence, SequenceConfig};
use stereocal_wire::DELIMITER;

const W: u16 = 128;
const H: u16 = 96;
const PAIRS: usize = 2;
/// Bytes per edit: operation, packet (u16 LE: the stream holds 732 packets), offset
/// (u16 LE), value.
const EDIT_LEN: usize = 6;
/// Records read per input. A stream whose frame ids jump ahead gives a dropped record per id
/// skipped (that many frames were lost), so the count is not bounded by the pairs it holds.
const MAX_RECORDS: usize = 64;

/// What the device said during the handshake (kept intact: the host must reach the
/// streaming state), the calibration, and the packets of the pairs after it, unframed.
struct Reference {
    handshake: Vec<u8>,
    calib: Calibration,
    packets: Vec<Vec<u8>>,
    /// The raw verge of each pair as the in-process session measured it: the stream replayed
    /// without edits must give the same, or the harness tests less than it claims.
    raw_verge_deg: Vec<f64>,
}

fn reference() -> &'static Reference {
    static REFERENCE: OnceLock<Reference> = OnceLock::new();
    REFERENCE.get_or_init(|| {
        let config = SequenceConfig {
            width: u32::from(W),
            height: u32::from(H),
            frames: PAIRS,
            ..SequenceConfig::for_scene(SceneKind::Lab)
        };
        let sequence = Sequence::builtin(SceneKind::Lab, config).expect("the lab scene renders");
        let calib = Calibration::from_toml_str(&sequence.calib_toml(), "calib.toml")
            .expect("the renderer writes a valid calibration");
        let device = Recording::new(InProcessLink::new().expect("the in-process device opens"));
        let mut session = Session::with_device(device, calib, W, H, SessionConfig::default())
            .expect("the in-process device takes the handshake");
        let handshake = session.device_mut().take_received();
        let mut raw_verge_deg = Vec::new();
        for frame in 0..PAIRS {
            let images = sequence
                .frame(frame)
                .expect("the frame renders")
                .images
                .expect("no frame is dropped at a drop rate of 0");
            let record = session
                .process(
                    frame,
                    Some((images.left.as_raw(), images.right.as_raw())),
                    (usize::from(W), usize::from(H)),
                    sequence.timestamp_us(frame),
                    None,
                )
                .expect("the in-process device answers every pair");
            // The stream must reach the estimator and the filter, or the edits test less.
            assert_eq!(record.status, FrameStatus::Ok, "{record:?}");
            raw_verge_deg.extend(record.raw_verge_deg);
        }
        let stream = session.device_mut().take_received();
        let packets = stream
            .split(|&b| b == DELIMITER)
            .filter(|frame| !frame.is_empty())
            .map(|frame| cobs::decode_vec(frame).expect("the device frames with COBS"))
            .collect();
        Reference {
            handshake,
            calib,
            packets,
            raw_verge_deg,
        }
    })
}

/// The reference packets with the input's edits applied.
fn edited(packets: &[Vec<u8>], edits: &[u8]) -> Vec<Vec<u8>> {
    let mut packets = packets.to_vec();
    for edit in edits.chunks_exact(EDIT_LEN) {
        if packets.is_empty() {
            break;
        }
        let index = usize::from(u16::from_le_bytes([edit[1], edit[2]])) % packets.len();
        let offset = usize::from(u16::from_le_bytes([edit[3], edit[4]]));
        match edit[0] % 4 {
            0 => {
                let packet = &mut packets[index];
                if !packet.is_empty() {
                    let at = offset % packet.len();
                    packet[at] = edit[5];
                }
            }
            1 => {
                let packet = &mut packets[index];
                packet.truncate(offset % (packet.len() + 1));
            }
            2 => {
                packets.remove(index);
            }
            _ => {
                let copy = packets[index].clone();
                packets.insert(index + 1, copy);
            }
        }
    }
    packets
}

fn check(record: &stereocal::output::record::FrameRecord, frame: usize) {
    assert_eq!(record.frame, frame);
    let measured = [
        record.raw_verge_deg,
        record.filtered_verge_deg,
        record.filtered_sigma_deg,
    ];
    match record.status {
        FrameStatus::Ok | FrameStatus::Salvaged => {
            for value in measured {
                let value = value.expect("an estimated record carries its angles");
                assert!(value.is_finite(), "{record:?}");
            }
            assert!(record.filtered_sigma_deg.unwrap() >= 0.0, "{record:?}");
            assert_eq!(
                record.link_loss.is_some(),
                record.status == FrameStatus::Salvaged,
                "{record:?}"
            );
        }
        FrameStatus::NoEstimate => assert!(measured.iter().all(Option::is_none), "{record:?}"),
        FrameStatus::Dropped => {
            assert!(measured.iter().all(Option::is_none), "{record:?}");
            assert!(record.dropped_because.is_some(), "{record:?}");
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let Some((&chunk, edits)) = data.split_first() else {
        return;
    };
    let reference = reference();
    let mut stream = reference.handshake.clone();
    for packet in edited(&reference.packets, edits) {
        stream.extend(cobs::encode_vec(&packet));
        stream.push(DELIMITER);
    }
    // Chunks of 2 to 256 bytes, or the default 4096 for half of the inputs' first bytes.
    let link = match chunk {
        0..=127 => ReplayLink::new(stream),
        _ => ReplayLink::new(stream).with_chunk(usize::from(chunk - 127) * 2),
    };
    let device = OwnCameras::new(link, Duration::from_millis(1));
    // Every frame that can be salvaged is, so that the salvage paths (lost rows, points and
    // patches, a lost FrameEnd) reach the estimator; the default limit would drop most of the
    // small frames' losses.
    let config = SessionConfig {
        link: LinkProtection {
            loss_limit: 1.0,
            ..LinkProtection::clean()
        },
        ..SessionConfig::default()
    };
    let mut session = Session::with_device(device, reference.calib, W, H, config)
        .expect("the recorded handshake replays");
    let mut raw_verge_deg = Vec::new();
    for frame in 0..MAX_RECORDS {
        match session.receive(frame) {
            Ok(record) => {
                check(&record, frame);
                raw_verge_deg.push(record.raw_verge_deg);
            }
            // The end of the replay closes the link; a pair out of step ends the session.
            Err(_) => break,
        }
    }
    if edits.len() < EDIT_LEN {
        let expected: Vec<_> = reference.raw_verge_deg.iter().copied().map(Some).collect();
        assert_eq!(
            raw_verge_deg, expected,
            "the unedited stream replays differently"
        );
    }
});
