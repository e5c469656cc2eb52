//! The 3D world: a ground plane, axis-aligned boxes, a sky at infinity, and their materials.
//!
//! Boxes aligned with the road axes are enough for façades, vehicles, trees, poles and lab
//! furniture, and they keep the ray intersection exact and cheap (three slabs). Everything is
//! stored in world coordinates: x right, y down (the ground is the plane y = 0, so things above
//! it have negative y), z along the road.

use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::layout;
use crate::texture::{floor_i64, Texture};
use crate::SynthError;

/// The built-in scenes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SceneKind {
    /// A city street seen from a car (thesis 5.1.2): road with markings, parked vehicles,
    /// trees, poles and façades; the vehicle drives along +z.
    Road,
    /// A lab (thesis 5.1.1): textured objects 1-5 m away in a closed room; the head stands still.
    Lab,
    /// A nearly uniform, low-contrast wall and floor: too little texture for an estimate.
    Sparse,
}

impl SceneKind {
    pub const ALL: [SceneKind; 3] = [Self::Road, Self::Lab, Self::Sparse];

    pub fn name(self) -> &'static str {
        match self {
            Self::Road => "road",
            Self::Lab => "lab",
            Self::Sparse => "sparse",
        }
    }
}

impl fmt::Display for SceneKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for SceneKind {
    type Err = SynthError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s)
            .ok_or_else(|| SynthError::UnknownScene(s.to_owned()))
    }
}

/// Which of the scene's noise textures a surface uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TextureKind {
    /// Balanced multi-scale noise (plaster, asphalt, paint).
    Fractal,
    /// Grainy, strong fine scales (foliage, gravel, bark).
    Rough,
    /// Dominated by coarse scales (stains, shading variations, clouds).
    Smooth,
}

impl TextureKind {
    fn index(self) -> usize {
        match self {
            Self::Fractal => 0,
            Self::Rough => 1,
            Self::Smooth => 2,
        }
    }
}

/// A regular pattern drawn over a surface's noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Pattern {
    None,
    /// Windows on a façade's street-facing sides: a grid of `size` rectangles every
    /// `spacing` metres (along z, along y), each with its own brightness.
    Windows {
        spacing: [f64; 2],
        size: [f64; 2],
        glass: f32,
    },
    /// Square paving tiles of `tile_m` with dark seams of `seam_m`.
    Paving {
        tile_m: f64,
        seam_m: f64,
    },
}

/// A textured surface: `mean + contrast·fine + macro_contrast·coarse` where `fine` and
/// `coarse` are lookups of the same unit-variance texture at `metres_per_texel` and at 13.7×
/// that scale (the second lookup breaks the texture's periodicity), then `pattern`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    pub texture: TextureKind,
    pub metres_per_texel: f64,
    /// Texture-space offset in metres so that equal surfaces do not look alike.
    pub offset: [f64; 2],
    pub mean: f32,
    pub contrast: f32,
    pub macro_contrast: f32,
    pub pattern: Pattern,
}

/// What a surface looks like.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Material {
    /// A uniform intensity in [0, 1] (tests use it for exact coverage measurements).
    Flat(f32),
    Surface(Surface),
    /// The street of the road scene: lanes, markings, parking strips and sidewalks laid out
    /// across x (only meaningful on the ground plane).
    Road,
}

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneBox {
    pub min: [f64; 3],
    pub max: [f64; 3],
    pub material: Material,
}

/// The sky at infinity, a function of direction only (zero disparity: the points the verge
/// estimate likes best).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sky {
    /// Intensity at the horizon.
    pub horizon: f32,
    /// Added at the zenith.
    pub gradient: f32,
    /// Contrast of the clouds.
    pub clouds: f32,
}

/// A world to render. Build one with [`Scene::new`] or start from [`Scene::empty`] and add boxes.
#[derive(Debug, Clone)]
pub struct Scene {
    pub(crate) kind: Option<SceneKind>,
    pub(crate) boxes: Vec<SceneBox>,
    pub(crate) ground: Option<Material>,
    pub(crate) sky: Sky,
    pub(crate) textures: Arc<[Texture; 3]>,
    /// The z range the scene is furnished over (a moving head must stay inside it).
    pub(crate) extent_z: [f64; 2],
}

/// Texture side length: 512 texels (2^9).
const TEXTURE_SIZE_LOG2: u32 = 9;

impl Scene {
    /// The built-in scene `kind`, laid out deterministically from `seed`.
    pub fn new(kind: SceneKind, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut scene = Self::with_textures(&mut rng, Sky::default());
        scene.kind = Some(kind);
        match kind {
            SceneKind::Road => layout::road(&mut scene, &mut rng),
            SceneKind::Lab => layout::lab(&mut scene, &mut rng),
            SceneKind::Sparse => layout::sparse(&mut scene),
        }
        scene
    }

    /// A scene with no ground and a uniform sky of intensity `background`; add boxes with
    /// [`Scene::add_box`]. The noise textures still come from `seed`.
    pub fn empty(seed: u64, background: f32) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        Self::with_textures(
            &mut rng,
            Sky {
                horizon: background,
                gradient: 0.0,
                clouds: 0.0,
            },
        )
    }

    fn with_textures(rng: &mut ChaCha8Rng, sky: Sky) -> Self {
        let textures = [
            Texture::fractal(rng, TEXTURE_SIZE_LOG2, 0.85),
            Texture::fractal(rng, TEXTURE_SIZE_LOG2, 0.97),
            Texture::fractal(rng, TEXTURE_SIZE_LOG2, 0.65),
        ];
        Scene {
            kind: None,
            boxes: Vec::new(),
            ground: None,
            sky,
            textures: Arc::new(textures),
            extent_z: [f64::NEG_INFINITY, f64::INFINITY],
        }
    }

    pub fn add_box(&mut self, b: SceneBox) {
        self.boxes.push(b);
    }

    /// Put a ground plane (y = 0) of `material` under the scene, or remove it.
    pub fn set_ground(&mut self, material: Option<Material>) {
        self.ground = material;
    }

    pub fn set_sky(&mut self, sky: Sky) {
        self.sky = sky;
    }

    pub fn kind(&self) -> Option<SceneKind> {
        self.kind
    }

    pub fn boxes(&self) -> &[SceneBox] {
        &self.boxes
    }

    /// The z range a moving head must stay inside (furniture ends beyond it).
    pub fn extent_z(&self) -> [f64; 2] {
        self.extent_z
    }

    /// Intensity of `material` at texture coordinates `uv` (metres on the surface), filtered
    /// over `footprint_m`, and the pattern region the point is in (0 = plain texture). The
    /// noise is prefiltered, the pattern's hard edges are not: the renderer supersamples
    /// where neighbouring pixels are in different regions. `street_facing` enables façade
    /// windows (faces normal to x).
    pub(crate) fn shade(
        &self,
        material: &Material,
        uv: [f64; 2],
        footprint_m: f64,
        street_facing: bool,
    ) -> (f32, u32) {
        match material {
            Material::Flat(v) => (*v, 0),
            Material::Surface(s) => self.shade_surface(s, uv, footprint_m, street_facing),
            Material::Road => layout::shade_road(self, uv, footprint_m),
        }
    }

    pub(crate) fn shade_surface(
        &self,
        s: &Surface,
        uv: [f64; 2],
        footprint_m: f64,
        street_facing: bool,
    ) -> (f32, u32) {
        let tex = &self.textures[s.texture.index()];
        let u = (uv[0] + s.offset[0]) / s.metres_per_texel;
        let v = (uv[1] + s.offset[1]) / s.metres_per_texel;
        let fp = footprint_m / s.metres_per_texel;
        let mut value = s.mean + s.contrast * tex.sample(u, v, fp);
        if s.macro_contrast != 0.0 {
            const MACRO: f64 = 13.7;
            value += s.macro_contrast * tex.sample_coarse(v / MACRO + 97.0, u / MACRO, fp / MACRO);
        }
        match s.pattern {
            Pattern::None => (value, 0),
            Pattern::Windows {
                spacing,
                size,
                glass,
            } if street_facing => {
                let (cu, fu) = cell(uv[0], spacing[0]);
                let (cv, fv) = cell(uv[1], spacing[1]);
                let margin_u = (spacing[0] - size[0]) / 2.0;
                let margin_v = (spacing[1] - size[1]) / 2.0;
                let inside = fu > margin_u
                    && fu < margin_u + size[0]
                    && fv > margin_v
                    && fv < margin_v + size[1];
                if inside {
                    // Curtains and reflections: each window its own brightness.
                    let h = hash2(cu, cv);
                    (glass + 0.35 * h + 0.04 * (value - s.mean), 1)
                } else {
                    (value, 0)
                }
            }
            Pattern::Windows { .. } => (value, 0),
            Pattern::Paving { tile_m, seam_m } => {
                const SEAM_DARKEN: f32 = 0.45;
                if footprint_m > 2.0 * seam_m {
                    // Seams thinner than the footprint: their mean darkening (they cover
                    // about 2·seam/tile of the surface), instead of aliasing.
                    let cover = (2.0 * seam_m / tile_m).min(1.0) as f32;
                    return (value * (1.0 - SEAM_DARKEN * cover), 0);
                }
                let (_, fu) = cell(uv[0], tile_m);
                let (_, fv) = cell(uv[1], tile_m);
                if fu < seam_m || fv < seam_m {
                    (value * (1.0 - SEAM_DARKEN), 1)
                } else {
                    (value, 0)
                }
            }
        }
    }

    /// The sky's intensity for a world direction (not necessarily normalized).
    pub(crate) fn shade_sky(&self, d: [f64; 3], footprint_rad: f64) -> f32 {
        let sky = &self.sky;
        let norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        let elevation = (-d[1] / norm).clamp(-1.0, 1.0);
        let mut value = sky.horizon + sky.gradient * elevation.max(0.0) as f32;
        if sky.clouds != 0.0 {
            // Texture coordinates from the unit direction alone put the clouds at infinity;
            // ~3 mrad per texel near the horizon.
            const RAD_PER_TEXEL: f64 = 0.003;
            let tex = &self.textures[TextureKind::Smooth.index()];
            let c = tex.sample(
                d[0] / norm / RAD_PER_TEXEL,
                (d[2] / norm + 2.0 * elevation) / RAD_PER_TEXEL,
                footprint_rad / RAD_PER_TEXEL,
            );
            value += sky.clouds * c * elevation.max(0.0).sqrt() as f32;
        }
        value
    }
}

impl Default for Sky {
    fn default() -> Self {
        Sky {
            horizon: 0.78,
            gradient: 0.12,
            clouds: 0.07,
        }
    }
}

/// Index of the cell of width `w` containing `x`, and the offset of `x` inside it.
pub(crate) fn cell(x: f64, w: f64) -> (i64, f64) {
    let c = floor_i64(x / w);
    (c, x - c as f64 * w)
}

/// A deterministic pseudo-random value in [0, 1) for a 2D integer cell.
pub(crate) fn hash2(a: i64, b: i64) -> f32 {
    let mut h = (a as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
        ^ (b as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f);
    h ^= h >> 31;
    h = h.wrapping_mul(0x94d0_49bb_1331_11eb);
    h ^= h >> 29;
    (h >> 40) as f32 / (1u64 << 24) as f32
}
