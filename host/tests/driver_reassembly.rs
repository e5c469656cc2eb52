//! Frame reassembly and damage handling of the host driver, on hand-built packet sequences
//! played back through a [`ReplayLink`].

mod driver_fixture;

use std::time::Duration;

use driver_fixture::{frame_packets, pattern, point, FrameSpec, Sobel, Wire};
use stereocal::descriptor::{describe, DescriptorConfig};
use stereocal::driver::{
    ContentError, Damage, Driver, DriverError, FrameOutcome, PairOutcome, ReceivedFrame, Salvage,
};
use stereocal::features::Gradients;
use stereocal::link::{LinkError, ReplayLink};
use stereocal_wire::{Camera, LogRepr, PacketKind, PacketRepr, Source};

const T: Duration = Duration::from_secs(1);

fn driver(wire: &Wire) -> Driver<ReplayLink> {
    Driver::new(ReplayLink::new(wire.bytes.clone()))
}

/// A driver that salvages whatever it can: the small test frames have so few keypoints that
/// any loss is beyond the default limit, which the salvage mechanics are tested apart from.
fn salvaging(wire: &Wire) -> Driver<ReplayLink> {
    let mut d = driver(wire);
    d.set_loss_limit(1.0);
    d
}

fn delivered(outcome: FrameOutcome) -> ReceivedFrame {
    match outcome {
        FrameOutcome::Delivered(f) => *f,
        FrameOutcome::Damaged(d) => {
            panic!("frame {} {:?} damaged: {}", d.frame_id, d.camera, d.damage)
        }
    }
}

fn damage(outcome: FrameOutcome) -> Damage {
    match outcome {
        FrameOutcome::Damaged(d) => d.damage,
        FrameOutcome::Delivered(f) => panic!("frame {} {:?} delivered", f.frame_id, f.camera),
    }
}

/// After the last packet the replay link closes: the driver must say so, not hang.
fn assert_exhausted(d: &mut Driver<ReplayLink>) {
    assert!(matches!(
        d.next_frame(T),
        Err(DriverError::Link(LinkError::Closed { .. }))
    ));
}

#[test]
fn rows_frame_is_reassembled_with_full_resolution_keypoints() {
    let mut wire = Wire::new();
    let spec = FrameSpec::small(7, Camera::Left);
    let range = wire.frame(&spec);
    let mut d = driver(&wire);
    let f = delivered(d.next_frame(T).unwrap());
    assert_eq!((f.frame_id, f.camera, f.octaves), (7, Camera::Left, 2));
    assert_eq!(f.wire_bytes, range.len() as u64);
    assert_eq!(f.packets as usize, frame_packets(&spec).len());
    let k = f.features.keypoints();
    assert_eq!(k.len(), 2);
    // Octave 0: (5 + 0.5, 6 - 0.25). Octave 1: ((3 - 0.5) * 2, (4 + 0.25) * 2).
    assert_eq!((k[0].x, k[0].y, k[0].octave), (5.5, 5.75, 0));
    assert_eq!((k[1].x, k[1].y, k[1].octave), (5.0, 8.5, 1));
    assert_eq!(k[0].dog, 2.0);
    assert_eq!((f.features.width, f.features.height), (32, 16));
    assert_eq!(f.features.timestamp_us, 7000);
    for octave in 0..2u8 {
        let plane = f.features.plane(octave).expect("plane of every octave");
        let (w, h) = (32 >> octave, 16 >> octave);
        assert_eq!((plane.width(), plane.height()), (w, h));
        for y in 0..h as i32 {
            for x in 0..w as i32 {
                let px = pattern(octave, x, y);
                assert_eq!(plane.get(x, y), Some((px.magnitude, px.orientation)));
            }
        }
    }
    assert_eq!(d.stats().frames_delivered, 1);
    assert_eq!(d.stats().delivered_wire_bytes, range.len() as u64);
    assert_eq!(d.stats().bytes_received, wire.bytes.len() as u64);
    assert_exhausted(&mut d);
}

#[test]
fn any_chunking_of_the_link_gives_the_same_frames() {
    let mut wire = Wire::new();
    wire.frame(&FrameSpec::small(1, Camera::Left));
    wire.log(&[1, 0, 42, 0]);
    wire.frame(&FrameSpec::small(1, Camera::Right));
    let reference: Vec<FrameOutcome> = {
        let mut d = driver(&wire);
        vec![d.next_frame(T).unwrap(), d.next_frame(T).unwrap()]
    };
    for chunk in [1, 2, 3, 7, 64, 1000] {
        let mut d = Driver::new(ReplayLink::new(wire.bytes.clone()).with_chunk(chunk));
        let got = vec![d.next_frame(T).unwrap(), d.next_frame(T).unwrap()];
        assert_eq!(got, reference, "chunk {chunk}");
        assert_eq!(d.stats().frames_delivered, 2);
    }
}

#[test]
fn patches_are_matched_to_points_and_points_without_patch_are_dropped() {
    let mut wire = Wire::new();
    let mut spec = FrameSpec::small(3, Camera::Right);
    spec.points.push(point(2, 2, 0, 0, 0));
    // Patch of point 0 near nothing, point 2 at the image corner (zeros outside), none
    // for point 1.
    spec.sobel = Sobel::Patches(vec![2, 0]);
    wire.frame(&spec);
    let mut d = driver(&wire);
    let f = delivered(d.next_frame(T).unwrap());
    assert_eq!(f.points_without_patch, 1);
    let k = f.features.keypoints();
    assert_eq!(k.len(), 2);
    assert_eq!((k[0].x, k[0].y), (5.5, 5.75));
    assert_eq!((k[1].x, k[1].y), (2.0, 2.0));
    let Gradients::Patches(patches) = f.features.gradients() else {
        panic!("patches expected");
    };
    assert_eq!(patches.len(), 2);
    // Window offset (dx, dy) of keypoint 1 is octave pixel (2 + dx, 2 + dy).
    let px = pattern(0, 3, 1);
    assert_eq!(
        f.features.window_sample(1, 1, -1),
        Some((px.magnitude, px.orientation))
    );
    assert_eq!(f.features.window_sample(1, -3, 0), Some((0, 0)));
    let px = pattern(0, 5, 6);
    assert_eq!(
        f.features.window_sample(0, 0, 0),
        Some((px.magnitude, px.orientation))
    );
}

/// Packet index of octave 0's row `y` in [`frame_packets`] of a rows-mode frame.
fn row_packet(y: usize) -> usize {
    1 + y
}

#[test]
fn a_lost_sobel_row_costs_only_the_windows_touching_it() {
    let mut wire = Wire::new();
    wire.frame_losing(&FrameSpec::small(1, Camera::Left), &[row_packet(1)]);
    wire.frame(&FrameSpec::small(1, Camera::Right));
    let mut d = salvaging(&wire);
    let first = delivered(d.next_frame(T).unwrap());
    assert_eq!(
        first.salvage,
        Some(Salvage {
            packets_lost: 1,
            rows_lost: vec![1, 0],
            points_lost: Some(0),
            patches_lost: Some(0),
            keypoints_lost: 2,
        })
    );
    let plane = first.features.plane(0).expect("octave 0 plane");
    assert!(!plane.valid(0, 1) && plane.valid(0, 0) && plane.valid(0, 2));
    assert_eq!(plane.get(3, 1), None);
    let px = pattern(0, 3, 2);
    assert_eq!(plane.get(3, 2), Some((px.magnitude, px.orientation)));
    // Keypoint 0 sits on octave 0 row 6: its 16x16 window covers rows -2..14, row 1 with
    // them. Keypoint 1's window lies in octave 1, which lost nothing, so its descriptor
    // stays; but its match is refined on octave 0 around its full-resolution row 9, within
    // the refinement's 11 px reach of row 1, so it counts as lost too. Without refinement
    // only keypoint 0 is.
    let mut window = [(0, 0); 256];
    assert_eq!(first.features.window(0, &mut window), 0);
    assert!(first.features.window(1, &mut window) > 0);
    assert_eq!(first.features.keypoints()[1].y.round(), 9.0);
    assert_eq!(first.features.keypoints_on_lost_pixels(None), 1);
    let mut unrefined = salvaging(&wire);
    unrefined.set_refinement_reach(None);
    let salvage = delivered(unrefined.next_frame(T).unwrap()).salvage;
    assert_eq!(salvage.map(|s| s.keypoints_lost), Some(1));
    let set = describe(&first.features, &DescriptorConfig::default());
    assert!((0..set.len()).all(|i| set.keypoint(i) != 0));
    let second = delivered(d.next_frame(T).unwrap());
    assert_eq!((second.camera, second.salvage), (Camera::Right, None));
    let s = d.stats();
    assert_eq!(
        (s.frames_delivered, s.frames_salvaged, s.frames_damaged),
        (2, 1, 0)
    );
    assert_eq!((s.sequence_gaps, s.packets_lost), (1, 1));
}

#[test]
fn a_lost_row_segment_costs_only_its_pixels() {
    let mut spec = FrameSpec::small(1, Camera::Left);
    spec.sobel = Sobel::Segments(8);
    // Whole, the segmented frame gives the planes of the unsegmented one.
    let mut wire = Wire::new();
    wire.frame(&spec);
    wire.frame(&FrameSpec::small(1, Camera::Left));
    let mut d = driver(&wire);
    let segmented = delivered(d.next_frame(T).unwrap());
    let whole = delivered(d.next_frame(T).unwrap());
    assert_eq!(segmented.salvage, None);
    assert_eq!(segmented.features.gradients(), whole.features.gradients());
    // Row 1's last segment (columns 24..32) of octave 0 lost: keypoint 0's window (columns
    // -2..14) does not reach it.
    let mut wire = Wire::new();
    wire.frame_losing(&spec, &[1 + 4 + 3]);
    let f = delivered(salvaging(&wire).next_frame(T).unwrap());
    let salvage = f.salvage.expect("salvaged");
    assert_eq!((salvage.rows_lost, salvage.keypoints_lost), (vec![1, 0], 0));
    let plane = f.features.plane(0).expect("octave 0");
    assert!(plane.valid(23, 1) && !plane.valid(24, 1) && !plane.valid(31, 1));
    assert_eq!(plane.lost_pixels(), 8);
    let mut window = [(0, 0); 256];
    assert!(f.features.window(0, &mut window) > 0);
}

#[test]
fn a_frame_that_lost_more_than_the_limit_is_dropped() {
    let mut wire = Wire::new();
    // One of octave 0's 16 rows: 6 % of its pixels, keypoint 0's window touches it and
    // keypoint 1's refinement reach holds it: both of the frame's keypoints.
    for _ in 0..2 {
        wire.frame_losing(&FrameSpec::small(1, Camera::Left), &[row_packet(1)]);
    }
    let mut d = driver(&wire);
    assert_eq!(
        damage(d.next_frame(T).unwrap()),
        Damage::PlaneLost {
            octave: 0,
            lost: 32,
            of: 512
        }
    );
    d.set_loss_limit(0.1);
    assert_eq!(
        damage(d.next_frame(T).unwrap()),
        Damage::Lost { lost: 2, of: 2 }
    );
    assert_eq!(d.stats().damage.lost, 2);
}

/// 600 points with distinct placements: octave 0's 512 pixels, then octave 1's first 88.
fn many_points(frame_id: u32) -> FrameSpec {
    let mut spec = FrameSpec::small(frame_id, Camera::Left);
    spec.points = (0..600u16)
        .map(|i| match i {
            0..512 => point(i % 32, i / 32, 0, 0, 0),
            _ => point((i - 512) % 16, (i - 512) / 16, 1, 0, 0),
        })
        .collect();
    spec
}

/// `spec` sent with the second of its five 128-point batches lost, as the salvaging driver
/// delivers it.
fn losing_the_second_point_batch(spec: FrameSpec) -> ReceivedFrame {
    let mut wire = Wire::new();
    let batch = frame_packets(&spec).len() - 5;
    wire.frame_losing(&spec, &[batch]);
    delivered(salvaging(&wire).next_frame(T).unwrap())
}

#[test]
fn a_lost_point_batch_costs_its_points_in_rows_mode() {
    let f = losing_the_second_point_batch(many_points(5));
    let salvage = f.salvage.expect("salvaged");
    assert_eq!(
        (salvage.points_lost, salvage.rows_lost_total()),
        (Some(128), 0)
    );
    assert_eq!(f.features.keypoints().len(), 472);
}

#[test]
fn patches_after_a_lost_point_batch_find_their_points_by_placement() {
    let mut spec = many_points(6);
    spec.sobel = Sobel::Patches((0..600).collect());
    let f = losing_the_second_point_batch(spec);
    let salvage = f.salvage.expect("salvaged");
    assert_eq!(
        (salvage.points_lost, salvage.patches_lost),
        (Some(128), Some(0))
    );
    assert_eq!(
        (f.features.keypoints().len(), f.points_without_patch),
        (472, 0)
    );
    // Received keypoint 128 is device point 256 at octave 0 (0, 8); each window is its own.
    for k in [0, 127, 128, 471] {
        let kp = f.features.keypoints()[k];
        let (x, y) = kp.octave_position();
        let px = pattern(kp.octave, x as i32, y as i32 + 1);
        assert_eq!(
            f.features.window_sample(k, 0, 1),
            Some((px.magnitude, px.orientation)),
            "keypoint {k}"
        );
    }
}

#[test]
fn repeated_and_overtaken_packets_are_dropped() {
    let mut wire = Wire::new();
    wire.frame(&FrameSpec::small(2, Camera::Left));
    let p = wire.packets.clone();
    let mut bytes = Vec::new();
    for (i, range) in p.iter().enumerate() {
        match i {
            // Row 2 comes twice; row 5 is overtaken by row 6.
            3 => bytes.extend_from_slice(&wire.bytes[range.clone()].repeat(2)),
            6 => {
                bytes.extend_from_slice(&wire.bytes[range.clone()]);
                bytes.extend_from_slice(&wire.bytes[p[5].clone()]);
            }
            5 => {}
            _ => bytes.extend_from_slice(&wire.bytes[range.clone()]),
        }
    }
    let mut d = Driver::new(ReplayLink::new(bytes));
    d.set_loss_limit(1.0);
    let f = delivered(d.next_frame(T).unwrap());
    let salvage = f.salvage.expect("the overtaken row counts as lost");
    assert_eq!((salvage.packets_lost, salvage.rows_lost), (1, vec![1, 0]));
    assert!(!f.features.plane(0).is_some_and(|p| p.valid(0, 4)));
    assert_eq!(d.stats().late_packets, 2);
}

#[test]
fn lost_frame_start_is_reported_as_missing_start() {
    let mut wire = Wire::new();
    wire.frame_losing(&FrameSpec::small(4, Camera::Left), &[0]);
    wire.frame(&FrameSpec::small(4, Camera::Right));
    let mut d = driver(&wire);
    let first = d.next_frame(T).unwrap();
    assert_eq!(first.frame_id(), 4);
    assert!(matches!(damage(first), Damage::MissingStart { first } if first.seq == 1));
    delivered(d.next_frame(T).unwrap());
}

#[test]
fn garbage_between_frames_is_skipped() {
    let mut wire = Wire::new();
    wire.frame(&FrameSpec::small(1, Camera::Left));
    // Line noise with delimiters in it, and an over-long run without one.
    wire.raw(&[0x13, 0x00, 0xff, 0x42, 0x07, 0x00, 0x00, 0x55]);
    wire.raw(&vec![0x5a; 5000]);
    wire.raw(&[0x00]);
    wire.frame(&FrameSpec::small(1, Camera::Right));
    let mut d = driver(&wire);
    match d.next_pair(T).unwrap() {
        PairOutcome::Pair { left, right } => {
            delivered(left);
            delivered(right);
        }
        other => panic!("pair expected, got {other:?}"),
    }
    let s = d.stats();
    assert!(s.undecodable >= 2, "{s:?}");
    assert_eq!(s.over_long, 1);
    assert_eq!(s.frames_damaged, 0);
}

#[test]
fn corruption_inside_a_frame_costs_the_packet_it_hit() {
    let mut wire = Wire::new();
    let range = wire.frame(&FrameSpec::small(1, Camera::Left));
    wire.frame(&FrameSpec::small(1, Camera::Right));
    let mut bytes = wire.bytes.clone();
    // Flip a byte in the middle of the left frame (in some Sobel row's pixels).
    let at = range.start + range.len() / 2;
    bytes[at] = if bytes[at] == 0x01 { 0x02 } else { 0x01 };
    let mut d = Driver::new(ReplayLink::new(bytes));
    d.set_loss_limit(1.0);
    let first = delivered(d.next_frame(T).unwrap());
    assert_eq!(first.salvage.map(|s| s.packets_lost), Some(1));
    assert_eq!(delivered(d.next_frame(T).unwrap()).salvage, None);
    let s = d.stats();
    assert_eq!(
        (s.undecodable, s.frames_salvaged, s.frames_damaged),
        (1, 1, 0)
    );
}

#[test]
fn a_frame_without_its_end_closes_at_the_next_start_with_unknown_totals() {
    let mut wire = Wire::new();
    let spec = FrameSpec::small(2, Camera::Left);
    let packets = frame_packets(&spec);
    // The device stops mid-frame (no FrameEnd) but numbers on without a gap.
    for p in &packets[..packets.len() - 1] {
        wire.push(&p.repr());
    }
    let next_seq = wire.next_seq(Source::Left);
    wire.frame(&FrameSpec::small(3, Camera::Left));
    let mut d = driver(&wire);
    let first = delivered(d.next_frame(T).unwrap());
    let salvage = first.salvage.expect("salvaged");
    assert!(salvage.end_lost());
    assert_eq!((salvage.packets_lost, salvage.rows_lost_total()), (0, 0));
    assert_eq!(first.features.keypoints().len(), 2);
    assert_eq!(
        wire.next_seq(Source::Left),
        next_seq + frame_packets(&spec).len() as u16
    );
    assert_eq!(delivered(d.next_frame(T).unwrap()).frame_id, 3);
}

#[test]
fn bytes_cut_off_mid_packet_damage_the_frame() {
    let mut wire = Wire::new();
    let range = wire.frame(&FrameSpec::small(2, Camera::Left));
    let mut bytes = wire.bytes[..range.end - 10].to_vec();
    let mut next = Wire::new();
    next.frame(&FrameSpec::small(3, Camera::Left));
    bytes.extend_from_slice(&next.bytes);
    let mut d = Driver::new(ReplayLink::new(bytes));
    // The cut FrameEnd merges with the next FrameStart into one undecodable link frame: the
    // first frame is salvaged without its end when the next frame's packets show up.
    let first = delivered(d.next_frame(T).unwrap());
    assert!(first.salvage.is_some_and(|s| s.end_lost()));
    // The next frame's numbering restarted at 0 (another device run); it is then missing
    // its start and is dropped, without the driver getting stuck.
    let second = d.next_frame(T).unwrap();
    assert_eq!(second.frame_id(), 3);
    assert_exhausted(&mut d);
}

#[test]
fn log_packets_inside_a_frame_are_surfaced_not_damage() {
    let mut wire = Wire::new();
    let spec = FrameSpec::small(5, Camera::Left);
    let packets = frame_packets(&spec);
    let mut frame_bytes = 0;
    for (i, p) in packets.iter().enumerate() {
        frame_bytes += wire.push(&p.repr()).len();
        if i == 1 {
            wire.log(&[0x01, 0x00, 0x2a, 0x00]);
        }
    }
    let mut d = driver(&wire);
    let f = delivered(d.next_frame(T).unwrap());
    assert_eq!(
        f.wire_bytes, frame_bytes as u64,
        "log bytes are not the frame's"
    );
    let logs = d.take_logs();
    assert_eq!(logs.len(), 1);
    // The first packet of the device's control source, whatever the channel sent before.
    assert_eq!(
        (logs[0].seq, &logs[0].bytes[..]),
        (0, &[0x01, 0x00, 0x2a, 0x00][..])
    );
    assert!(d.take_logs().is_empty());
    assert_eq!(d.stats().log_frames, 1);
}

#[test]
fn counts_that_disagree_with_frame_end_damage_the_frame() {
    let mut wire = Wire::new();
    let spec = FrameSpec::small(6, Camera::Left);
    let mut packets = frame_packets(&spec);
    if let Some(driver_fixture::Owned::End(end)) = packets.last_mut() {
        end.point_count = 3;
    }
    for p in &packets {
        wire.push(&p.repr());
    }
    let mut d = driver(&wire);
    assert!(matches!(
        damage(d.next_frame(T).unwrap()),
        Damage::CountMismatch {
            points_announced: 3,
            points_received: 2,
            ..
        }
    ));
}

#[test]
fn points_outside_their_octave_are_named() {
    let mut wire = Wire::new();
    let mut spec = FrameSpec::small(8, Camera::Left);
    spec.points.push(point(16, 2, 1, 0, 0)); // octave 1 is 16 wide
    wire.frame(&spec);
    let mut d = driver(&wire);
    match damage(d.next_frame(T).unwrap()) {
        Damage::Content { packet, problem } => {
            assert_eq!((packet.kind, packet.frame_id), (PacketKind::PointBatch, 8));
            assert_eq!(
                problem,
                ContentError::PointOutside {
                    index: 2,
                    octave: 1,
                    x: 16,
                    y: 2,
                    width: 16,
                    height: 8
                }
            );
        }
        other => panic!("content error expected, got {other}"),
    }
}

#[test]
fn a_packet_of_another_frame_damages_both() {
    let mut wire = Wire::new();
    let left = frame_packets(&FrameSpec::small(9, Camera::Left));
    let right = frame_packets(&FrameSpec::small(9, Camera::Right));
    // Left's start and a row, then right's body without its start, then a whole frame.
    wire.push(&left[0].repr());
    wire.push(&left[1].repr());
    for p in &right[1..] {
        wire.push(&p.repr());
    }
    wire.frame(&FrameSpec::small(10, Camera::Left));
    let mut d = driver(&wire);
    // Left kept one of octave 0's rows and no point: too little to salvage.
    assert!(matches!(
        damage(d.next_frame(T).unwrap()),
        Damage::Lost { .. } | Damage::PlaneLost { .. }
    ));
    let second = d.next_frame(T).unwrap();
    assert_eq!((second.frame_id(), second.camera()), (9, Camera::Right));
    assert!(matches!(
        damage(second),
        Damage::Foreign { .. } | Damage::MissingStart { .. }
    ));
    assert_eq!(delivered(d.next_frame(T).unwrap()).frame_id, 10);
    assert_eq!(d.stats().frames_damaged, 2);
}

#[test]
fn pairs_keep_a_damaged_partner_and_split_lone_frames() {
    let mut wire = Wire::new();
    wire.frame(&FrameSpec::small(1, Camera::Left));
    let lose: Vec<usize> = (1..=8).map(row_packet).collect();
    wire.frame_losing(&FrameSpec::small(1, Camera::Right), &lose);
    // Frame 2's right camera is lost without trace.
    wire.frame(&FrameSpec::small(2, Camera::Left));
    wire.frame(&FrameSpec::small(3, Camera::Right));
    wire.frame(&FrameSpec::small(3, Camera::Left));
    let mut d = driver(&wire);
    match d.next_pair(T).unwrap() {
        PairOutcome::Pair { left, right } => {
            assert_eq!(left.frame_id(), 1);
            delivered(left);
            damage(right);
        }
        other => panic!("pair expected, got {other:?}"),
    }
    let lone = d.next_pair(T).unwrap();
    assert!(matches!(&lone, PairOutcome::Single(f) if f.frame_id() == 2));
    let pair = d.next_pair(T).unwrap();
    assert_eq!(pair.frame_id(), 3);
    let bytes = pair.wire_bytes();
    let (l, r) = pair.delivered().expect("both delivered");
    assert_eq!((l.camera, r.camera), (Camera::Left, Camera::Right));
    assert_eq!(bytes, l.wire_bytes + r.wire_bytes);
}

/// Each source is numbered on its own: a lost control packet is a gap in control's
/// numbering, which leaves the open camera frame whole; the right channel's numbering does not
/// continue the left one's.
#[test]
fn a_gap_in_another_source_leaves_the_frame_whole() {
    let mut wire = Wire::new();
    let packets = frame_packets(&FrameSpec::small(12, Camera::Left));
    for (i, p) in packets.iter().enumerate() {
        wire.push(&p.repr());
        if i == 1 {
            wire.log(&[1, 2]);
            wire.lose(&PacketRepr::Log(LogRepr { frame: &[3, 4] }));
            wire.log(&[5, 6]);
        }
    }
    wire.frame(&FrameSpec::small(12, Camera::Right));
    assert_eq!(wire.next_seq(Source::Right), wire.next_seq(Source::Left));
    let mut d = driver(&wire);
    assert_eq!(delivered(d.next_frame(T).unwrap()).camera, Camera::Left);
    assert_eq!(delivered(d.next_frame(T).unwrap()).camera, Camera::Right);
    let s = d.stats();
    assert_eq!(
        (s.sequence_gaps, s.packets_lost, s.frames_damaged),
        (1, 1, 0)
    );
}

#[test]
fn packets_of_an_unknown_kind_are_counted_not_damage() {
    let mut wire = Wire::new();
    let packets = frame_packets(&FrameSpec::small(11, Camera::Left));
    for (i, p) in packets.iter().enumerate() {
        wire.push(&p.repr());
        if i == 2 {
            // A newer channel's kind: the header says it took the channel's next number.
            wire.unknown_kind(Source::Left, 0x30, &[1, 0, 2, 3]);
        }
    }
    let mut d = driver(&wire);
    let f = delivered(d.next_frame(T).unwrap());
    assert_eq!(f.frame_id, 11);
    let s = d.stats();
    assert_eq!((s.unknown_kinds, s.undecodable, s.sequence_gaps), (1, 0, 0));
}

#[test]
fn error_reports_outside_a_request_are_kept_bounded_to_the_newest() {
    use stereocal_wire::{ErrorCode, ErrorReportRepr, PacketRepr};
    let mut wire = Wire::new();
    for detail in 0..100 {
        wire.push(&PacketRepr::ErrorReport(ErrorReportRepr {
            code: ErrorCode::Busy,
            detail,
        }));
    }
    wire.frame(&FrameSpec::small(1, Camera::Left));
    let mut d = driver(&wire);
    delivered(d.next_frame(T).unwrap());
    let reports = d.take_device_errors();
    // A bounded list: the newest 64 of the 100 the device sent.
    assert_eq!(reports.len(), 64);
    assert_eq!(reports[0].report.detail, 36);
    assert_eq!(reports[63].report.detail, 99);
    assert_eq!(reports[63].seq, 99);
    assert!(d.take_device_errors().is_empty());
}

#[test]
fn a_register_read_gets_its_error_report_while_unclaimed_reports_fill_the_list() {
    use stereocal_wire::{ErrorCode, ErrorReportRepr, PacketRepr};
    let report = |code, detail| PacketRepr::ErrorReport(ErrorReportRepr { code, detail });
    let mut wire = Wire::new();
    for detail in 0..64 {
        wire.push(&report(ErrorCode::Busy, detail));
    }
    wire.frame(&FrameSpec::small(1, Camera::Left));
    // The answer to the read below: the list of unclaimed reports is full when it arrives.
    wire.push(&report(ErrorCode::UnknownRegister, 0xFC));
    let mut d = driver(&wire);
    delivered(d.next_frame(T).unwrap());
    match d.read_register(0x00FC, T) {
        Err(DriverError::Device { code, detail, .. }) => {
            assert_eq!((code, detail), (ErrorCode::UnknownRegister, 0xFC));
        }
        other => panic!("the read's error report expected, got {other:?}"),
    }
    // The unclaimed reports stay, less the oldest, which the read's own pushed out of the full
    // list before the read took it.
    let reports = d.take_device_errors();
    let details: Vec<u32> = reports.iter().map(|r| r.report.detail).collect();
    assert_eq!(details, (1..64).collect::<Vec<u32>>());
    assert!(reports.iter().all(|r| r.report.code == ErrorCode::Busy));
}

#[test]
fn encoder_readings_wait_for_their_capture_and_older_ones_go() {
    use stereocal_wire::{EncodersRepr, PacketRepr};
    let reading = |frame_id, left_yaw_udeg| {
        PacketRepr::Encoders(EncodersRepr {
            frame_id,
            left_yaw_udeg,
            right_yaw_udeg: -500_000,
        })
    };
    let mut wire = Wire::new();
    // A head stamps each capture's reading before its frames; the host may take them late.
    for id in 1..=3u32 {
        wire.push(&reading(id, 1_000_000 * id as i32));
        wire.frame(&FrameSpec::small(id, Camera::Left));
    }
    let mut d = driver(&wire);
    for _ in 0..3 {
        delivered(d.next_frame(T).unwrap());
    }
    assert_eq!(d.take_encoders(2).map(|e| e.left_yaw_udeg), Some(2_000_000));
    // Capture 1's reading went with 2's (no pair asks for an older capture again).
    assert_eq!(d.take_encoders(1), None);
    assert_eq!(d.take_encoders(4), None);
    // Nor does a reading outlive a later capture's request.
    assert_eq!(d.take_encoders(3), None);
    assert_eq!(d.stats().stray_packets, 0);
}

#[test]
fn unclaimed_encoder_readings_are_kept_bounded_to_the_newest() {
    use stereocal_wire::{EncodersRepr, PacketRepr};
    let mut wire = Wire::new();
    for id in 0..100u32 {
        wire.push(&PacketRepr::Encoders(EncodersRepr {
            frame_id: id,
            left_yaw_udeg: id as i32,
            right_yaw_udeg: 0,
        }));
    }
    wire.frame(&FrameSpec::small(100, Camera::Left));
    let mut d = driver(&wire);
    delivered(d.next_frame(T).unwrap());
    // The newest 64 of the 100: 36 and later.
    assert_eq!(d.take_encoders(35), None);
    assert_eq!(d.take_encoders(36).map(|e| e.left_yaw_udeg), Some(36));
    assert_eq!(d.take_encoders(99).map(|e| e.left_yaw_udeg), Some(99));
}
