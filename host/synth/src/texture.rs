//! Tileable multi-scale value-noise textures with a mip pyramid.
//!
//! DoG keypoints appear only where an image has structure at the scale of the filter, and the
//! fabric looks at four octaves; a texture with energy in every octave band (value noise summed
//! over periods 2..size/2 with a slowly falling amplitude, close to the 1/f spectrum of natural
//! images) gives keypoints at all of them. The pyramid is prefiltered so that a single sample per
//! pixel already integrates the texture over the pixel footprint, which is what makes the
//! adaptive supersampling in `render.rs` cheap without aliasing the interiors of surfaces.

use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// One mip level: a square, power-of-two, wrap-around grid of intensities.
#[derive(Debug, Clone)]
struct Level {
    size: usize,
    texels: Vec<f32>,
}

impl Level {
    /// Bilinear lookup with wrap-around; `u`, `v` are in this level's texel units, texel
    /// centres at half-integers.
    fn bilinear(&self, u: f64, v: f64) -> f32 {
        let (x, y) = (u - 0.5, v - 0.5);
        let (xi, yi) = (floor_i64(x), floor_i64(y));
        let fx = (x - xi as f64) as f32;
        let fy = (y - yi as f64) as f32;
        // Two's complement `& mask` is the wrap-around modulo for negative cells too.
        let mask = (self.size - 1) as i64;
        let x0 = (xi & mask) as usize;
        let y0 = (yi & mask) as usize;
        let x1 = (x0 + 1) & (self.size - 1);
        let y1 = (y0 + 1) & (self.size - 1);
        let row0 = &self.texels[y0 * self.size..(y0 + 1) * self.size];
        let row1 = &self.texels[y1 * self.size..(y1 + 1) * self.size];
        let top = row0[x0] + (row0[x1] - row0[x0]) * fx;
        let bottom = row1[x0] + (row1[x1] - row1[x0]) * fx;
        top + (bottom - top) * fy
    }

    /// The next coarser level: 2x2 box average.
    fn halve(&self) -> Level {
        let size = self.size / 2;
        let mut texels = Vec::with_capacity(size * size);
        for y in 0..size {
            for x in 0..size {
                let at = |dx: usize, dy: usize| self.texels[(2 * y + dy) * self.size + 2 * x + dx];
                texels.push(0.25 * (at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1)));
            }
        }
        Level { size, texels }
    }
}

/// A zero-mean, unit-variance tileable noise texture and its mip pyramid.
#[derive(Debug, Clone)]
pub(crate) struct Texture {
    levels: Vec<Level>,
}

impl Texture {
    /// Fractal value noise of `2^size_log2` texels square. `persistence` is the amplitude ratio
    /// from one octave to the next finer one (1.0 would be equal energy per octave, i.e. a 1/f
    /// amplitude spectrum; slightly below keeps the surfaces from looking like pure grain).
    pub(crate) fn fractal(rng: &mut ChaCha8Rng, size_log2: u32, persistence: f32) -> Self {
        let size = 1usize << size_log2;
        let mut acc = vec![0.0f32; size * size];
        let mut amplitude = 1.0f32;
        // Coarsest period: half the texture, finest: 2 texels.
        for period_log2 in (1..size_log2).rev() {
            let period = 1usize << period_log2;
            let cells = size / period;
            let lattice: Vec<f32> = (0..cells * cells).map(|_| rng.random::<f32>()).collect();
            let inv = 1.0 / period as f32;
            for y in 0..size {
                let gy = y / period;
                let ty = smooth((y % period) as f32 * inv);
                let gy1 = (gy + 1) % cells;
                for x in 0..size {
                    let gx = x / period;
                    let tx = smooth((x % period) as f32 * inv);
                    let gx1 = (gx + 1) % cells;
                    let a = lattice[gy * cells + gx];
                    let b = lattice[gy * cells + gx1];
                    let c = lattice[gy1 * cells + gx];
                    let d = lattice[gy1 * cells + gx1];
                    let top = a + (b - a) * tx;
                    let bottom = c + (d - c) * tx;
                    acc[y * size + x] += amplitude * (top + (bottom - top) * ty);
                }
            }
            amplitude *= persistence;
        }
        let n = acc.len() as f32;
        let mean = acc.iter().sum::<f32>() / n;
        let var = acc.iter().map(|v| (v - mean) * (v - mean)).sum::<f32>() / n;
        let inv_std = 1.0 / var.sqrt().max(f32::EPSILON);
        for v in &mut acc {
            *v = (*v - mean) * inv_std;
        }
        let mut levels = vec![Level { size, texels: acc }];
        while let Some(last) = levels.last() {
            if last.size == 1 {
                break;
            }
            let next = last.halve();
            levels.push(next);
        }
        Texture { levels }
    }

    /// Trilinear lookup at texel coordinates (`u`, `v`) of level 0, prefiltered over a
    /// footprint of `footprint` level-0 texels.
    pub(crate) fn sample(&self, u: f64, v: f64, footprint: f64) -> f32 {
        let top = (self.levels.len() - 1) as f64;
        let lod = log2_approx(footprint.max(1.0)).min(top);
        // lod is in [0, top], so the floor is a valid level index.
        let l0 = floor_i64(lod);
        let frac = (lod - l0 as f64) as f32;
        let l0 = l0 as usize;
        let scale0 = 1.0 / (1u64 << l0) as f64;
        let a = self.levels[l0].bilinear(u * scale0, v * scale0);
        if frac == 0.0 || l0 + 1 >= self.levels.len() {
            return a;
        }
        let b = self.levels[l0 + 1].bilinear(u * scale0 * 0.5, v * scale0 * 0.5);
        a + (b - a) * frac
    }
}

/// `x.floor()` as an integer, without the libm call that `floor` is on baseline x86-64.
/// Saturates far outside the i64 range, where texture coordinates have no precision anyway.
pub(crate) fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x {
        t - 1
    } else {
        t
    }
}

/// Piecewise-linear log2 (exact at powers of two, within 0.09 between): mip level selection
/// only needs a monotonic, roughly logarithmic map. `x` must be a positive normal number.
fn log2_approx(x: f64) -> f64 {
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let mantissa = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    exponent as f64 + (mantissa - 1.0)
}

impl Texture {
    /// Bilinear lookup at the mip level nearest to the footprint: half the cost of
    /// [`Texture::sample`], for the low-frequency layers where the level seam does not show.
    pub(crate) fn sample_coarse(&self, u: f64, v: f64, footprint: f64) -> f32 {
        let top = (self.levels.len() - 1) as f64;
        let level = floor_i64(log2_approx(footprint.max(1.0)).min(top) + 0.5) as usize;
        let scale = 1.0 / (1u64 << level) as f64;
        self.levels[level].bilinear(u * scale, v * scale)
    }
}

/// Hermite smoothstep: C1-continuous interpolation between lattice values.
fn smooth(t: f32) -> f32 {
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn normalized_and_tileable() {
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let t = Texture::fractal(&mut rng, 6, 0.7);
        let l0 = &t.levels[0];
        let n = l0.texels.len() as f32;
        let mean = l0.texels.iter().sum::<f32>() / n;
        let var = l0
            .texels
            .iter()
            .map(|v| (v - mean) * (v - mean))
            .sum::<f32>()
            / n;
        assert!(mean.abs() < 1e-4 && (var - 1.0).abs() < 1e-3);
        // Wrap-around: a lookup one period away is the same texel.
        let a = t.sample(3.5, 7.5, 1.0);
        let b = t.sample(3.5 + 64.0, 7.5 - 128.0, 1.0);
        assert!((a - b).abs() < 1e-5);
        assert_eq!(t.levels.last().map(|l| l.size), Some(1));
        // A huge footprint returns the (zero) mean.
        assert!(t.sample(10.0, 10.0, 1e9).abs() < 1e-4);
        assert_eq!(
            (
                floor_i64(-0.5),
                floor_i64(2.0),
                floor_i64(2.7),
                floor_i64(-3.0)
            ),
            (-1, 2, 2, -3)
        );
        assert_eq!(log2_approx(8.0), 3.0);
        assert!((log2_approx(3.0) - 3f64.log2()).abs() < 0.09);
    }
}
