//! Ray casting one camera image of a [`Scene`], exactly through the pinhole model.
//!
//! Every sample is a ray through an exact sub-pixel position; the nearest hit among the ground
//! plane and the boxes decides what is seen, so occlusion and projection are exact and only the
//! pixel integration is sampled. To keep a 640x480 image within a few tens of milliseconds the
//! integration is adaptive: one ray per pixel centre, with textures prefiltered over the pixel
//! footprint (mip maps), and an `n`x`n` stratified grid wherever a pixel's centre sample
//! differs from a 4-neighbour in the surface it hit or in the pattern region on it (window or
//! wall, marking or asphalt), i.e. on geometric and pattern edges, where prefiltering cannot
//! help.
//!
//! Candidate boxes are binned per 16x16-pixel tile from their exact projected bounding boxes
//! (boxes straddling the camera plane go to every tile) and sorted by their nearest depth so a
//! ray stops testing once the next box cannot be nearer than its current hit.

use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::camera::CameraPose;
use crate::scene::Scene;

/// How the light over a pixel is integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Supersampling {
    /// One prefiltered sample per pixel, `edge`x`edge` stratified samples on edges.
    Adaptive { edge: u8 },
    /// `per_axis`x`per_axis` stratified samples in every pixel (slow; a reference).
    Uniform { per_axis: u8 },
}

impl Default for Supersampling {
    fn default() -> Self {
        Supersampling::Adaptive { edge: 4 }
    }
}

/// Motion blur: the image integrates the scene over `exposure_s` centred on the frame time,
/// with `per_axis`x`per_axis` stratified samples per pixel, each at its own instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionBlur {
    pub exposure_s: f64,
    pub per_axis: u8,
}

/// Tile size of the candidate bins (pixels).
const TILE: usize = 16;
/// Boxes whose nearest point is farther than this are not drawn (1 m there is ~1 pixel).
pub(crate) const DRAW_DISTANCE_M: f64 = 600.0;
/// Shading of the six box faces (−x, +x, −y, +y, −z, +z outward normals): a light from above,
/// slightly from the left and behind the head.
const FACE_SHADE: [f32; 6] = [0.78, 0.92, 1.0, 0.45, 0.86, 0.66];
/// The ground is lit like a box top.
const GROUND_SHADE: f32 = 1.0;

/// Where the image rows come from: output row `r` is frame row `r * step + offset`
/// (`step` 2 for an interlaced field).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct RowMap {
    pub step: u32,
    pub offset: u32,
}

/// Everything `render` needs besides the scene and the camera.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RenderSpec {
    /// Frame size (full frame, even when rendering a field).
    pub width: u32,
    pub height: u32,
    pub rows: RowMap,
    pub supersampling: Supersampling,
    /// Standard deviation of the sensor noise in grey levels (0 = none).
    pub noise_sigma: f32,
    pub noise_seed: u64,
}

/// What a sample ray hit: `id` names the surface (sky 0, ground 1, box face `2 + 6 box + face`)
/// and, in its low 3 bits, the pattern region on it, so that edges between surfaces and
/// pattern edges (windows, markings) can be found.
#[derive(Debug, Clone, Copy)]
struct Sample {
    id: u32,
    value: f32,
}

/// A candidate box as a tile stores it: the depth below which it cannot be hit and its bounds
/// inline, so the intersection loop walks one contiguous list instead of the scene's boxes.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    near: f64,
    min: [f64; 3],
    max: [f64; 3],
    index: u32,
}

/// The candidate boxes of every tile, nearest first.
struct Bins {
    tiles_x: usize,
    tiles_y: usize,
    tiles: Vec<Vec<Candidate>>,
}

impl Bins {
    /// Bins for rays of all `poses` (the instants of a motion-blurred exposure share bins).
    fn new(scene: &Scene, poses: &[CameraPose], width: u32, height: u32) -> Self {
        let tiles_x = (width as usize).div_ceil(TILE);
        let tiles_y = (height as usize).div_ceil(TILE);
        let mut tiles: Vec<Vec<Candidate>> = vec![Vec::new(); tiles_x * tiles_y];
        for (index, b) in scene.boxes.iter().enumerate() {
            let mut near = f64::INFINITY;
            let mut straddles = false;
            let mut behind = true;
            let (mut u0, mut u1, mut v0, mut v1) = (
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
            );
            for pose in poses {
                for corner in 0..8 {
                    let p = Vector3::new(
                        if corner & 1 == 0 { b.min[0] } else { b.max[0] },
                        if corner & 2 == 0 { b.min[1] } else { b.max[1] },
                        if corner & 4 == 0 { b.min[2] } else { b.max[2] },
                    );
                    let c = pose.to_camera(&p);
                    near = near.min(c.z);
                    if c.z <= 1e-6 {
                        straddles = true;
                        continue;
                    }
                    behind = false;
                    let k = &pose.intrinsics;
                    let (u, v) = (k.fx * c.x / c.z + k.cx, k.fy * c.y / c.z + k.cy);
                    u0 = u0.min(u);
                    u1 = u1.max(u);
                    v0 = v0.min(v);
                    v1 = v1.max(v);
                }
            }
            // Entirely behind every camera plane: no forward ray reaches it.
            if behind || near > DRAW_DISTANCE_M {
                continue;
            }
            let item = Candidate {
                near: near.max(0.0),
                min: b.min,
                max: b.max,
                index: index as u32,
            };
            let (tx0, tx1, ty0, ty1) = if straddles {
                (0, tiles_x - 1, 0, tiles_y - 1)
            } else {
                // Pixel i holds samples in [i - 0.5, i + 0.5]; one pixel of margin.
                let range = |lo: f64, hi: f64, n: usize| -> Option<(usize, usize)> {
                    let first = (lo - 1.5).ceil();
                    let last = (hi + 1.5).floor();
                    let max = (n * TILE - 1) as f64;
                    if last < 0.0 || first > max {
                        return None;
                    }
                    let first = first.max(0.0) as usize / TILE;
                    let last = last.min(max) as usize / TILE;
                    Some((first, last.min(n - 1)))
                };
                let (Some((tx0, tx1)), Some((ty0, ty1))) =
                    (range(u0, u1, tiles_x), range(v0, v1, tiles_y))
                else {
                    continue;
                };
                (tx0, tx1, ty0, ty1)
            };
            for ty in ty0..=ty1 {
                for tx in tx0..=tx1 {
                    tiles[ty * tiles_x + tx].push(item);
                }
            }
        }
        for list in &mut tiles {
            list.sort_by(|a, b| a.near.total_cmp(&b.near));
        }
        Bins {
            tiles_x,
            tiles_y,
            tiles,
        }
    }

    fn at(&self, u: f64, v: f64) -> &[Candidate] {
        // Sample positions lie within the frame's pixel grid; clamp guards the margins.
        let tx = ((u + 0.5).max(0.0) as usize / TILE).min(self.tiles_x - 1);
        let ty = ((v + 0.5).max(0.0) as usize / TILE).min(self.tiles_y - 1);
        &self.tiles[ty * self.tiles_x + tx]
    }
}

/// One camera image at the instants `poses` (one pose, or one per motion-blur sample).
pub(crate) fn render(scene: &Scene, poses: &[CameraPose], spec: &RenderSpec) -> Vec<u8> {
    let bins = Bins::new(scene, poses, spec.width, spec.height);
    let tracer = Tracer { scene, bins: &bins };
    let w = spec.width as usize;
    let out_h = (spec.height / spec.rows.step) as usize;
    let frame_v = |r: usize| f64::from(spec.rows.offset) + (r * spec.rows.step as usize) as f64;
    let mut pixels = vec![0u8; w * out_h];
    match spec.supersampling {
        Supersampling::Adaptive { edge } if poses.len() == 1 => {
            let pose = &poses[0];
            let mut centres = vec![Sample { id: 0, value: 0.0 }; w * out_h];
            centres.par_chunks_mut(w).enumerate().for_each(|(r, row)| {
                let v = frame_v(r);
                for (i, s) in row.iter_mut().enumerate() {
                    *s = tracer.sample(pose, i as f64, v, 1.0);
                }
            });
            pixels.par_chunks_mut(w).enumerate().for_each(|(r, row)| {
                let mut noise = Noise::new(spec, r);
                let v = frame_v(r);
                for (i, px) in row.iter_mut().enumerate() {
                    let c = centres[r * w + i];
                    let differs = |n: &Sample| n.id != c.id;
                    let on_edge = (i > 0 && differs(&centres[r * w + i - 1]))
                        || (i + 1 < w && differs(&centres[r * w + i + 1]))
                        || (r > 0 && differs(&centres[(r - 1) * w + i]))
                        || (r + 1 < out_h && differs(&centres[(r + 1) * w + i]));
                    let value = if on_edge {
                        tracer.stratified(std::slice::from_ref(pose), i as f64, v, edge)
                    } else {
                        c.value
                    };
                    *px = noise.quantize(value);
                }
            });
        }
        Supersampling::Adaptive { edge: n } | Supersampling::Uniform { per_axis: n } => {
            pixels.par_chunks_mut(w).enumerate().for_each(|(r, row)| {
                let mut noise = Noise::new(spec, r);
                let v = frame_v(r);
                for (i, px) in row.iter_mut().enumerate() {
                    *px = noise.quantize(tracer.stratified(poses, i as f64, v, n));
                }
            });
        }
    }
    pixels
}

struct Tracer<'a> {
    scene: &'a Scene,
    bins: &'a Bins,
}

impl Tracer<'_> {
    /// The mean of `n`x`n` samples over pixel (`u`, `v`): one per cell of an `n`x`n` grid
    /// and, inside the cells, offset so that all `n²` samples have distinct columns and rows
    /// (the canonical multi-jittered arrangement). A plain grid would measure a near-vertical
    /// edge's coverage only to 1/n of a pixel, always rounding the same way (a bias of up to
    /// 1/(2n) px in the edge position); this one resolves 1/n². With several poses each sample
    /// takes its instant from a fixed permutation, so time and position decorrelate.
    fn stratified(&self, poses: &[CameraPose], u: f64, v: f64, n: u8) -> f32 {
        let n = usize::from(n.max(1));
        let nn = (n * n) as f64;
        let mut sum = 0.0f32;
        for k in 0..n * n {
            let (sx, sy) = (k % n, k / n);
            let pose = &poses[(k * 11 + 3) % poses.len()];
            let su = u - 0.5 + ((sx * n + sy) as f64 + 0.5) / nn;
            let sv = v - 0.5 + ((sy * n + sx) as f64 + 0.5) / nn;
            sum += self.sample(pose, su, sv, 1.0 / n as f64).value;
        }
        sum / (n * n) as f32
    }

    /// One ray through pixel coordinate (`u`, `v`), textures filtered over `spacing` pixels.
    fn sample(&self, pose: &CameraPose, u: f64, v: f64, spacing: f64) -> Sample {
        let o = pose.center;
        let d = pose.ray(u, v);
        let inv = Vector3::new(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
        // Nearest hit: (depth, id, box index, entry axis).
        let mut best_t = f64::INFINITY;
        let mut best: Option<(u32, usize)> = None;
        let mut ground = false;
        if self.scene.ground.is_some() && d.y > 0.0 {
            let t = -o.y / d.y;
            if t > 0.0 {
                best_t = t;
                ground = true;
            }
        }
        for b in self.bins.at(u, v) {
            if b.near >= best_t {
                break;
            }
            let mut t_in = f64::NEG_INFINITY;
            let mut t_out = f64::INFINITY;
            let mut axis = 0usize;
            for a in 0..3 {
                let t0 = (b.min[a] - o[a]) * inv[a];
                let t1 = (b.max[a] - o[a]) * inv[a];
                let (lo, hi) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
                if lo > t_in {
                    t_in = lo;
                    axis = a;
                }
                t_out = t_out.min(hi);
            }
            if t_in <= t_out && t_in > 0.0 && t_in < best_t {
                best_t = t_in;
                best = Some((b.index, axis));
                ground = false;
            }
        }
        let pixel_m = best_t * spacing / pose.intrinsics.fx;
        let footprint = |axis: usize| {
            let cos = d[axis].abs() / d.norm();
            pixel_m / cos.max(0.125)
        };
        if let Some((index, axis)) = best {
            let b = &self.scene.boxes[index as usize];
            let p = o + d * best_t;
            // Entering through the min face means the outward normal is −axis.
            let face = 2 * axis + usize::from(d[axis] < 0.0);
            let uv = match axis {
                0 => [p.z, p.y],
                1 => [p.x, p.z],
                _ => [p.x, p.y],
            };
            let (value, region) = self
                .scene
                .shade(&b.material, uv, footprint(axis), axis == 0);
            return Sample {
                id: (2 + 6 * index + face as u32) << 3 | region,
                value: value * FACE_SHADE[face],
            };
        }
        if ground {
            if let Some(material) = &self.scene.ground {
                let p = o + d * best_t;
                let (value, region) = self.scene.shade(material, [p.x, p.z], footprint(1), false);
                return Sample {
                    id: 1 << 3 | region,
                    value: value * GROUND_SHADE,
                };
            }
        }
        let value = self
            .scene
            .shade_sky([d.x, d.y, d.z], spacing / pose.intrinsics.fx);
        Sample { id: 0, value }
    }
}

/// Seeded Gaussian sensor noise for one row and the 8-bit quantization.
struct Noise {
    rng: ChaCha8Rng,
    sigma: f32,
    spare: Option<f32>,
}

impl Noise {
    fn new(spec: &RenderSpec, row: usize) -> Self {
        let seed = spec.noise_seed ^ (row as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        Noise {
            rng: ChaCha8Rng::seed_from_u64(seed),
            sigma: spec.noise_sigma,
            spare: None,
        }
    }

    /// Box-Muller, both outputs used.
    fn gaussian(&mut self) -> f32 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let u1: f32 = 1.0 - self.rng.random::<f32>(); // (0, 1]: ln is finite
        let u2: f32 = self.rng.random();
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (std::f32::consts::TAU * u2).sin_cos();
        self.spare = Some(r * s);
        r * c
    }

    fn quantize(&mut self, value: f32) -> u8 {
        let mut grey = value * 255.0;
        if self.sigma > 0.0 {
            grey += self.sigma * self.gaussian();
        }
        // Saturating float-to-int cast after clamping: the sensor clips.
        grey.round().clamp(0.0, 255.0) as u8
    }
}
