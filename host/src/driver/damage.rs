//! Why a camera frame was dropped, naming the packet at fault.

use std::fmt;

use stereocal_wire::{Camera, PacketKind};

use crate::features::FeatureError;

/// A packet, identified the way a log line needs it: kind, sequence number, frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PacketRef {
    /// Packet kind.
    pub kind: PacketKind,
    /// Link sequence number.
    pub seq: u16,
    /// The frame the packet says it belongs to.
    pub frame_id: u32,
    /// The camera the packet says it belongs to.
    pub camera: Camera,
}

impl fmt::Display for PacketRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:?} seq {} (frame {} {:?})",
            self.kind, self.seq, self.frame_id, self.camera
        )
    }
}

/// What made a frame unusable. The first problem found is kept; later packets of the frame
/// are still consumed so the next frame starts cleanly.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Damage {
    /// The link cost the frame more of its keypoints than a salvaged frame may lose
    /// ([`MAX_LOST_FRACTION`](super::MAX_LOST_FRACTION)): points or patches that did not
    /// arrive, and keypoints whose window touches a lost row.
    #[error("lost {lost} of {of} keypoints")]
    Lost {
        /// Keypoints lost.
        lost: u32,
        /// Points announced (the points that arrived when the `FrameEnd` was lost).
        of: u32,
    },
    /// The link cost an octave's Sobel plane more of its pixels than a salvaged frame may
    /// lose ([`MAX_LOST_FRACTION`](super::MAX_LOST_FRACTION)).
    #[error("lost {lost} of {of} Sobel pixels of octave {octave}")]
    PlaneLost {
        /// The octave.
        octave: u8,
        /// Pixels lost.
        lost: u32,
        /// Pixels of the octave.
        of: u32,
    },
    /// An intact packet of the frame's channel whose payload breaks its kind's layout.
    #[error("undecodable packet after seq {after_seq}: {error}")]
    Undecodable {
        /// The sequence number of the last packet that decoded, of any source.
        after_seq: u16,
        /// The wire crate's reason.
        error: stereocal_wire::Error,
    },
    /// The device restarted (said `Hello`) before this frame's `FrameEnd`; also the reason
    /// an unsalvageable frame gives when the next `FrameStart` came before its `FrameEnd`.
    #[error("cut short: {next} arrived before FrameEnd")]
    Truncated {
        /// The packet that started the next frame.
        next: PacketRef,
    },
    /// Packets of the frame arrived without its `FrameStart` (it was lost).
    #[error("no FrameStart: the first packet of the frame was {first}")]
    MissingStart {
        /// The first packet seen.
        first: PacketRef,
    },
    /// A packet of another frame or camera arrived inside this frame.
    #[error("{packet} arrived inside another frame")]
    Foreign {
        /// The intruding packet.
        packet: PacketRef,
    },
    /// `FrameEnd`'s counts disagree with what arrived.
    #[error(
        "FrameEnd seq {seq} announces {points_announced} points and {sobel_announced} Sobel packets, \
         {points_received} and {sobel_received} arrived"
    )]
    CountMismatch {
        /// The `FrameEnd`'s sequence number.
        seq: u16,
        /// Points the device sent.
        points_announced: u32,
        /// Points received.
        points_received: u32,
        /// Sobel packets the device sent.
        sobel_announced: u32,
        /// Sobel packets received.
        sobel_received: u32,
    },
    /// A packet's contents do not fit the frame it belongs to.
    #[error("{packet}: {problem}")]
    Content {
        /// The packet at fault.
        packet: PacketRef,
        /// What is wrong with it.
        problem: ContentError,
    },
    /// The assembled frame failed the feature frame's own checks.
    #[error("frame {frame_id} {camera:?}: {error}")]
    Assembly {
        /// Frame number.
        frame_id: u32,
        /// Camera.
        camera: Camera,
        /// The check that failed.
        error: FeatureError,
    },
}

/// What is wrong with the contents of one packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ContentError {
    /// Octave at or above the frame's octave count.
    #[error("octave {octave} but the frame has {octaves}")]
    Octave {
        /// The packet's octave.
        octave: u8,
        /// The frame's octave count.
        octaves: u8,
    },
    /// A point outside its octave's image.
    #[error("point {index} at ({x}, {y}) outside octave {octave} ({width}x{height})")]
    PointOutside {
        /// Index within the packet.
        index: usize,
        /// Octave.
        octave: u8,
        /// Column.
        x: u16,
        /// Row.
        y: u16,
        /// Octave width.
        width: u16,
        /// Octave height.
        height: u16,
    },
    /// A Sobel row (or segment) that is empty or ends past its octave's width.
    #[error(
        "Sobel row segment of {width} pixels at column {x}, octave {octave} is {expected} wide"
    )]
    RowWidth {
        /// Octave.
        octave: u8,
        /// First column sent.
        x: u16,
        /// Width sent.
        width: u16,
        /// Octave width.
        expected: u16,
    },
    /// A Sobel row below its octave's image.
    #[error("Sobel row {row} outside octave {octave} ({height} rows)")]
    RowOutside {
        /// Octave.
        octave: u8,
        /// Row sent.
        row: u16,
        /// Octave height.
        height: u16,
    },
    /// Pixels of a Sobel row sent twice: a segment starting left of the end of the row's
    /// last one.
    #[error("Sobel row {row} of octave {octave} repeats pixels from column {x}")]
    DuplicateRow {
        /// Octave.
        octave: u8,
        /// Row.
        row: u16,
        /// First column of the repeating segment.
        x: u16,
    },
    /// Sobel rows of one octave from two different scales.
    #[error("Sobel rows of octave {octave} from scales {first} and {other}")]
    MixedScales {
        /// Octave.
        octave: u8,
        /// Scale of the octave's first row.
        first: u8,
        /// The other scale.
        other: u8,
    },
    /// Both `SobelRows` and `SobelPatch` packets in one frame.
    #[error("SobelRows and SobelPatch packets in one frame")]
    MixedSobelModes,
    /// A patch for a point index that was never sent.
    #[error("patch for point {index}, only {points} points so far")]
    PatchIndex {
        /// The patch's point index.
        index: u16,
        /// Points received before the patch.
        points: usize,
    },
    /// Two patches for one point.
    #[error("second patch for point {index}")]
    DuplicatePatch {
        /// The point index.
        index: u16,
    },
    /// A patch whose octave or centre is not its point's.
    #[error(
        "patch for point {index} at octave {octave} ({x}, {y}), the point is at octave \
         {point_octave} ({point_x}, {point_y})"
    )]
    PatchPlacement {
        /// The point index.
        index: u16,
        /// Patch octave.
        octave: u8,
        /// Patch centre column.
        x: u16,
        /// Patch centre row.
        y: u16,
        /// Point octave.
        point_octave: u8,
        /// Point column.
        point_x: u16,
        /// Point row.
        point_y: u16,
    },
    /// A Sobel plane that did not receive all its rows by `FrameEnd`.
    #[error("octave {octave} Sobel plane has {received} of {rows} rows")]
    IncompletePlane {
        /// Octave.
        octave: u8,
        /// Rows received.
        received: u32,
        /// Rows in the octave.
        rows: u16,
    },
    /// `FrameStart` describes a frame the host cannot hold.
    #[error("frame {width}x{height} with {octaves} octaves")]
    BadGeometry {
        /// Width.
        width: u16,
        /// Height.
        height: u16,
        /// Octaves.
        octaves: u8,
    },
}

/// Counts of dropped frames by reason (one per [`Damage`] variant).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DamageCounts {
    /// Frames dropped for [`Damage::Lost`].
    pub lost: u64,
    /// Frames dropped for [`Damage::Undecodable`].
    pub undecodable: u64,
    /// Frames dropped for [`Damage::Truncated`].
    pub truncated: u64,
    /// Frames dropped for [`Damage::MissingStart`].
    pub missing_start: u64,
    /// Frames dropped for [`Damage::Foreign`].
    pub foreign: u64,
    /// Frames dropped for [`Damage::CountMismatch`].
    pub count_mismatch: u64,
    /// Frames dropped for [`Damage::Content`].
    pub content: u64,
    /// Frames dropped for [`Damage::Assembly`].
    pub assembly: u64,
}

impl DamageCounts {
    /// Counts one dropped frame.
    pub fn count(&mut self, damage: &Damage) {
        let slot = match damage {
            Damage::Lost { .. } | Damage::PlaneLost { .. } => &mut self.lost,
            Damage::Undecodable { .. } => &mut self.undecodable,
            Damage::Truncated { .. } => &mut self.truncated,
            Damage::MissingStart { .. } => &mut self.missing_start,
            Damage::Foreign { .. } => &mut self.foreign,
            Damage::CountMismatch { .. } => &mut self.count_mismatch,
            Damage::Content { .. } => &mut self.content,
            Damage::Assembly { .. } => &mut self.assembly,
        };
        *slot += 1;
    }

    /// All dropped frames.
    pub fn total(&self) -> u64 {
        self.lost
            + self.undecodable
            + self.truncated
            + self.missing_start
            + self.foreign
            + self.count_mismatch
            + self.content
            + self.assembly
    }
}
