//! The stream engine's behaviour: what it sends for a frame, and when.

use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_wire::{
    Camera, FrameEndFlags, FrameEndRepr, FrameStartRepr, PacketRepr, PointBatchRepr, Records,
    SobelPatchRepr, SobelPixel, SobelRowsRepr, Source, PATCH_PIXELS,
};

use crate::fabric::stream::patch::{PatchQueue, PendingPatch, HALF};
use crate::fabric::stream::point_batch::{wire_point, PointBatch};
use crate::fabric::stream::sobel_ring::{Completed, OutOfOrder, SobelRing};
use crate::fabric::{Extremum, FrontEnd, Overflow, SobelRun};
use crate::framing::{ByteSink, Framer, Numbering};

/// What FRAME_ARM latches for the engine: the frame's registers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StreamFrame {
    /// FRAME_ID.
    pub frame_id: u32,
    /// STREAM_CONTROL.CAMERA.
    pub camera: Camera,
    /// TIMESTAMP_HI:TIMESTAMP_LO.
    pub timestamp_us: u64,
    /// WIDTH.
    pub width: u16,
    /// HEIGHT.
    pub height: u16,
    /// OCTAVES.
    pub octaves: u8,
    /// OUTPUT_MODE.SOBEL_OUTPUT.
    pub mode: SobelOutput,
    /// OUTPUT_MODE.SOBEL_SCALE.
    pub sobel_scale: u8,
    /// OUTPUT_MODE.POINTS_PER_BATCH.
    pub points_per_batch: u8,
    /// OUTPUT_MODE.ROW_SEGMENT.
    pub row_segment: u16,
}

/// Why the engine stopped sending a frame (STREAM_FAULT).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StreamFault {
    /// A Sobel pixel outside its octave's image or behind a row already complete.
    SobelOrder(OutOfOrder),
    /// A point outside its octave's image.
    PointOutside {
        /// The point's octave.
        octave: u8,
        /// Its column.
        x: u16,
        /// Its row.
        y: u16,
    },
    /// A packet the framer refused.
    Encode,
}

/// What the engine sent of the current (or last) frame: STREAM_POINTS,
/// STREAM_SOBEL_PACKETS and STREAM_PATCHES_DROPPED.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StreamCounts {
    /// Points sent in `PointBatch` packets.
    pub points: u32,
    /// `SobelRows` or `SobelPatch` packets sent.
    pub sobel_packets: u32,
    /// Points that got no patch.
    pub patches_dropped: u32,
}

/// The frame being sent.
#[derive(Clone, Copy, Debug)]
struct Sending {
    frame: StreamFrame,
    /// The datapath's drop counters at FRAME_ARM.
    drops_at_arm: Overflow,
}

/// The stream engine of one camera channel whose octave 0 is at most `W0` pixels wide,
/// sending on the link `L` (its LINK_OUT port).
pub struct StreamEngine<const W0: usize, L> {
    out: Output<W0, L>,
    /// Room for the deeper octaves' pixels of a line time while octave 0's are stored first
    /// (`FrontEnd::drain_sobel_by_octave`): as many as the Sobel FIFO holds, 3 lines of
    /// octave 0 (the map's `sobel_fifo_depth`), two words each.
    stash: [[[u32; 2]; W0]; 3],
}

/// Everything of the engine but its stash: what turns the records into packets.
struct Output<const W0: usize, L> {
    link: L,
    framer: Framer,
    numbering: Numbering,
    sending: Option<Sending>,
    counts: StreamCounts,
    fault: Option<StreamFault>,
    ring: SobelRing<W0>,
    patches: PatchQueue,
    batch: PointBatch,
    patch: [SobelPixel; PATCH_PIXELS],
}

impl<const W0: usize, L: ByteSink> StreamEngine<W0, L> {
    /// An idle engine on `link`, its first packet numbered 0.
    pub fn new(link: L) -> Self {
        Self {
            out: Output {
                link,
                framer: Framer::new(),
                numbering: Numbering::new(Source::channel(Camera::Left)),
                sending: None,
                counts: StreamCounts::default(),
                fault: None,
                ring: SobelRing::new(),
                patches: PatchQueue::new(),
                batch: PointBatch::new(),
                patch: [SobelPixel::default(); PATCH_PIXELS],
            },
            stash: [[[0; 2]; W0]; 3],
        }
    }

    /// The link the engine sends on.
    pub fn link(&self) -> &L {
        &self.out.link
    }

    /// The link, mutably (to take what the engine sent).
    pub fn link_mut(&mut self) -> &mut L {
        &mut self.out.link
    }

    /// STREAM_CONTROL.FEC: whether the link frames sent from now on carry parity.
    pub fn set_fec(&mut self, on: bool) {
        self.out.framer.set_fec(on);
    }

    /// Whether a frame is being sent (FRAME_ARM up to its end): the FIFOs are the engine's.
    pub fn sending(&self) -> bool {
        self.out.sending.is_some()
    }

    /// The current (or last) frame's counters.
    pub fn counts(&self) -> StreamCounts {
        self.out.counts
    }

    /// Why the current (or last) frame stopped, if it did.
    pub fn fault(&self) -> Option<StreamFault> {
        self.out.fault
    }

    /// FRAME_ARM with the engine enabled: zeroes the counters and sends `FrameStart`.
    /// `drops` are the datapath's drop counters now, the base of `FrameEnd`'s.
    pub fn start(&mut self, frame: StreamFrame, drops: Overflow) {
        let source = Source::channel(frame.camera);
        if self.out.numbering.source() != source {
            self.out.numbering = Numbering::new(source);
        }
        self.out.counts = StreamCounts::default();
        self.out.fault = None;
        self.out
            .ring
            .start(frame.width, frame.height, frame.octaves);
        self.out.patches.clear();
        self.out.batch.start(frame.points_per_batch);
        self.out.sending = Some(Sending {
            frame,
            drops_at_arm: drops,
        });
        let start = PacketRepr::FrameStart(FrameStartRepr {
            frame_id: frame.frame_id,
            camera: frame.camera,
            width: frame.width,
            height: frame.height,
            octaves: frame.octaves,
            timestamp_us: frame.timestamp_us,
        });
        self.out.send_or_fault(&start);
    }

    /// SOFT_RESET: the frame is abandoned without a `FrameEnd`; the counters and the fault
    /// read 0. The numbering goes on, so the host sees the abandoned frame's end as lost.
    pub fn abort(&mut self) {
        self.out.sending = None;
        self.out.counts = StreamCounts::default();
        self.out.fault = None;
    }

    /// Takes every entry the datapath's FIFOs hold, points first, then the Sobel pixels
    /// octave by octave, and sends what they make ready. With no frame being sent the FIFOs
    /// are left to the bus; after a fault the frame's entries are taken and discarded.
    pub fn take<F: FrontEnd + ?Sized>(&mut self, datapath: &mut F) {
        if self.out.sending.is_none() {
            return;
        }
        let Self { out, stash } = self;
        datapath.drain_points(&mut |points| {
            for point in points {
                if out.fault.is_none() {
                    if let Err(fault) = out.on_point(point) {
                        out.fault = Some(fault);
                    }
                }
            }
        });
        datapath.drain_sobel_by_octave(stash.as_flattened_mut(), &mut |run| {
            if out.fault.is_none() {
                if let Err(fault) = out.on_sobel(run) {
                    out.fault = Some(fault);
                }
            }
        });
    }

    /// The datapath has emitted the whole frame: sends the rows and patches still held, the
    /// last points and `FrameEnd` (none after a fault). `drops` are the datapath's drop
    /// counters now.
    pub fn finish(&mut self, drops: Overflow) {
        let Some(sending) = self.out.sending.take() else {
            return;
        };
        if self.out.fault.is_some() {
            return;
        }
        if let Err(fault) = self.out.flush(&sending) {
            self.out.fault = Some(fault);
            return;
        }
        let overflow = drops.since(sending.drops_at_arm);
        let dropped_sobel = overflow
            .sobel
            .saturating_add(self.out.counts.patches_dropped);
        let mut flags = FrameEndFlags(0);
        if overflow.points > 0 {
            flags = flags | FrameEndFlags::POINT_FIFO_OVERFLOW;
        }
        if dropped_sobel > 0 {
            flags = flags | FrameEndFlags::SOBEL_FIFO_OVERFLOW;
        }
        let end = PacketRepr::FrameEnd(FrameEndRepr {
            frame_id: sending.frame.frame_id,
            camera: sending.frame.camera,
            point_count: self.out.counts.points,
            sobel_count: self.out.counts.sobel_packets,
            flags,
            dropped_points: overflow.points,
            dropped_sobel,
        });
        self.out.send_or_fault(&end);
    }
}

impl<const W0: usize, L: ByteSink> Output<W0, L> {
    /// The rows each octave still has open, the patches still waiting, the last points.
    fn flush(&mut self, sending: &Sending) -> Result<(), StreamFault> {
        for completed in self.ring.finish().into_iter().flatten() {
            self.rows_completed(&sending.frame, completed)?;
        }
        while let Some(patch) = self.patches.take_first(|_| true) {
            self.send_patch(&sending.frame, &patch)?;
        }
        self.send_points(&sending.frame)
    }

    fn send_or_fault(&mut self, packet: &PacketRepr<'_>) {
        if self.fault.is_none()
            && self
                .framer
                .send(&mut self.link, &mut self.numbering, packet)
                .is_err()
        {
            self.fault = Some(StreamFault::Encode);
        }
    }

    fn frame(&self) -> Option<StreamFrame> {
        self.sending.map(|s| s.frame)
    }

    fn on_point(&mut self, point: &Extremum) -> Result<(), StreamFault> {
        let outside = StreamFault::PointOutside {
            octave: point.octave,
            x: point.x,
            y: point.y,
        };
        let (Some(frame), Some(rows)) = (self.frame(), self.ring.rows(point.octave)) else {
            return Err(outside);
        };
        let (width, height) = rows.dims();
        let done = rows.next_row();
        if point.x >= width || point.y >= height {
            return Err(outside);
        }
        let index = self.counts.points;
        self.counts.points = self.counts.points.saturating_add(1);
        if self.batch.push(wire_point(point)) {
            self.send_points(&frame)?;
        }
        if frame.mode != SobelOutput::Patches {
            return Ok(());
        }
        let Ok(index) = u16::try_from(index) else {
            // SobelPatch numbers points with 16 bits; later points cannot be referenced.
            self.counts.patches_dropped = self.counts.patches_dropped.saturating_add(1);
            return Ok(());
        };
        let pending = PendingPatch {
            index,
            octave: point.octave,
            x: point.x,
            y: point.y,
        };
        if done >= pending.rows_needed_before(height) {
            self.send_patch(&frame, &pending)
        } else {
            if self.patches.push(pending).is_err() {
                self.counts.patches_dropped = self.counts.patches_dropped.saturating_add(1);
            }
            Ok(())
        }
    }

    /// Stores a run of the Sobel stream, sending what each row it completes makes ready
    /// before storing the pixels after it.
    fn on_sobel(&mut self, mut run: SobelRun<'_>) -> Result<(), StreamFault> {
        let Some(frame) = self.frame() else {
            return Ok(());
        };
        while !run.is_empty() {
            let (taken, completed) = self.ring.push_run(&run).map_err(StreamFault::SobelOrder)?;
            if let Some(completed) = completed {
                self.rows_completed(&frame, completed)?;
            }
            run = run.split_at(taken).1;
        }
        Ok(())
    }

    /// Sends completed rows (rows mode) or the patches they made ready (patch mode).
    fn rows_completed(
        &mut self,
        frame: &StreamFrame,
        completed: Completed,
    ) -> Result<(), StreamFault> {
        let octave = completed.octave;
        match frame.mode {
            SobelOutput::Rows => {
                // Validated at least MIN_SIDE, so never 0.
                let segment = usize::from(frame.row_segment).max(1);
                for row in completed.rows {
                    // A row whose every pixel the FIFO dropped is not sent (FrameEnd counts it).
                    let Some(pixels) = self.ring.row(octave, row) else {
                        continue;
                    };
                    for (i, part) in pixels.chunks(segment).enumerate() {
                        let packet = PacketRepr::SobelRows(SobelRowsRepr {
                            frame_id: frame.frame_id,
                            camera: frame.camera,
                            octave,
                            scale: frame.sobel_scale,
                            row,
                            // A row is at most MAX_WIDTH pixels, which fits a u16.
                            x: (i * segment) as u16,
                            pixels: Records::Values(part),
                        });
                        self.framer
                            .send(&mut self.link, &mut self.numbering, &packet)
                            .map_err(|_| StreamFault::Encode)?;
                        self.counts.sobel_packets = self.counts.sobel_packets.saturating_add(1);
                    }
                }
            }
            SobelOutput::Patches => {
                let Some(rows) = self.ring.rows(octave) else {
                    return Ok(());
                };
                let (done, (_, height)) = (rows.next_row(), rows.dims());
                while let Some(patch) = self
                    .patches
                    .take_first(|p| p.octave == octave && done >= p.rows_needed_before(height))
                {
                    self.send_patch(frame, &patch)?;
                }
            }
        }
        Ok(())
    }

    /// Cuts and sends one patch, or counts it when its top rows have left the ring.
    fn send_patch(&mut self, frame: &StreamFrame, patch: &PendingPatch) -> Result<(), StreamFault> {
        let top_held = self.ring.rows(patch.octave).is_some_and(|rows| {
            patch.first_row() >= rows.oldest_row() && patch.first_row() < rows.dims().1
        });
        if !top_held {
            self.counts.patches_dropped = self.counts.patches_dropped.saturating_add(1);
            return Ok(());
        }
        self.ring.window(
            patch.octave,
            i32::from(patch.x) - i32::from(HALF),
            i32::from(patch.y) - i32::from(HALF),
            &mut self.patch,
        );
        let packet = PacketRepr::SobelPatch(SobelPatchRepr {
            frame_id: frame.frame_id,
            camera: frame.camera,
            point_index: patch.index,
            octave: patch.octave,
            scale: frame.sobel_scale,
            x: patch.x,
            y: patch.y,
            pixels: Records::Values(&self.patch),
        });
        self.framer
            .send(&mut self.link, &mut self.numbering, &packet)
            .map_err(|_| StreamFault::Encode)?;
        self.counts.sobel_packets = self.counts.sobel_packets.saturating_add(1);
        Ok(())
    }

    /// Sends the collected points, if any.
    fn send_points(&mut self, frame: &StreamFrame) -> Result<(), StreamFault> {
        if self.batch.points().is_empty() {
            return Ok(());
        }
        let packet = PacketRepr::PointBatch(PointBatchRepr {
            frame_id: frame.frame_id,
            camera: frame.camera,
            points: Records::Values(self.batch.points()),
        });
        self.framer
            .send(&mut self.link, &mut self.numbering, &packet)
            .map_err(|_| StreamFault::Encode)?;
        self.batch.clear();
        Ok(())
    }
}
