//! Decoded packets in, camera frames out: the receiving state machine of the driver.
//!
//! Link-independent and synchronous, so every damage case is tested with hand-built packet
//! sequences. One frame is assembled at a time (the device sends a camera frame's packets
//! contiguously, control packets aside). Each wire source numbers its packets on its own, so
//! the sequence numbers are checked per source, and a gap in the frame's channel says how
//! many of its packets the link lost; an undecodable link frame needs no rule of its own,
//! since the packet it was shows as a gap in its source.
//!
//! A frame that lost packets is *salvaged* (`salvage.rs`): delivered with what arrived, the
//! losses counted, when its `FrameStart` arrived (only it carries the timestamp) and it lost
//! no more than the loss limit. Its end is its `FrameEnd`, or, when that was lost, the next
//! `FrameStart` or a packet of another frame (then its totals are unknown). A frame is
//! *damaged* when it cannot be salvaged: no `FrameStart`, more lost than the limit, contents
//! that contradict themselves, or a device restart in its middle; a damaged frame is consumed
//! up to its end, reported once and dropped. The next `FrameStart` always starts afresh,
//! which is the resynchronisation. A frame packet whose number lies just behind its source's
//! last (a repeat, or one overtaken by a later packet) is dropped: its place was already
//! counted as lost or filled.

use std::collections::{HashMap, VecDeque};

use stereocal_hdl::regs;
use stereocal_wire::{
    Camera, EncodersRepr, ErrorReportRepr, FrameEndFlags, FrameEndRepr, FrameStartRepr, Header,
    HelloRepr, PacketKind, PacketRepr, Point, RegisterValueRepr, Source,
};

use super::damage::{ContentError, Damage, PacketRef};
use super::gradients::{Completeness, FinishError, GradientBuilder};
use super::keypoint::keypoint;
use super::salvage::{within_limit, Salvage, MAX_LOST_FRACTION};
use super::stats::LinkStats;
use crate::features::{FeatureFrame, Gradients, Keypoint};
use stereocal_wire::octave_dims;

/// A camera frame that arrived complete and consistent.
#[derive(Debug, Clone, PartialEq)]
pub struct ReceivedFrame {
    /// Frame number from the device.
    pub frame_id: u32,
    /// Which camera.
    pub camera: Camera,
    /// Keypoints (full-resolution pixels) and gradients.
    pub features: FeatureFrame,
    /// Octaves the device computed.
    pub octaves: u8,
    /// Link bytes of the frame's packets, `FrameStart` through `FrameEnd` (COBS and
    /// delimiters included, interleaved log packets excluded).
    pub wire_bytes: u64,
    /// Packets of the frame.
    pub packets: u32,
    /// Points the fabric's FIFO could not hold (from `FrameEnd`).
    pub dropped_points: u32,
    /// Sobel records the fabric or the soft-core could not hold (from `FrameEnd`).
    pub dropped_sobel: u32,
    /// FIFO overflow flags (from `FrameEnd`).
    pub flags: FrameEndFlags,
    /// Points left out of `features` because their patch never came (patches mode).
    pub points_without_patch: u32,
    /// What the link lost of the frame, `None` when it arrived whole.
    pub salvage: Option<Salvage>,
}

/// A camera frame that was dropped.
#[derive(Debug, Clone, PartialEq)]
pub struct DamagedFrame {
    /// Frame number.
    pub frame_id: u32,
    /// Which camera.
    pub camera: Camera,
    /// The first problem found.
    pub damage: Damage,
    /// Link bytes of the packets that arrived for it.
    pub wire_bytes: u64,
}

/// What became of one camera frame.
#[derive(Debug, Clone, PartialEq)]
pub enum FrameOutcome {
    /// Assembled.
    Delivered(Box<ReceivedFrame>),
    /// Dropped, with the reason.
    Damaged(DamagedFrame),
}

impl FrameOutcome {
    /// Frame number.
    pub fn frame_id(&self) -> u32 {
        match self {
            Self::Delivered(f) => f.frame_id,
            Self::Damaged(f) => f.frame_id,
        }
    }

    /// Camera.
    pub fn camera(&self) -> Camera {
        match self {
            Self::Delivered(f) => f.camera,
            Self::Damaged(f) => f.camera,
        }
    }

    /// Link bytes of the frame.
    pub fn wire_bytes(&self) -> u64 {
        match self {
            Self::Delivered(f) => f.wire_bytes,
            Self::Damaged(f) => f.wire_bytes,
        }
    }

    /// The frame, if it was delivered.
    pub fn delivered(self) -> Option<ReceivedFrame> {
        match self {
            Self::Delivered(f) => Some(*f),
            Self::Damaged(_) => None,
        }
    }
}

/// One defmt log frame from the device, undecoded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LogFrame {
    /// Sequence number of its packet.
    pub seq: u16,
    /// The defmt frame bytes (decode with the firmware ELF's defmt table).
    pub bytes: Vec<u8>,
}

/// What one packet amounted to.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Event {
    Frame(FrameOutcome),
    Hello(HelloRepr),
    RegisterValue(RegisterValueRepr),
    Log(LogFrame),
    DeviceError { seq: u16, report: ErrorReportRepr },
    Encoders(EncodersRepr),
}

/// The frame being assembled.
#[derive(Debug)]
struct Partial {
    frame_id: u32,
    camera: Camera,
    /// `None` when the `FrameStart` was lost (the frame is damaged then).
    start: Option<FrameStartRepr>,
    damage: Option<Damage>,
    wire_bytes: u64,
    packets: u32,
    /// Packets of the frame's channel its sequence numbers show lost while the frame was open.
    lost_packets: u32,
    points: Vec<Point>,
    keypoints: Vec<Keypoint>,
    sobel_packets: u32,
    gradients: GradientBuilder,
}

impl Partial {
    fn new(frame_id: u32, camera: Camera, start: Option<FrameStartRepr>) -> Self {
        Self {
            frame_id,
            camera,
            start,
            damage: None,
            wire_bytes: 0,
            packets: 0,
            lost_packets: 0,
            points: Vec::new(),
            keypoints: Vec::new(),
            sobel_packets: 0,
            gradients: GradientBuilder::Empty,
        }
    }

    fn damage(&mut self, damage: Damage) {
        self.damage.get_or_insert(damage);
    }
}

/// How far behind its source's last number a frame packet counts as a repeat or a late
/// packet rather than a jump: more than a link reorders, and little enough that a device
/// that restarted without its `Hello` reaching the host (numbering from 0 again) is taken
/// as a jump after at most this many packets.
const LATE_WINDOW: u16 = 8;

/// What a packet's sequence number says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Numbering {
    /// The next of its source, the first of it, or after a gap.
    Fresh,
    /// At or just behind its source's last number: a repeat or a late packet.
    Late,
}

/// The receiving state machine.
#[derive(Debug, Default)]
pub(crate) struct FrameAssembler {
    /// The last sequence number of each source seen since the device's `Hello`.
    last_seq: HashMap<Source, u16>,
    /// The sequence number of the last packet that decoded, of any source (for reports).
    last_decoded: Option<u16>,
    partial: Option<Partial>,
    events: VecDeque<Event>,
    pub stats: LinkStats,
    /// The salvage limit when not [`MAX_LOST_FRACTION`](super::salvage::MAX_LOST_FRACTION).
    pub loss_limit: Option<f64>,
    /// The estimator's sub-pixel refinement reach
    /// ([`SubpixelConfig::reach_px`](crate::subpixel::SubpixelConfig::reach_px)), which
    /// counts a keypoint with a lost pixel within it as lost; `None` when the estimator does
    /// not refine.
    pub refinement_reach: Option<usize>,
}

/// The frame id and camera a frame-body packet carries.
fn body_ids(packet: &PacketRepr<'_>) -> Option<(u32, Camera)> {
    match packet {
        PacketRepr::PointBatch(p) => Some((p.frame_id, p.camera)),
        PacketRepr::SobelRows(p) => Some((p.frame_id, p.camera)),
        PacketRepr::SobelPatch(p) => Some((p.frame_id, p.camera)),
        PacketRepr::FrameEnd(p) => Some((p.frame_id, p.camera)),
        _ => None,
    }
}

/// Why a `FrameStart` describes a frame the fabric cannot produce (and the host will not
/// allocate planes for).
fn geometry_problem(start: &FrameStartRepr) -> Option<ContentError> {
    let fits = start.octaves >= 1
        && u32::from(start.octaves) <= regs::MAX_OCTAVES
        && start.width >= 1
        && u32::from(start.width) <= regs::MAX_WIDTH
        && start.height >= 1
        && u32::from(start.height) <= regs::MAX_HEIGHT;
    (!fits).then_some(ContentError::BadGeometry {
        width: start.width,
        height: start.height,
        octaves: start.octaves,
    })
}

/// Adds a points or Sobel packet to an undamaged frame.
fn add_body(p: &mut Partial, packet: &PacketRepr<'_>) -> Result<(), ContentError> {
    // Only undamaged frames get here, and those have their FrameStart.
    let Some(start) = p.start else {
        return Ok(());
    };
    match packet {
        PacketRepr::PointBatch(batch) => {
            for (index, point) in batch.points.iter().enumerate() {
                if point.octave >= start.octaves {
                    return Err(ContentError::Octave {
                        octave: point.octave,
                        octaves: start.octaves,
                    });
                }
                let (w, h) = octave_dims(start.width, start.height, point.octave);
                if point.x >= w || point.y >= h {
                    return Err(ContentError::PointOutside {
                        index,
                        octave: point.octave,
                        x: point.x,
                        y: point.y,
                        width: w,
                        height: h,
                    });
                }
                p.points.push(point);
                p.keypoints.push(keypoint(&point));
            }
            Ok(())
        }
        PacketRepr::SobelRows(row) => {
            p.sobel_packets += 1;
            p.gradients
                .add_row(row, start.width, start.height, start.octaves)
        }
        PacketRepr::SobelPatch(patch) => {
            p.sobel_packets += 1;
            p.gradients.add_patch(patch, start.octaves)
        }
        _ => Ok(()),
    }
}

impl FrameAssembler {
    /// An assembler that has seen nothing, counting lost pixels within `refinement_reach` of
    /// a keypoint against it (see [`FrameAssembler::refinement_reach`]).
    pub fn new(refinement_reach: Option<usize>) -> Self {
        Self {
            refinement_reach,
            ..Self::default()
        }
    }

    /// The next thing that happened, oldest first.
    pub fn pop_event(&mut self) -> Option<Event> {
        self.events.pop_front()
    }

    /// The frame in progress: id, camera and packets so far.
    pub fn in_progress(&self) -> Option<(u32, Camera, u32)> {
        self.partial
            .as_ref()
            .map(|p| (p.frame_id, p.camera, p.packets))
    }

    /// A link frame that did not decode; `wire_len` is the bytes it took, `header` its header
    /// when the packet was intact up to its payload.
    ///
    /// An intact packet still used up a number of its source, which is checked as any
    /// packet's. One of a kind this host does not know (a newer device may add kinds within a
    /// version) is then counted and skipped without damage; one whose payload breaks its
    /// kind's layout damages the open frame when it comes from the frame's channel. A damaged
    /// packet costs nothing here: the gap it leaves in its source's numbering is counted
    /// against the frame it belonged to.
    pub fn undecodable(
        &mut self,
        error: stereocal_wire::Error,
        header: Option<Header>,
        wire_len: usize,
    ) {
        let mut ours = false;
        if let Some(header) = header {
            if self.number(&header) == Numbering::Late {
                self.stats.late_packets += 1;
                return;
            }
            ours = self
                .partial
                .as_ref()
                .is_some_and(|p| Source::channel(p.camera) == header.source);
        }
        if let Some(p) = &mut self.partial {
            p.wire_bytes += wire_len as u64;
        }
        if header.is_some() && error == stereocal_wire::Error::DecodeUnknownKind {
            self.stats.unknown_kinds += 1;
            return;
        }
        self.stats.undecodable += 1;
        let after_seq = self.last_decoded.unwrap_or(0);
        if let Some(p) = self.partial.as_mut().filter(|_| ours) {
            p.damage(Damage::Undecodable { after_seq, error });
        }
    }

    /// A link frame longer than any packet: like any damaged packet, it shows as a gap.
    pub fn over_long(&mut self, wire_len: usize) {
        self.stats.over_long += 1;
        if let Some(p) = &mut self.partial {
            p.wire_bytes += wire_len as u64;
        }
    }

    /// Checks an intact packet's sequence number against its source's last. A jump counts as
    /// a gap, and the packets it skipped count against the open frame when they were its
    /// channel's; a number at or just behind the last is a late packet, which leaves the
    /// numbering as it is.
    fn number(&mut self, header: &Header) -> Numbering {
        let (source, seq) = (header.source, header.seq);
        let Some(&last) = self.last_seq.get(&source) else {
            self.last_seq.insert(source, seq);
            self.last_decoded = Some(seq);
            return Numbering::Fresh;
        };
        if last.wrapping_sub(seq) < LATE_WINDOW {
            return Numbering::Late;
        }
        self.last_seq.insert(source, seq);
        self.last_decoded = Some(seq);
        let expected = last.wrapping_add(1);
        if seq == expected {
            return Numbering::Fresh;
        }
        let lost = seq.wrapping_sub(expected);
        self.stats.sequence_gaps += 1;
        self.stats.packets_lost += u64::from(lost);
        if let Some(p) = self
            .partial
            .as_mut()
            .filter(|p| Source::channel(p.camera) == source)
        {
            p.lost_packets = p.lost_packets.saturating_add(u32::from(lost));
        }
        Numbering::Fresh
    }

    /// A decoded packet; `wire_len` is the link bytes it took (delimiter and any noise
    /// before it included).
    pub fn packet(&mut self, header: &Header, packet: &PacketRepr<'_>, wire_len: usize) {
        self.stats.packets += 1;
        let seq = header.seq;
        if let PacketRepr::Hello(hello) = packet {
            // A device that says Hello has (re)started: every source's numbering starts
            // over, and a frame it was sending will not be finished.
            self.last_seq.clear();
            self.last_seq.insert(header.source, seq);
            self.last_decoded = Some(seq);
            if let Some(p) = self.partial.take() {
                let next = PacketRef {
                    kind: header.kind,
                    seq,
                    frame_id: p.frame_id,
                    camera: p.camera,
                };
                self.close_damaged(p, Damage::Truncated { next });
            }
            self.events.push_back(Event::Hello(*hello));
            return;
        }
        let late = self.number(header) == Numbering::Late;
        let frame_packet = matches!(
            packet,
            PacketRepr::FrameStart(_)
                | PacketRepr::PointBatch(_)
                | PacketRepr::SobelRows(_)
                | PacketRepr::SobelPatch(_)
                | PacketRepr::FrameEnd(_)
        );
        if late && frame_packet {
            self.stats.late_packets += 1;
            return;
        }
        match packet {
            PacketRepr::Log(log) => {
                self.stats.log_frames += 1;
                self.events.push_back(Event::Log(LogFrame {
                    seq,
                    bytes: log.frame.to_vec(),
                }));
            }
            PacketRepr::RegisterValue(v) => self.events.push_back(Event::RegisterValue(*v)),
            PacketRepr::Encoders(e) => self.events.push_back(Event::Encoders(*e)),
            PacketRepr::ErrorReport(report) => {
                self.stats.device_errors += 1;
                self.events.push_back(Event::DeviceError {
                    seq,
                    report: *report,
                });
            }
            PacketRepr::FrameStart(start) => {
                let this = PacketRef {
                    kind: header.kind,
                    seq,
                    frame_id: start.frame_id,
                    camera: start.camera,
                };
                if let Some(previous) = self.partial.take() {
                    self.close_without_end(previous, Damage::Truncated { next: this });
                }
                let mut fresh = Partial::new(start.frame_id, start.camera, Some(*start));
                fresh.wire_bytes = wire_len as u64;
                fresh.packets = 1;
                if let Some(problem) = geometry_problem(start) {
                    fresh.damage(Damage::Content {
                        packet: this,
                        problem,
                    });
                }
                self.partial = Some(fresh);
            }
            PacketRepr::PointBatch(_)
            | PacketRepr::SobelRows(_)
            | PacketRepr::SobelPatch(_)
            | PacketRepr::FrameEnd(_) => self.body(header, packet, wire_len),
            PacketRepr::Hello(_) | PacketRepr::RegisterWrite(_) | PacketRepr::RegisterRead(_) => {
                // Host-to-device kinds: a loopback or a confused peer.
                self.stats.stray_packets += 1;
            }
        }
    }

    /// A packet of a frame's body (points, Sobel, end).
    fn body(&mut self, header: &Header, packet: &PacketRepr<'_>, wire_len: usize) {
        let Some((frame_id, camera)) = body_ids(packet) else {
            return;
        };
        let this = PacketRef {
            kind: header.kind,
            seq: header.seq,
            frame_id,
            camera,
        };
        let belongs = self
            .partial
            .as_ref()
            .map(|p| (p.frame_id, p.camera) == (frame_id, camera));
        if belongs == Some(false) {
            // Another frame's packet: this frame lost its end, the other its start.
            if let Some(previous) = self.partial.take() {
                self.close_without_end(previous, Damage::Foreign { packet: this });
            }
        }
        let p = self.partial.get_or_insert_with(|| {
            let mut headless = Partial::new(frame_id, camera, None);
            headless.damage(Damage::MissingStart { first: this });
            headless
        });
        p.wire_bytes += wire_len as u64;
        p.packets += 1;
        if p.damage.is_none() {
            if let Err(problem) = add_body(p, packet) {
                p.damage(Damage::Content {
                    packet: this,
                    problem,
                });
            }
        }
        if let PacketRepr::FrameEnd(end) = packet {
            if let Some(p) = self.partial.take() {
                self.close(p, header.seq, end);
            }
        }
    }

    /// Reports a dropped frame.
    fn close_damaged(&mut self, p: Partial, damage: Damage) {
        let damage = p.damage.clone().unwrap_or(damage);
        self.stats.frames_damaged += 1;
        self.stats.damage.count(&damage);
        self.events
            .push_back(Event::Frame(FrameOutcome::Damaged(DamagedFrame {
                frame_id: p.frame_id,
                camera: p.camera,
                damage,
                wire_bytes: p.wire_bytes,
            })));
    }

    /// Closes a frame whose `FrameEnd` was lost, found out by `reason` (the packet that
    /// showed it): salvaged with unknown totals when it has its `FrameStart`.
    fn close_without_end(&mut self, p: Partial, reason: Damage) {
        match (p.start, &p.damage) {
            (Some(start), None) => {
                let seq = self.last_decoded.unwrap_or(0);
                let lost = p.lost_packets;
                self.finish(p, start, seq, None, Some(lost));
            }
            _ => self.close_damaged(p, reason),
        }
    }

    /// Closes a frame at its `FrameEnd` (sequence number `seq`).
    fn close(&mut self, p: Partial, seq: u16, end: &FrameEndRepr) {
        let (Some(start), None) = (p.start, &p.damage) else {
            let damage = p.damage.clone().unwrap_or(Damage::MissingStart {
                first: PacketRef {
                    kind: PacketKind::FrameEnd,
                    seq,
                    frame_id: p.frame_id,
                    camera: p.camera,
                },
            });
            return self.close_damaged(p, damage);
        };
        let points_received = p.points.len().min(u32::MAX as usize) as u32;
        let counts_match = end.point_count == points_received && end.sobel_count == p.sobel_packets;
        // Without a gap, counts that disagree are the device's own inconsistency; with one,
        // the difference is what the link lost, which cannot exceed what was announced.
        let lost_fits = end.point_count >= points_received && end.sobel_count >= p.sobel_packets;
        if !counts_match && (p.lost_packets == 0 || !lost_fits) {
            let damage = Damage::CountMismatch {
                seq,
                points_announced: end.point_count,
                points_received,
                sobel_announced: end.sobel_count,
                sobel_received: p.sobel_packets,
            };
            return self.close_damaged(p, damage);
        }
        let lost = (p.lost_packets > 0).then_some(p.lost_packets);
        self.finish(p, start, seq, Some(end), lost);
    }

    /// Assembles a frame that has its `FrameStart` and no damage. `end` is its `FrameEnd`
    /// (`None` when lost), `lost` the packets lost (`None` when it arrived whole); a frame
    /// that lost more than the loss limit is dropped.
    fn finish(
        &mut self,
        mut p: Partial,
        start: FrameStartRepr,
        seq: u16,
        end: Option<&FrameEndRepr>,
        lost: Option<u32>,
    ) {
        let points_received = p.points.len().min(u32::MAX as usize) as u32;
        let points_lost = end.map(|e| e.point_count - points_received);
        let completeness = match lost {
            None => Completeness::Intact,
            Some(_) => Completeness::Salvaged {
                width: start.width,
                height: start.height,
                octaves: start.octaves,
                points_known: points_lost == Some(0),
            },
        };
        let points = std::mem::take(&mut p.points);
        let keypoints = std::mem::take(&mut p.keypoints);
        let gradients = std::mem::take(&mut p.gradients);
        let patches_mode = matches!(gradients, GradientBuilder::Patches(_));
        let finished = match gradients.finish(&points, keypoints, completeness) {
            Ok(f) => f,
            Err(FinishError::Content(problem)) => {
                let packet = PacketRef {
                    kind: PacketKind::FrameEnd,
                    seq,
                    frame_id: p.frame_id,
                    camera: p.camera,
                };
                return self.close_damaged(p, Damage::Content { packet, problem });
            }
            Err(FinishError::Frame(error)) => {
                let damage = Damage::Assembly {
                    frame_id: p.frame_id,
                    camera: p.camera,
                    error,
                };
                return self.close_damaged(p, damage);
            }
        };
        let mut salvage = lost.map(|packets_lost| Salvage {
            packets_lost,
            rows_lost: finished.rows_lost.clone(),
            points_lost,
            patches_lost: end.map(|e| {
                if patches_mode {
                    e.sobel_count - p.sobel_packets
                } else {
                    0
                }
            }),
            keypoints_lost: 0,
        });
        let features = match FeatureFrame::new(
            u64::from(p.frame_id),
            start.timestamp_us,
            start.width.into(),
            start.height.into(),
            finished.keypoints,
            finished.gradients,
        ) {
            Ok(f) => f,
            Err(error) => {
                let damage = Damage::Assembly {
                    frame_id: p.frame_id,
                    camera: p.camera,
                    error,
                };
                return self.close_damaged(p, damage);
            }
        };
        if let Some(damage) = salvage
            .as_ref()
            .and_then(|_| plane_over_limit(&features, self.loss_limit.unwrap_or(MAX_LOST_FRACTION)))
        {
            return self.close_damaged(p, damage);
        }
        if let Some(s) = &mut salvage {
            let on_lost_pixels = features
                .keypoints_on_lost_pixels(self.refinement_reach)
                .min(u32::MAX as usize) as u32;
            s.keypoints_lost =
                s.points_lost.unwrap_or(0) + s.patches_lost.unwrap_or(0) + on_lost_pixels;
            // Without its `FrameEnd`, the points that arrived are all the frame is known to have.
            let announced = end.map_or(points_received, |e| e.point_count);
            let limit = self.loss_limit.unwrap_or(MAX_LOST_FRACTION);
            if !within_limit(s.keypoints_lost, announced, limit) {
                let damage = Damage::Lost {
                    lost: s.keypoints_lost,
                    of: announced,
                };
                return self.close_damaged(p, damage);
            }
        }
        self.stats.frames_delivered += 1;
        self.stats.frames_salvaged += u64::from(salvage.is_some());
        self.stats.delivered_wire_bytes += p.wire_bytes;
        self.events
            .push_back(Event::Frame(FrameOutcome::Delivered(Box::new(
                ReceivedFrame {
                    frame_id: p.frame_id,
                    camera: p.camera,
                    features,
                    octaves: start.octaves,
                    wire_bytes: p.wire_bytes,
                    packets: p.packets,
                    dropped_points: end.map_or(0, |e| e.dropped_points),
                    dropped_sobel: end.map_or(0, |e| e.dropped_sobel),
                    flags: end.map_or(FrameEndFlags(0), |e| e.flags),
                    points_without_patch: finished.without_patch,
                    salvage,
                },
            ))));
    }
}

/// Why a salvaged frame lost too much of a Sobel plane to be delivered: an octave short of
/// more than `limit` of its pixels (the guided search reads the planes beyond the keypoints'
/// windows). `None` when every plane is within it.
fn plane_over_limit(features: &FeatureFrame, limit: f64) -> Option<Damage> {
    let Gradients::Planes(planes) = features.gradients() else {
        return None;
    };
    planes.iter().find_map(|plane| {
        let pixels = plane.width().saturating_mul(plane.height());
        let lost = u32::try_from(plane.lost_pixels()).unwrap_or(u32::MAX);
        (!within_limit(lost, pixels, limit)).then_some(Damage::PlaneLost {
            octave: plane.octave(),
            lost,
            of: pixels,
        })
    })
}
