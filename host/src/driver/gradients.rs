//! Collects a frame's Sobel packets into the gradient data of a [`FeatureFrame`](crate::frame::FeatureFrame).
//!
//! Rows mode: one plane per octave, every row exactly once. Patches mode: one 16x16 window
//! per point, matched to its point by `point_index` (a patch may arrive before its point's
//! `PointBatch`: the soft-core cuts a patch as soon as its rows are in, and flushes points in
//! batches), placed on its point's octave pixel.

use stereocal_firmware::fabric::geometry::octave_dims;
use stereocal_wire::{
    Point, Record, Records, SobelPatchRepr, SobelPixel, SobelRowsRepr, PATCH_PIXELS,
};

use super::damage::ContentError;
use crate::frame::{FrameError, Gradients, Keypoint, SobelPatch, SobelPlane};

/// One octave's plane being filled row by row.
#[derive(Debug)]
pub(crate) struct PlaneBuilder {
    octave: u8,
    scale: u8,
    width: u16,
    height: u16,
    magnitude: Vec<u8>,
    orientation: Vec<u8>,
    have_row: Vec<bool>,
    rows: u32,
}

/// A received patch, with where the device says it sits.
#[derive(Debug)]
pub(crate) struct PatchEntry {
    octave: u8,
    x: u16,
    y: u16,
    patch: SobelPatch,
}

/// The Sobel data of a frame so far.
#[derive(Debug, Default)]
pub(crate) enum GradientBuilder {
    /// No Sobel packet yet.
    #[default]
    Empty,
    Rows(Vec<PlaneBuilder>),
    Patches(Vec<Option<PatchEntry>>),
}

/// What [`GradientBuilder::finish`] hands back.
pub(crate) struct Finished {
    pub keypoints: Vec<Keypoint>,
    pub gradients: Gradients,
    /// Points dropped because no patch came for them.
    pub without_patch: u32,
}

impl GradientBuilder {
    /// Adds one `SobelRows` packet of a `width x height` frame with `octaves` octaves.
    pub fn add_row(
        &mut self,
        row: &SobelRowsRepr<'_>,
        width: u16,
        height: u16,
        octaves: u8,
    ) -> Result<(), ContentError> {
        if row.octave >= octaves {
            return Err(ContentError::Octave {
                octave: row.octave,
                octaves,
            });
        }
        if matches!(self, Self::Empty) {
            *self = Self::Rows(Vec::new());
        }
        let Self::Rows(planes) = self else {
            return Err(ContentError::MixedSobelModes);
        };
        let plane = match planes.iter().position(|p| p.octave == row.octave) {
            Some(i) => &mut planes[i],
            None => {
                let slot = planes.len();
                let (w, h) = octave_dims(width, height, row.octave);
                let n = usize::from(w) * usize::from(h);
                planes.push(PlaneBuilder {
                    octave: row.octave,
                    scale: row.scale,
                    width: w,
                    height: h,
                    magnitude: vec![0; n],
                    orientation: vec![0; n],
                    have_row: vec![false; usize::from(h)],
                    rows: 0,
                });
                &mut planes[slot]
            }
        };
        if row.scale != plane.scale {
            return Err(ContentError::MixedScales {
                octave: row.octave,
                first: plane.scale,
                other: row.scale,
            });
        }
        if row.pixels.len() != usize::from(plane.width) {
            return Err(ContentError::RowWidth {
                octave: row.octave,
                width: row.pixels.len().min(usize::from(u16::MAX)) as u16,
                expected: plane.width,
            });
        }
        let r = usize::from(row.row);
        match plane.have_row.get_mut(r) {
            None => {
                return Err(ContentError::RowOutside {
                    octave: row.octave,
                    row: row.row,
                    height: plane.height,
                })
            }
            Some(true) => {
                return Err(ContentError::DuplicateRow {
                    octave: row.octave,
                    row: row.row,
                })
            }
            Some(have) => *have = true,
        }
        plane.rows += 1;
        let start = r * usize::from(plane.width);
        let end = start + usize::from(plane.width);
        let mag = &mut plane.magnitude[start..end];
        let ori = &mut plane.orientation[start..end];
        match row.pixels {
            // As decoded from the wire: split the interleaved bytes in one pass the compiler
            // can vectorise (the full-Sobel stream is most of what a host decodes).
            Records::Wire(bytes) => {
                for ((m, o), px) in mag
                    .iter_mut()
                    .zip(ori.iter_mut())
                    .zip(bytes.chunks_exact(SobelPixel::LEN))
                {
                    if let [magnitude, orientation] = *px {
                        *m = magnitude;
                        *o = orientation;
                    }
                }
            }
            Records::Values(pixels) => {
                for ((m, o), px) in mag.iter_mut().zip(ori.iter_mut()).zip(pixels) {
                    *m = px.magnitude;
                    *o = px.orientation;
                }
            }
        }
        Ok(())
    }

    /// Adds one `SobelPatch` packet of a frame with `octaves` octaves.
    pub fn add_patch(
        &mut self,
        patch: &SobelPatchRepr<'_>,
        octaves: u8,
    ) -> Result<(), ContentError> {
        if patch.octave >= octaves {
            return Err(ContentError::Octave {
                octave: patch.octave,
                octaves,
            });
        }
        if matches!(self, Self::Empty) {
            *self = Self::Patches(Vec::new());
        }
        let Self::Patches(entries) = self else {
            return Err(ContentError::MixedSobelModes);
        };
        let index = usize::from(patch.point_index);
        if entries.len() <= index {
            entries.resize_with(index + 1, || None);
        }
        if entries[index].is_some() {
            return Err(ContentError::DuplicatePatch {
                index: patch.point_index,
            });
        }
        let mut out = SobelPatch {
            magnitude: [0; PATCH_PIXELS],
            orientation: [0; PATCH_PIXELS],
        };
        for (i, px) in patch.pixels.iter().take(PATCH_PIXELS).enumerate() {
            out.magnitude[i] = px.magnitude;
            out.orientation[i] = px.orientation;
        }
        entries[index] = Some(PatchEntry {
            octave: patch.octave,
            x: patch.x,
            y: patch.y,
            patch: out,
        });
        Ok(())
    }

    /// Pairs the gradients with the frame's points.
    pub fn finish(
        self,
        points: &[Point],
        keypoints: Vec<Keypoint>,
    ) -> Result<Finished, FinishError> {
        match self {
            Self::Empty => Ok(Finished {
                keypoints,
                gradients: Gradients::Planes(Vec::new()),
                without_patch: 0,
            }),
            Self::Rows(planes) => {
                let mut out = Vec::with_capacity(planes.len());
                for p in planes {
                    if p.rows != u32::from(p.height) {
                        return Err(FinishError::Content(ContentError::IncompletePlane {
                            octave: p.octave,
                            received: p.rows,
                            rows: p.height,
                        }));
                    }
                    let plane = SobelPlane::new(
                        p.octave,
                        p.width.into(),
                        p.height.into(),
                        p.magnitude,
                        p.orientation,
                    )
                    .map_err(FinishError::Frame)?;
                    out.push(plane);
                }
                Ok(Finished {
                    keypoints,
                    gradients: Gradients::Planes(out),
                    without_patch: 0,
                })
            }
            Self::Patches(mut entries) => {
                if let Some(index) = entries.iter().skip(points.len()).position(Option::is_some) {
                    return Err(FinishError::Content(ContentError::PatchIndex {
                        index: (points.len() + index) as u16,
                        points: points.len(),
                    }));
                }
                entries.resize_with(points.len(), || None);
                let mut kept = Vec::with_capacity(points.len());
                let mut patches = Vec::with_capacity(points.len());
                for (i, ((p, k), entry)) in points.iter().zip(keypoints).zip(entries).enumerate() {
                    let Some(e) = entry else { continue };
                    if (e.octave, e.x, e.y) != (p.octave, p.x, p.y) {
                        return Err(FinishError::Content(ContentError::PatchPlacement {
                            index: i as u16,
                            octave: e.octave,
                            x: e.x,
                            y: e.y,
                            point_octave: p.octave,
                            point_x: p.x,
                            point_y: p.y,
                        }));
                    }
                    kept.push(k);
                    patches.push(e.patch);
                }
                let without_patch = (points.len() - kept.len()) as u32;
                Ok(Finished {
                    keypoints: kept,
                    gradients: Gradients::Patches(patches),
                    without_patch,
                })
            }
        }
    }
}

/// Why the gradients could not be finished.
pub(crate) enum FinishError {
    Content(ContentError),
    Frame(FrameError),
}
