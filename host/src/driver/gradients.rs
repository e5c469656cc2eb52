//! Collects a frame's Sobel packets into the gradient data of a [`FeatureFrame`](crate::features::FeatureFrame).
//!
//! Rows mode: one plane per octave, every row exactly once. Patches mode: one 16x16 window
//! per point, matched to its point by `point_index` (a patch may arrive before its point's
//! `PointBatch`: the soft-core cuts a patch as soon as its rows are in, and flushes points in
//! batches), placed on its point's octave pixel.

use stereocal_wire::{
    octave_dims, Point, Record, Records, SobelPatchRepr, SobelPixel, SobelRowsRepr, PATCH_PIXELS,
};

use super::damage::ContentError;
use crate::features::{FeatureError, Gradients, Keypoint, SobelPatch, SobelPlane};

/// Pixels [`split_pixels`] handles per step: a multiple of the SIMD width, and long enough
/// that the per-step slicing is small next to the copying.
const SPLIT_LANES: usize = 32;

/// One octave's plane being filled row by row.
#[derive(Debug)]
pub(crate) struct PlaneBuilder {
    octave: u8,
    scale: u8,
    width: u16,
    height: u16,
    /// The rows up to the furthest one received; grown a row at a time rather than
    /// zero-filled whole up front, since rows come in order and every byte is written anyway.
    magnitude: Vec<u8>,
    /// Same length as `magnitude`.
    orientation: Vec<u8>,
    /// Every orientation code received, ORed together (for [`SobelPlane::with_codes`]).
    codes: u8,
    have_row: Vec<bool>,
    rows: u32,
}

/// Splits wire-format Sobel pixels (magnitude, orientation byte pairs) into `magnitude` and
/// `orientation` and returns their orientation codes ORed together.
///
/// Most of what a host receives is Sobel rows. Reading each pair as a little-endian `u16`
/// into a fixed-size block and splitting that with shifts, with one OR accumulator per lane,
/// compiles to packed loads, shifts and packs; the pair-by-pair loop it replaces (and one
/// with a single scalar OR) did not vectorise.
fn split_pixels(bytes: &[u8], magnitude: &mut [u8], orientation: &mut [u8]) -> u8 {
    let mut lanes = [0u8; SPLIT_LANES];
    let mut mags = magnitude.chunks_exact_mut(SPLIT_LANES);
    let mut oris = orientation.chunks_exact_mut(SPLIT_LANES);
    let mut pairs = bytes.chunks_exact(SPLIT_LANES * SobelPixel::LEN);
    for ((m, o), px) in (&mut mags).zip(&mut oris).zip(&mut pairs) {
        let mut words = [0u16; SPLIT_LANES];
        for (w, pair) in words.iter_mut().zip(px.chunks_exact(SobelPixel::LEN)) {
            if let [magnitude, orientation] = *pair {
                *w = u16::from_le_bytes([magnitude, orientation]);
            }
        }
        for (((m, o), lane), w) in m.iter_mut().zip(o).zip(&mut lanes).zip(words) {
            let [magnitude, orientation] = w.to_le_bytes();
            *m = magnitude;
            *o = orientation;
            *lane |= orientation;
        }
    }
    let mut codes = lanes.iter().fold(0, |ored, &lane| ored | lane);
    let rest = mags.into_remainder().iter_mut().zip(oris.into_remainder());
    for ((m, o), pair) in rest.zip(pairs.remainder().chunks_exact(SobelPixel::LEN)) {
        if let [magnitude, orientation] = *pair {
            *m = magnitude;
            *o = orientation;
            codes |= orientation;
        }
    }
    codes
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
                    magnitude: Vec::with_capacity(n),
                    orientation: Vec::with_capacity(n),
                    codes: 0,
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
        if plane.magnitude.len() < end {
            // The next row (or one past a gap, which a later row fills): zeroing only what
            // the row is about to overwrite is cheap while it is in cache.
            plane.magnitude.resize(end, 0);
            plane.orientation.resize(end, 0);
        }
        let mag = &mut plane.magnitude[start..end];
        let ori = &mut plane.orientation[start..end];
        plane.codes |= match row.pixels {
            Records::Wire(bytes) => split_pixels(bytes, mag, ori),
            Records::Values(pixels) => {
                let mut codes = 0;
                for ((m, o), px) in mag.iter_mut().zip(ori.iter_mut()).zip(pixels) {
                    *m = px.magnitude;
                    *o = px.orientation;
                    codes |= px.orientation;
                }
                codes
            }
        };
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
                    let plane = SobelPlane::with_codes(
                        p.octave,
                        p.width.into(),
                        p.height.into(),
                        p.magnitude,
                        p.orientation,
                        p.codes,
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
    Frame(FeatureError),
}

#[cfg(test)]
mod tests {
    use super::*;
    use stereocal_wire::Camera;

    /// Wire bytes of a `width`-pixel row whose pixel `i` is `(row·7 + i, (row + i) % 64)`.
    fn wire_row(row: u16, width: u16) -> Vec<u8> {
        (0..width)
            .flat_map(|i| [(row * 7 + i) as u8, ((row + i) % 64) as u8])
            .collect()
    }

    fn rows_packet(row: u16, pixels: Records<'_, SobelPixel>) -> SobelRowsRepr<'_> {
        SobelRowsRepr {
            frame_id: 1,
            camera: Camera::Left,
            octave: 0,
            scale: 1,
            row,
            pixels,
        }
    }

    #[test]
    fn rows_in_any_order_split_into_planes() {
        // 37 pixels: one whole block of the split and a tail.
        let (width, height) = (37u16, 4u16);
        let mut builder = GradientBuilder::Empty;
        for row in [2, 0, 3, 1] {
            let bytes = wire_row(row, width);
            let packet = rows_packet(row, Records::Wire(&bytes));
            assert!(builder.add_row(&packet, width, height, 1).is_ok());
        }
        let Ok(finished) = builder.finish(&[], Vec::new()) else {
            panic!("complete plane refused");
        };
        let Gradients::Planes(planes) = finished.gradients else {
            panic!("rows gave patches");
        };
        let bytes: Vec<u8> = (0..height).flat_map(|r| wire_row(r, width)).collect();
        let magnitude: Vec<u8> = bytes.iter().step_by(2).copied().collect();
        let orientation: Vec<u8> = bytes.iter().skip(1).step_by(2).copied().collect();
        assert_eq!(planes[0].magnitude(), magnitude.as_slice());
        assert_eq!(planes[0].orientation(), orientation.as_slice());
    }

    #[test]
    fn wide_orientation_gives_the_planes_error() {
        let (width, height) = (40u16, 2u16);
        let mut builder = GradientBuilder::Empty;
        let good = vec![SobelPixel::default(); usize::from(width)];
        let mut bad = good.clone();
        bad[35].orientation = 64;
        let packets = [
            rows_packet(0, Records::Values(&good)),
            rows_packet(1, Records::Values(&bad)),
        ];
        for packet in &packets {
            assert!(builder.add_row(packet, width, height, 1).is_ok());
        }
        assert!(matches!(
            builder.finish(&[], Vec::new()),
            Err(FinishError::Frame(FeatureError::OrientationRange {
                octave: 0,
                index: 75,
                code: 64
            }))
        ));
    }
}
