//! The features of one camera frame as the host holds them after reassembling the wire packets.
//!
//! Coordinates: keypoints are in full-resolution pixels (x right, y down, pixel centres at
//! integers). Pixel `(i, j)` of octave `o` sits at full-resolution `(i·2ᵒ, j·2ᵒ)`: each octave
//! keeps the even pixels of the previous one.
//!
//! Gradients come in one of two forms, matching the two transfer modes of the soft-core:
//! the full Sobel planes of every octave ("full rows", most data, allows sub-pixel match
//! refinement on octave 0), or one 16×16 window per keypoint ("patches").
//! Orientation is the fabric's 6-bit CORDIC angle: `k · 360/64°` measured from +x toward +y
//! (image down), i.e. `atan2(gy, gx)`; magnitude is the fabric's 8-bit `x_n·5/8`.

/// Side length of the gradient window the descriptor is built from: the thesis' 16x16 window
/// (4.4.2, after Lowe), which is also what a `SobelPatch` carries.
pub const PATCH_SIZE: usize = stereocal_wire::PATCH_SIZE;
/// Number of orientation codes of the fabric (6 bits).
pub const ORIENTATION_STEPS: u8 = 64;

/// Why a camera frame's features could not be assembled.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FeatureError {
    /// A Sobel plane's magnitude or orientation samples do not number `width·height`.
    #[error(
        "Sobel plane of octave {octave}: {len} magnitude/orientation samples for {width}x{height}"
    )]
    PlaneSize {
        /// The plane's octave.
        octave: u8,
        /// The plane's width in octave pixels.
        width: u32,
        /// The plane's height in octave pixels.
        height: u32,
        /// Samples given: the shorter of the magnitude and orientation vectors.
        len: usize,
    },
    /// An orientation code of 64 or more: the fabric's codes have 6 bits.
    #[error(
        "Sobel plane of octave {octave}: orientation code {code} at index {index} is not 6-bit"
    )]
    OrientationRange {
        /// The plane's octave.
        octave: u8,
        /// Row-major index of the first such sample.
        index: usize,
        /// Its code.
        code: u8,
    },
    /// Patch gradients that are not one per keypoint.
    #[error("{patches} gradient patches for {keypoints} keypoints")]
    PatchCount {
        /// Patches given.
        patches: usize,
        /// Keypoints given.
        keypoints: usize,
    },
    /// A keypoint that is not finite or lies outside the image (more than half a pixel
    /// beyond the outer pixel centres).
    #[error("keypoint {index}: coordinates ({x}, {y}) are not finite or outside {width}x{height}")]
    KeypointPosition {
        /// Index of the keypoint in the frame.
        index: usize,
        /// Its full-resolution x in pixels.
        x: f32,
        /// Its full-resolution y in pixels.
        y: f32,
        /// Image width in full-resolution pixels.
        width: u32,
        /// Image height in full-resolution pixels.
        height: u32,
    },
}

/// One DoG extremum.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Keypoint {
    /// Full-resolution x, including the octave scaling and the sub-pixel offset.
    pub x: f32,
    /// Full-resolution y, including the octave scaling and the sub-pixel offset.
    pub y: f32,
    /// Pyramid octave (0 = full resolution).
    pub octave: u8,
    /// Scale index within the octave, with its sub-scale offset.
    pub scale: f32,
    /// DoG response at the extremum (contrast).
    pub dog: f32,
}

impl Keypoint {
    /// Position in the pixel grid of the keypoint's own octave.
    pub fn octave_position(&self) -> (f32, f32) {
        let s = (1u32 << self.octave.min(31)) as f32;
        (self.x / s, self.y / s)
    }
}

/// Sobel magnitude and orientation of one octave, row-major.
///
/// A plane salvaged from a damaged camera frame lacks the pixels whose packets (rows or row
/// segments) the link lost: their samples are 0 and [`Self::valid`] says so, and everything
/// that reads a window of the plane (descriptor windows, sub-pixel windows) skips a window
/// touching such a pixel, so a lost packet costs the keypoints around it and never feeds
/// made-up gradients onward.
#[derive(Debug, Clone, PartialEq)]
pub struct SobelPlane {
    octave: u8,
    width: u32,
    height: u32,
    magnitude: Vec<u8>,
    orientation: Vec<u8>,
    /// One flag per pixel, row-major; `None` when every pixel is valid (an intact frame).
    valid: Option<Vec<bool>>,
}

impl SobelPlane {
    /// Checks the sizes and that every orientation is a 6-bit code.
    pub fn new(
        octave: u8,
        width: u32,
        height: u32,
        magnitude: Vec<u8>,
        orientation: Vec<u8>,
    ) -> Result<Self, FeatureError> {
        // One branch-free OR over the plane (it vectorises), where searching for the first
        // bad code took a compare and branch per pixel; the search only runs on a bad plane.
        let codes = orientation.iter().fold(0, |ored, &code| ored | code);
        Self::with_codes(octave, width, height, magnitude, orientation, codes)
    }

    /// [`Self::new`] for a caller that ORed every orientation code together (`codes`) while
    /// writing the plane: the driver does so in the pass that splits the received pixels, so
    /// a valid plane is not read a second time. A code of 64 or more sets a bit of `codes`
    /// at or above [`ORIENTATION_STEPS`]; then the plane is searched for the first one, and
    /// the error is the one [`Self::new`] gives.
    pub(crate) fn with_codes(
        octave: u8,
        width: u32,
        height: u32,
        magnitude: Vec<u8>,
        orientation: Vec<u8>,
        codes: u8,
    ) -> Result<Self, FeatureError> {
        let n = width as usize * height as usize;
        if magnitude.len() != n || orientation.len() != n {
            return Err(FeatureError::PlaneSize {
                octave,
                width,
                height,
                len: magnitude.len().min(orientation.len()),
            });
        }
        if codes >= ORIENTATION_STEPS {
            if let Some((index, &code)) = orientation
                .iter()
                .enumerate()
                .find(|(_, &c)| c >= ORIENTATION_STEPS)
            {
                return Err(FeatureError::OrientationRange {
                    octave,
                    index,
                    code,
                });
            }
        }
        Ok(Self {
            octave,
            width,
            height,
            magnitude,
            orientation,
            valid: None,
        })
    }

    /// The plane with only the pixels whose flag in `valid` is set marked valid (`valid`
    /// holds one flag per pixel, row-major; pixels beyond it are invalid).
    pub fn with_valid(mut self, mut valid: Vec<bool>) -> Self {
        valid.resize(self.magnitude.len(), false);
        self.valid = (!valid.iter().all(|&v| v)).then_some(valid);
        self
    }

    /// Whether pixel `(x, y)` holds received gradients (false outside the plane).
    pub fn valid(&self, x: i64, y: i64) -> bool {
        if x < 0 || y < 0 || x >= i64::from(self.width) || y >= i64::from(self.height) {
            return false;
        }
        let i = y as usize * self.width as usize + x as usize;
        self.valid
            .as_ref()
            .is_none_or(|v| v.get(i).copied().unwrap_or(false))
    }

    /// Whether every pixel of the window `xs` x `ys` that lies inside the plane is valid;
    /// pixels outside the plane are the callers' border checks, not lost data.
    pub fn window_valid(&self, xs: std::ops::Range<i64>, ys: std::ops::Range<i64>) -> bool {
        let Some(valid) = &self.valid else {
            return true;
        };
        let (w, h) = (i64::from(self.width), i64::from(self.height));
        let (x0, x1) = (xs.start.clamp(0, w) as usize, xs.end.clamp(0, w) as usize);
        let (y0, y1) = (ys.start.clamp(0, h) as usize, ys.end.clamp(0, h) as usize);
        (y0..y1).all(|y| {
            let row = y * w as usize;
            valid
                .get(row + x0..row + x1)
                .is_none_or(|v| v.iter().all(|&v| v))
        })
    }

    /// Pixels without received gradients (0 for an intact plane).
    pub fn lost_pixels(&self) -> usize {
        self.valid
            .as_ref()
            .map_or(0, |v| v.iter().filter(|&&v| !v).count())
    }

    /// Pyramid octave of the plane (0 = full resolution).
    pub fn octave(&self) -> u8 {
        self.octave
    }
    /// Width in pixels of the plane's octave.
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Height in pixels of the plane's octave.
    pub fn height(&self) -> u32 {
        self.height
    }
    /// Gradient magnitudes, row-major: the fabric's 8-bit `x_n·5/8`.
    pub fn magnitude(&self) -> &[u8] {
        &self.magnitude
    }
    /// Gradient orientations, row-major: 6-bit codes `k`, angle `k·360/64°` from +x toward +y.
    pub fn orientation(&self) -> &[u8] {
        &self.orientation
    }

    /// `(magnitude, orientation)` at integer octave coordinates, `None` outside or on a
    /// lost pixel.
    pub fn get(&self, x: i32, y: i32) -> Option<(u8, u8)> {
        if !self.valid(x.into(), y.into()) {
            return None;
        }
        let i = y as usize * self.width as usize + x as usize;
        Some((self.magnitude[i], self.orientation[i]))
    }
}

/// The 16×16 gradient window around one keypoint at the keypoint's octave, row-major.
/// Element `(r, c)` is octave pixel `(cx - 8 + c, cy - 8 + r)` with `(cx, cy)` the keypoint's
/// octave position rounded to the nearest pixel. Samples outside the image are 0.
#[derive(Debug, Clone, PartialEq)]
pub struct SobelPatch {
    /// Gradient magnitudes, the fabric's 8-bit `x_n·5/8`.
    pub magnitude: [u8; PATCH_SIZE * PATCH_SIZE],
    /// Gradient orientations, 6-bit codes `k`, angle `k·360/64°` from +x toward +y.
    pub orientation: [u8; PATCH_SIZE * PATCH_SIZE],
}

/// The gradient data that came with a frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Gradients {
    /// One plane per octave (any order; looked up by octave).
    Planes(Vec<SobelPlane>),
    /// One patch per keypoint, index-aligned with `FeatureFrame::keypoints`.
    Patches(Vec<SobelPatch>),
}

/// Everything the host knows about one camera frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureFrame {
    /// Frame counter from the link.
    pub index: u64,
    /// Capture time in microseconds (drives the Kalman prediction).
    pub timestamp_us: u64,
    /// Full-resolution image width in pixels.
    pub width: u32,
    /// Full-resolution image height in pixels.
    pub height: u32,
    keypoints: Vec<Keypoint>,
    gradients: Gradients,
}

impl FeatureFrame {
    /// Validates keypoint positions and the gradient/keypoint pairing.
    pub fn new(
        index: u64,
        timestamp_us: u64,
        width: u32,
        height: u32,
        keypoints: Vec<Keypoint>,
        gradients: Gradients,
    ) -> Result<Self, FeatureError> {
        if let Gradients::Patches(p) = &gradients {
            if p.len() != keypoints.len() {
                return Err(FeatureError::PatchCount {
                    patches: p.len(),
                    keypoints: keypoints.len(),
                });
            }
        }
        for (i, k) in keypoints.iter().enumerate() {
            let inside = k.x.is_finite()
                && k.y.is_finite()
                && k.x >= -0.5
                && k.y >= -0.5
                && k.x <= width as f32 - 0.5
                && k.y <= height as f32 - 0.5;
            if !inside {
                return Err(FeatureError::KeypointPosition {
                    index: i,
                    x: k.x,
                    y: k.y,
                    width,
                    height,
                });
            }
        }
        Ok(Self {
            index,
            timestamp_us,
            width,
            height,
            keypoints,
            gradients,
        })
    }

    /// The keypoints in the order the device sent them; [`Gradients::Patches`] and
    /// descriptor indices refer to this order.
    pub fn keypoints(&self) -> &[Keypoint] {
        &self.keypoints
    }

    /// The Sobel planes or patches that came with the frame.
    pub fn gradients(&self) -> &Gradients {
        &self.gradients
    }

    /// The Sobel plane of `octave`, when the frame carries planes.
    pub fn plane(&self, octave: u8) -> Option<&SobelPlane> {
        match &self.gradients {
            Gradients::Planes(p) => p.iter().find(|p| p.octave == octave),
            Gradients::Patches(_) => None,
        }
    }

    /// Keypoints the link's lost pixels cost the estimate: those whose 16×16 gradient window
    /// touches a lost pixel of its octave's plane (the descriptor skips it), and, with
    /// `refinement_reach` (`SubpixelConfig::reach_px`), those with a lost pixel within that
    /// many of their nearest full-resolution pixel (the sub-pixel refinement of a match there
    /// fails). A keypoint of a coarser octave keeps its descriptor when a full-resolution row
    /// goes, but not its refinement. 0 for an intact frame, and in patches mode, where a lost
    /// patch is a missing keypoint instead.
    pub fn keypoints_on_lost_pixels(&self, refinement_reach: Option<usize>) -> usize {
        let Gradients::Planes(_) = &self.gradients else {
            return 0;
        };
        let half = (PATCH_SIZE / 2) as i64;
        let reach = refinement_reach.map(|r| i64::try_from(r).unwrap_or(i64::MAX / 4));
        self.keypoints
            .iter()
            .filter(|kp| {
                let descriptor_lost = self.plane(kp.octave).is_some_and(|plane| {
                    let (ox, oy) = kp.octave_position();
                    let (x0, y0) = (ox.round() as i64 - half, oy.round() as i64 - half);
                    let side = PATCH_SIZE as i64;
                    !plane.window_valid(x0..x0 + side, y0..y0 + side)
                });
                let refinement_lost = reach.zip(self.plane(0)).is_some_and(|(r, plane)| {
                    let (x, y) = (kp.x.round() as i64, kp.y.round() as i64);
                    !plane.window_valid(x - r..x + r + 1, y - r..y + r + 1)
                });
                descriptor_lost || refinement_lost
            })
            .count()
    }

    /// Copies the 16×16 gradient window of keypoint `k` into `out` (row-major, the
    /// [`SobelPatch`] layout; unavailable samples are `(0, 0)`) and returns how many samples
    /// were available: none when the window touches a lost row of its plane, since a
    /// descriptor from part of a window differs from the whole window's.
    pub fn window(&self, k: usize, out: &mut [(u8, u8); PATCH_SIZE * PATCH_SIZE]) -> usize {
        out.fill((0, 0));
        let Some(kp) = self.keypoints.get(k) else {
            return 0;
        };
        match &self.gradients {
            Gradients::Patches(p) => match p.get(k) {
                Some(patch) => {
                    for (o, (&m, &a)) in out
                        .iter_mut()
                        .zip(patch.magnitude.iter().zip(patch.orientation.iter()))
                    {
                        *o = (m, a);
                    }
                    PATCH_SIZE * PATCH_SIZE
                }
                None => 0,
            },
            Gradients::Planes(_) => {
                let Some(plane) = self.plane(kp.octave) else {
                    return 0;
                };
                let (ox, oy) = kp.octave_position();
                let half = (PATCH_SIZE / 2) as i64;
                let (x0, y0) = (ox.round() as i64 - half, oy.round() as i64 - half);
                let side = PATCH_SIZE as i64;
                if !plane.window_valid(x0..x0 + side, y0..y0 + side) {
                    return 0;
                }
                let (w, h) = (plane.width as i64, plane.height as i64);
                let xa = x0.max(0);
                let xb = (x0 + PATCH_SIZE as i64).min(w);
                if xa >= xb {
                    return 0;
                }
                let mut count = 0;
                for r in 0..PATCH_SIZE as i64 {
                    let y = y0 + r;
                    if y < 0 || y >= h {
                        continue;
                    }
                    let row = (y * w) as usize;
                    let mags = &plane.magnitude[row + xa as usize..row + xb as usize];
                    let oris = &plane.orientation[row + xa as usize..row + xb as usize];
                    let dst = &mut out[(r as usize * PATCH_SIZE + (xa - x0) as usize)..];
                    for (d, (&m, &a)) in dst.iter_mut().zip(mags.iter().zip(oris)) {
                        *d = (m, a);
                    }
                    count += (xb - xa) as usize;
                }
                count
            }
        }
    }

    /// `(magnitude, orientation)` of the gradient window of keypoint `k` at window offset
    /// `(dx, dy)` ∈ [-8, 8)² from its rounded octave position; `None` when unavailable.
    pub fn window_sample(&self, k: usize, dx: i32, dy: i32) -> Option<(u8, u8)> {
        let kp = self.keypoints.get(k)?;
        match &self.gradients {
            Gradients::Patches(p) => {
                let half = (PATCH_SIZE / 2) as i32;
                let (c, r) = (dx + half, dy + half);
                if !(0..PATCH_SIZE as i32).contains(&c) || !(0..PATCH_SIZE as i32).contains(&r) {
                    return None;
                }
                let i = r as usize * PATCH_SIZE + c as usize;
                let patch = p.get(k)?;
                Some((patch.magnitude[i], patch.orientation[i]))
            }
            Gradients::Planes(_) => {
                let plane = self.plane(kp.octave)?;
                let (ox, oy) = kp.octave_position();
                plane.get(ox.round() as i32 + dx, oy.round() as i32 + dy)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kp(x: f32, y: f32, octave: u8) -> Keypoint {
        Keypoint {
            x,
            y,
            octave,
            scale: 1.0,
            dog: 10.0,
        }
    }

    #[test]
    fn plane_sizes_and_codes_are_checked() {
        assert!(matches!(
            SobelPlane::new(0, 4, 4, vec![0; 15], vec![0; 16]),
            Err(FeatureError::PlaneSize { .. })
        ));
        assert!(matches!(
            SobelPlane::new(1, 2, 2, vec![0; 4], vec![0, 1, 64, 3]),
            Err(FeatureError::OrientationRange {
                index: 2,
                code: 64,
                ..
            })
        ));
        let p = SobelPlane::new(0, 2, 2, vec![1, 2, 3, 4], vec![0, 1, 2, 63]).unwrap();
        assert_eq!(p.get(1, 1), Some((4, 63)));
        assert_eq!(p.get(2, 0), None);
        assert_eq!(p.get(-1, 0), None);
    }

    #[test]
    fn frame_checks_keypoints_and_patches() {
        let patch = SobelPatch {
            magnitude: [0; 256],
            orientation: [0; 256],
        };
        let err = FeatureFrame::new(
            0,
            0,
            10,
            10,
            vec![kp(1.0, 1.0, 0)],
            Gradients::Patches(vec![]),
        );
        assert!(matches!(err, Err(FeatureError::PatchCount { .. })));
        let err = FeatureFrame::new(
            0,
            0,
            10,
            10,
            vec![kp(f32::NAN, 1.0, 0)],
            Gradients::Planes(vec![]),
        );
        assert!(matches!(
            err,
            Err(FeatureError::KeypointPosition { index: 0, .. })
        ));
        let f = FeatureFrame::new(
            0,
            0,
            10,
            10,
            vec![kp(3.0, 4.0, 0)],
            Gradients::Patches(vec![patch]),
        )
        .unwrap();
        assert_eq!(f.window_sample(0, -8, -8), Some((0, 0)));
        assert_eq!(f.window_sample(0, 8, 0), None);
    }

    #[test]
    fn plane_windows_follow_the_octave_scaling() {
        // Octave 1 plane of a 8x8 image is 4x4; full-res (4, 2) is octave pixel (2, 1).
        let mag: Vec<u8> = (0..16).collect();
        let plane = SobelPlane::new(1, 4, 4, mag, vec![0; 16]).unwrap();
        let f = FeatureFrame::new(
            0,
            0,
            8,
            8,
            vec![kp(4.0, 2.0, 1)],
            Gradients::Planes(vec![plane]),
        )
        .unwrap();
        assert_eq!(f.window_sample(0, 0, 0), Some((6, 0)));
        assert_eq!(f.window_sample(0, 1, 1), Some((11, 0)));
        let mut win = [(0u8, 0u8); 256];
        // Window rows -8..8 around octave pixel (2, 1): only the 4x4 plane is inside.
        assert_eq!(f.window(0, &mut win), 16);
        for dy in -8..8 {
            for dx in -8..8 {
                let i = ((dy + 8) * 16 + dx + 8) as usize;
                assert_eq!(
                    Some(win[i]).filter(|_| f.window_sample(0, dx, dy).is_some()),
                    f.window_sample(0, dx, dy)
                );
            }
        }
        assert!(f.plane(0).is_none());
    }
}
