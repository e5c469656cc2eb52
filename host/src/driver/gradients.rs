//! Collects a frame's Sobel packets into the gradient data of a [`FeatureFrame`](crate::features::FeatureFrame).
//!
//! Rows mode: one plane per octave, every row exactly once. Patches mode: one 16x16 window
//! per point, matched to its point by `point_index` (a patch may arrive before its point's
//! `PointBatch`: the soft-core cuts a patch as soon as its rows are in, and flushes points in
//! batches), placed on its point's octave pixel.
//!
//! A frame salvaged after link loss keeps the rows it got, with the missing ones marked
//! invalid in its planes (an octave without any row gets an all-invalid plane, since the
//! soft-core sends every row of every octave); its patches are matched to points by index
//! while every point arrived, and by placement once a lost `PointBatch` has shifted the
//! indices of the points after it.

use std::collections::HashMap;

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
    /// Per row, the column after the last segment received (0: none yet). Segments of a row
    /// come left to right, so a segment starting before it repeats pixels.
    row_end: Vec<u16>,
    /// Per row, the pixels received.
    row_pixels: Vec<u16>,
    /// Column ranges `(row, from, to)` skipped between two segments of a row (lost packets).
    gaps: Vec<(u16, u16, u16)>,
    /// Rows received whole.
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
    /// Rows missing per octave (rows mode of a salvaged frame; empty otherwise).
    pub rows_lost: Vec<u32>,
}

/// How [`GradientBuilder::finish`] treats what is missing.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Completeness {
    /// Nothing was lost on the link: every row must be there, and a patch's index is its
    /// point's.
    Intact,
    /// Packets were lost: missing rows of the `octaves` octaves of a `width x height` frame
    /// are marked invalid, and patches are matched by index only when `points_known` (no
    /// point was lost), by placement otherwise.
    Salvaged {
        width: u16,
        height: u16,
        octaves: u8,
        points_known: bool,
    },
}

/// Where a point or patch sits: octave, column, row.
type Placement = (u8, u16, u16);

/// Each placement that occurs exactly once among `items`, with its index.
fn unique_placements(items: impl Iterator<Item = (usize, Placement)>) -> HashMap<Placement, usize> {
    let mut seen: HashMap<Placement, Option<usize>> = HashMap::new();
    for (i, at) in items {
        seen.entry(at).and_modify(|e| *e = None).or_insert(Some(i));
    }
    seen.into_iter()
        .filter_map(|(at, i)| Some((at, i?)))
        .collect()
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
                    row_end: vec![0; usize::from(h)],
                    row_pixels: vec![0; usize::from(h)],
                    gaps: Vec::new(),
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
        let (x, n) = (usize::from(row.x), row.pixels.len());
        if n == 0 || x + n > usize::from(plane.width) {
            return Err(ContentError::RowWidth {
                octave: row.octave,
                x: row.x,
                width: n.min(usize::from(u16::MAX)) as u16,
                expected: plane.width,
            });
        }
        let r = usize::from(row.row);
        let (Some(end), Some(received)) = (plane.row_end.get_mut(r), plane.row_pixels.get_mut(r))
        else {
            return Err(ContentError::RowOutside {
                octave: row.octave,
                row: row.row,
                height: plane.height,
            });
        };
        if x < usize::from(*end) {
            return Err(ContentError::DuplicateRow {
                octave: row.octave,
                row: row.row,
                x: row.x,
            });
        }
        if x > usize::from(*end) {
            plane.gaps.push((row.row, *end, row.x));
        }
        // `x + n <= width`, a u16.
        *end = (x + n) as u16;
        *received += n as u16;
        plane.rows += u32::from(*received == plane.width);
        let row_start = r * usize::from(plane.width);
        if plane.magnitude.len() < row_start + usize::from(plane.width) {
            // The next row (or one past a gap, which a later row fills): zeroing only what
            // the row is about to overwrite is cheap while it is in cache.
            plane
                .magnitude
                .resize(row_start + usize::from(plane.width), 0);
            plane
                .orientation
                .resize(row_start + usize::from(plane.width), 0);
        }
        let (start, end) = (row_start + x, row_start + x + n);
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
        completeness: Completeness,
    ) -> Result<Finished, FinishError> {
        match self {
            Self::Empty => Ok(Finished {
                keypoints,
                gradients: Gradients::Planes(Vec::new()),
                without_patch: 0,
                rows_lost: Vec::new(),
            }),
            Self::Rows(planes) => {
                let (gradients, rows_lost) = finish_planes(planes, completeness)?;
                Ok(Finished {
                    keypoints,
                    gradients,
                    without_patch: 0,
                    rows_lost,
                })
            }
            Self::Patches(mut entries) => {
                let points_known = match completeness {
                    Completeness::Intact => true,
                    Completeness::Salvaged { points_known, .. } => points_known,
                };
                if !points_known {
                    return Ok(finish_by_placement(points, keypoints, entries));
                }
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
                    rows_lost: Vec::new(),
                })
            }
        }
    }
}

/// The planes of a rows-mode frame and the rows each octave lacks. An intact frame must have
/// every row; a salvaged one gets its missing rows (and octaves) marked invalid.
fn finish_planes(
    planes: Vec<PlaneBuilder>,
    completeness: Completeness,
) -> Result<(Gradients, Vec<u32>), FinishError> {
    let mut out = Vec::with_capacity(planes.len());
    let mut rows_lost = Vec::new();
    for p in planes {
        let lost = u32::from(p.height) - p.rows;
        if lost > 0 && matches!(completeness, Completeness::Intact) {
            return Err(FinishError::Content(ContentError::IncompletePlane {
                octave: p.octave,
                received: p.rows,
                rows: p.height,
            }));
        }
        let (mut magnitude, mut orientation) = (p.magnitude, p.orientation);
        let n = usize::from(p.width) * usize::from(p.height);
        magnitude.resize(n, 0);
        orientation.resize(n, 0);
        let plane = SobelPlane::with_codes(
            p.octave,
            p.width.into(),
            p.height.into(),
            magnitude,
            orientation,
            p.codes,
        )
        .map_err(FinishError::Frame)?;
        let plane = if lost > 0 {
            plane.with_valid(valid_pixels(p.width, &p.row_end, &p.gaps))
        } else {
            plane
        };
        out.push(plane);
        note_lost(&mut rows_lost, p.octave, lost);
    }
    if let Completeness::Salvaged {
        width,
        height,
        octaves,
        ..
    } = completeness
    {
        let missing: Vec<u8> = (0..octaves)
            .filter(|&o| !out.iter().any(|p| p.octave() == o))
            .collect();
        for octave in missing {
            let (w, h) = octave_dims(width, height, octave);
            let n = usize::from(w) * usize::from(h);
            let plane =
                SobelPlane::with_codes(octave, w.into(), h.into(), vec![0; n], vec![0; n], 0)
                    .map_err(FinishError::Frame)?;
            out.push(plane.with_valid(Vec::new()));
            note_lost(&mut rows_lost, octave, u32::from(h));
        }
    }
    Ok((Gradients::Planes(out), rows_lost))
}

/// The received pixels of a `width`-wide plane, row-major: each row up to `row_end`, less the
/// `gaps` between its segments.
fn valid_pixels(width: u16, row_end: &[u16], gaps: &[(u16, u16, u16)]) -> Vec<bool> {
    let w = usize::from(width);
    let mut valid = vec![false; w * row_end.len()];
    for (r, &end) in row_end.iter().enumerate() {
        valid[r * w..r * w + usize::from(end)].fill(true);
    }
    for &(r, from, to) in gaps {
        let row = usize::from(r) * w;
        valid[row + usize::from(from)..row + usize::from(to)].fill(false);
    }
    valid
}

/// Records `lost` rows of `octave` in the per-octave list.
fn note_lost(rows_lost: &mut Vec<u32>, octave: u8, lost: u32) {
    let i = usize::from(octave);
    if rows_lost.len() <= i {
        rows_lost.resize(i + 1, 0);
    }
    rows_lost[i] += lost;
}

/// Pairs patches with points by placement, for a frame that lost points (a patch's
/// `point_index` counts the lost ones too). A placement shared by two points or two patches
/// is ambiguous, and its points go without a patch.
fn finish_by_placement(
    points: &[Point],
    keypoints: Vec<Keypoint>,
    entries: Vec<Option<PatchEntry>>,
) -> Finished {
    let at_point = unique_placements(
        points
            .iter()
            .enumerate()
            .map(|(i, p)| (i, (p.octave, p.x, p.y))),
    );
    let at_patch = unique_placements(
        entries
            .iter()
            .enumerate()
            .filter_map(|(i, e)| e.as_ref().map(|e| (i, (e.octave, e.x, e.y)))),
    );
    let mut entries = entries;
    let mut kept = Vec::with_capacity(points.len());
    let mut patches = Vec::with_capacity(points.len());
    for (i, (p, k)) in points.iter().zip(keypoints).enumerate() {
        let at = (p.octave, p.x, p.y);
        if at_point.get(&at) != Some(&i) {
            continue;
        }
        let Some(entry) = at_patch.get(&at).and_then(|&j| entries.get_mut(j)?.take()) else {
            continue;
        };
        kept.push(k);
        patches.push(entry.patch);
    }
    Finished {
        without_patch: (points.len() - kept.len()) as u32,
        keypoints: kept,
        gradients: Gradients::Patches(patches),
        rows_lost: Vec::new(),
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
            x: 0,
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
        let Ok(finished) = builder.finish(&[], Vec::new(), Completeness::Intact) else {
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
            builder.finish(&[], Vec::new(), Completeness::Intact),
            Err(FinishError::Frame(FeatureError::OrientationRange {
                octave: 0,
                index: 75,
                code: 64
            }))
        ));
    }
}
