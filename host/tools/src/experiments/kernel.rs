//! Thesis fig. 4.8, choosing the size of the Gaussian kernel (section 4.2.4): the octave's
//! cascade of Gaussians filtered with `n`-tap kernels, compared with the same cascade filtered
//! with a kernel so large (the thesis: 100x100) that nothing of the Gaussian is cut off; the
//! thesis plotted that error and the FPGA area against `n` and chose `n = 5`.
//!
//! Here the cascade is the fabric's octave 0 (G0, then G1..G3, each row then column, replicated
//! borders) on rendered road frames, with the design σ of each stage. For every odd `n` from 3
//! to 11 it is filtered twice: with the sampled Gaussian truncated to `n` taps and renormalised
//! (in `f64`: the truncation error alone), and with those taps quantised to 10 bits and the
//! fabric's Q8.8 arithmetic (what a fabric with `n` taps would compute). The fabric's own taps
//! (`stereocal_firmware::fabric::taps`, chosen for the exact design variance rather than by
//! sampling) get a row of their own. Even sizes are left out: a symmetric even kernel has no
//! centre pixel and would shift the image by half a pixel, an error that is not the kernel
//! size's. The reference has [`REFERENCE_TAPS`] taps; the error is over all four filtered
//! images, in grey levels. Area is the thesis' own measure of a LUT distributed-arithmetic
//! convolver, `2^n (bk + n - 1)` LUT bits per 1-D stage for `bk`-bit taps (section 4.2.3).
//!
//! Files: `results.csv` (size vs error), `sigma.csv` (the discrete σ, thesis table 4.2) and
//! `kernel.png`.

use std::ops::Range;
use std::path::Path;

use plotters::prelude::*;
use stereocal_firmware::fabric::taps::{discrete_sigma as taps_sigma, GAUSS_TAPS, TAP_BITS};

use super::files::Files;
use super::table::fixed;
use super::{ExperimentError, Outcome, Progress, Table};
use stereocal::output::plot::FAMILY;
use stereocal_synth::{SceneKind, Sequence, SequenceConfig, TrajectoryKind};

/// Kernel sizes compared (odd: see the module documentation).
pub const SIZES: [usize; 5] = [3, 5, 7, 9, 11];
/// Taps of the fabric's kernels.
pub const FABRIC_SIZE: usize = GAUSS_TAPS[0].len();
/// Taps of the reference kernel (the thesis used 100; odd so it has a centre). Beyond ±50
/// pixels the largest σ here (1.22) leaves less than 1e-300 of its weight.
pub const REFERENCE_TAPS: usize = 101;
/// The base σ of an octave (the camera blur after G0) and the camera's own blur.
const BASE_SIGMA: f64 = 1.0;
const CAMERA_SIGMA: f64 = 0.5;

/// The design σ of G0..G3 (`taps.rs`): G0 brings the camera's σ 0.5 to the base σ 1, and
/// G1..G3 follow Lowe's schedule `σ_i = sqrt(k² - 1)·k^(i-1)`, `k = 2^(1/3)`, so that after G3
/// the octave has σ 2 and its subsampled image is again a base of σ 1.
pub fn design_sigmas() -> [f64; 4] {
    let k = 2f64.powf(1.0 / 3.0);
    let step = (k * k - 1.0).sqrt() * BASE_SIGMA;
    [
        (BASE_SIGMA * BASE_SIGMA - CAMERA_SIGMA * CAMERA_SIGMA).sqrt(),
        step,
        step * k,
        step * k * k,
    ]
}

/// The Gaussian of `sigma` sampled at the `n` integer offsets around 0 (`n` odd) and
/// normalised to unit sum: the truncated kernel of the thesis' experiment.
pub fn sampled(sigma: f64, n: usize) -> Vec<f64> {
    let half = (n / 2) as f64;
    let taps: Vec<f64> = (0..n)
        .map(|i| {
            let d = i as f64 - half;
            (-d * d / (2.0 * sigma * sigma)).exp()
        })
        .collect();
    let sum: f64 = taps.iter().sum();
    taps.into_iter().map(|t| t / sum).collect()
}

/// `kernel` as `TAP_BITS`-bit taps summing to exactly `1 << TAP_BITS`: each tap rounded, the
/// centre absorbing the remainder, so the DC gain is one as in the fabric's taps.
pub fn quantize(kernel: &[f64]) -> Vec<u32> {
    let one = f64::from(1u32 << TAP_BITS);
    let mut taps: Vec<u32> = kernel.iter().map(|t| (t * one).round() as u32).collect();
    let centre = kernel.len() / 2;
    let others: u32 = taps.iter().sum::<u32>() - taps[centre];
    taps[centre] = (1u32 << TAP_BITS) - others;
    taps
}

/// Standard deviation of a discrete kernel about its centre (thesis eq. 4.4).
pub fn discrete_sigma(kernel: &[f64]) -> f64 {
    let half = (kernel.len() / 2) as f64;
    let sum: f64 = kernel.iter().sum();
    let var: f64 = kernel
        .iter()
        .enumerate()
        .map(|(i, t)| (i as f64 - half).powi(2) * t)
        .sum();
    (var / sum).sqrt()
}

/// The share of the reference Gaussian's weight that an `n`-tap kernel cuts off.
pub fn weight_lost(sigma: f64, n: usize) -> f64 {
    let reference = sampled(sigma, REFERENCE_TAPS);
    let centre = REFERENCE_TAPS / 2;
    let kept: f64 = reference[centre - n / 2..=centre + n / 2].iter().sum();
    1.0 - kept
}

/// DA LUT bits of one 1-D convolver stage with `n` taps of `TAP_BITS` bits (thesis 4.2.3).
pub fn lut_bits(n: usize) -> u64 {
    (1u64 << n) * (u64::from(TAP_BITS) + n as u64 - 1)
}

/// One grey image, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct Plane<T> {
    pub width: usize,
    pub height: usize,
    pub data: Vec<T>,
}

impl<T: Copy> Plane<T> {
    /// Filters every row with `dot` over the `n` samples around each pixel (edge pixels
    /// replicated, as the fabric does) and returns the result transposed, so calling it twice
    /// filters rows then columns and restores the orientation.
    fn rows_transposed<U: Copy + Default>(&self, n: usize, dot: impl Fn(&[T]) -> U) -> Plane<U> {
        let half = n / 2;
        let (w, h) = (self.width, self.height);
        let mut out = vec![U::default(); w * h];
        let mut padded = Vec::with_capacity(w + 2 * half);
        for y in 0..h {
            let row = &self.data[y * w..(y + 1) * w];
            padded.clear();
            padded.extend(std::iter::repeat_n(row[0], half));
            padded.extend_from_slice(row);
            padded.extend(std::iter::repeat_n(row[w - 1], half));
            for x in 0..w {
                out[x * h + y] = dot(&padded[x..x + n]);
            }
        }
        Plane {
            width: h,
            height: w,
            data: out,
        }
    }
}

/// One separable Gaussian in `f64`.
pub fn gaussian_f64(image: &Plane<f64>, kernel: &[f64]) -> Plane<f64> {
    let dot = |s: &[f64]| s.iter().zip(kernel).map(|(a, b)| a * b).sum::<f64>();
    image
        .rows_transposed(kernel.len(), dot)
        .rows_transposed(kernel.len(), dot)
}

/// One separable Gaussian in the fabric's arithmetic: Q8.8 samples, `TAP_BITS`-bit taps, the
/// row pass exact and the column pass rounded once, `(Σ tap·row + half) >> 2·TAP_BITS`
/// (`fabric::convolver::da_row` / `da_column`).
pub fn gaussian_q88(image: &Plane<u16>, taps: &[u32]) -> Plane<u16> {
    let row = |s: &[u16]| -> u64 {
        s.iter()
            .zip(taps)
            .map(|(&a, &t)| u64::from(a) * u64::from(t))
            .sum()
    };
    let column = |s: &[u64]| {
        let acc: u64 = s.iter().zip(taps).map(|(&a, &t)| a * u64::from(t)).sum();
        ((acc + (1 << (2 * TAP_BITS - 1))) >> (2 * TAP_BITS)) as u16
    };
    image
        .rows_transposed(taps.len(), row)
        .rows_transposed(taps.len(), column)
}

/// Each stage's output of the cascade `kernels` (G0 first) in grey levels.
pub fn cascade_f64(image: &Plane<f64>, kernels: &[Vec<f64>]) -> Vec<Plane<f64>> {
    let mut out: Vec<Plane<f64>> = Vec::with_capacity(kernels.len());
    for k in kernels {
        let next = gaussian_f64(out.last().unwrap_or(image), k);
        out.push(next);
    }
    out
}

/// Each stage's output of the cascade `taps` (G0 first) in Q8.8, from 8-bit pixels.
pub fn cascade_q88(image: &Plane<u8>, taps: &[Vec<u32>]) -> Vec<Plane<u16>> {
    let input = Plane {
        width: image.width,
        height: image.height,
        data: image.data.iter().map(|&p| u16::from(p) << 8).collect(),
    };
    let mut out: Vec<Plane<u16>> = Vec::with_capacity(taps.len());
    for t in taps {
        let next = gaussian_q88(out.last().unwrap_or(&input), t);
        out.push(next);
    }
    out
}

/// Error against the reference cascade, accumulated over images and stages (grey levels).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CascadeError {
    pub max_abs: f64,
    pub sum_sq: f64,
    pub samples: usize,
}

impl CascadeError {
    /// Adds the difference of `got` from `reference`, sample by sample.
    pub fn add(&mut self, got: impl IntoIterator<Item = f64>, reference: &[f64]) {
        for (g, r) in got.into_iter().zip(reference) {
            let e = g - r;
            self.max_abs = self.max_abs.max(e.abs());
            self.sum_sq += e * e;
            self.samples += 1;
        }
    }

    pub fn rms(&self) -> f64 {
        if self.samples == 0 {
            0.0
        } else {
            (self.sum_sq / self.samples as f64).sqrt()
        }
    }
}

/// The errors of one kernel size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SizeResult {
    pub size: usize,
    /// Truncated sampled kernels in `f64`.
    pub truncated: CascadeError,
    /// The same kernels in 10-bit taps and Q8.8 arithmetic.
    pub quantized: CascadeError,
}

/// The whole comparison over some images.
#[derive(Debug, Clone, PartialEq)]
pub struct KernelStudy {
    pub sizes: Vec<SizeResult>,
    /// The fabric's own taps in its own arithmetic.
    pub fabric: CascadeError,
    pub images: usize,
}

impl KernelStudy {
    pub fn new() -> Self {
        let none = CascadeError::default();
        Self {
            sizes: SIZES
                .iter()
                .map(|&size| SizeResult {
                    size,
                    truncated: none,
                    quantized: none,
                })
                .collect(),
            fabric: none,
            images: 0,
        }
    }

    /// Filters one 8-bit image with every kernel and accumulates the errors.
    pub fn add_image(&mut self, image: &Plane<u8>) {
        let sigmas = design_sigmas();
        let kernels = |n| sigmas.iter().map(|&s| sampled(s, n)).collect::<Vec<_>>();
        let grey = Plane {
            width: image.width,
            height: image.height,
            data: image.data.iter().map(|&p| f64::from(p)).collect(),
        };
        let reference = cascade_f64(&grey, &kernels(REFERENCE_TAPS));
        let q88 = |planes: Vec<Plane<u16>>, err: &mut CascadeError| {
            for (p, r) in planes.iter().zip(&reference) {
                err.add(p.data.iter().map(|&v| f64::from(v) / 256.0), &r.data);
            }
        };
        for result in &mut self.sizes {
            let float = kernels(result.size);
            for (p, r) in cascade_f64(&grey, &float).iter().zip(&reference) {
                result.truncated.add(p.data.iter().copied(), &r.data);
            }
            let taps: Vec<Vec<u32>> = float.iter().map(|k| quantize(k)).collect();
            q88(cascade_q88(image, &taps), &mut result.quantized);
        }
        let fabric: Vec<Vec<u32>> = GAUSS_TAPS
            .iter()
            .map(|t| t.iter().map(|&v| u32::from(v)).collect())
            .collect();
        q88(cascade_q88(image, &fabric), &mut self.fabric);
        self.images += 1;
    }
}

impl Default for KernelStudy {
    fn default() -> Self {
        Self::new()
    }
}

pub fn run(
    frames: usize,
    seed: u64,
    out: &Path,
    progress: &mut dyn FnMut(Progress),
) -> Result<Outcome, ExperimentError> {
    let mut config = SequenceConfig::for_scene(SceneKind::Road);
    config.frames = frames;
    config.seed = seed;
    config.trajectory = TrajectoryKind::Fixed;
    let sequence = Sequence::builtin(SceneKind::Road, config)?;
    progress(Progress::Run {
        label: "road frames through the Gaussian cascade",
        steps: frames,
    });
    let mut study = KernelStudy::new();
    for index in 0..sequence.len() {
        if let Some(images) = sequence.frame(index)?.images {
            study.add_image(&Plane {
                width: images.left.width() as usize,
                height: images.left.height() as usize,
                data: images.left.into_raw(),
            });
        }
        progress(Progress::Step);
    }
    if study.images == 0 {
        return Err(ExperimentError::Empty {
            experiment: "kernel",
            what: "image",
        });
    }
    let tables = vec![size_table(&study, seed), sigma_table()];
    let mut files = Files::new(out)?;
    for t in &tables {
        files.table(t)?;
    }
    files.figure("kernel.png", |path| draw(path, &study, seed))?;
    Ok(Outcome {
        title: "kernel size vs error (thesis fig. 4.8)".into(),
        tables,
        written: files.commit()?,
    })
}

fn size_table(study: &KernelStudy, seed: u64) -> Table {
    let g3 = design_sigmas()[3];
    let mut table = Table::new(
        "results",
        format!(
            "fig. 4.8, error of the G0..G3 cascade with n-tap kernels against {REFERENCE_TAPS} taps, \
             grey levels over all four filtered images of {} road frame(s), seed {seed}",
            study.images
        ),
        &[
            "taps n",
            "LUT bits per stage",
            "G3 sigma",
            "G3 weight cut (%)",
            "max err, f64",
            "RMS err, f64",
            "max err, 10-bit",
            "RMS err, 10-bit",
            "thesis (fig. 4.8)",
        ],
    );
    for r in &study.sizes {
        table.push(vec![
            r.size.to_string(),
            lut_bits(r.size).to_string(),
            format!("{:.4}", discrete_sigma(&sampled(g3, r.size))),
            format!("{:.3}", 100.0 * weight_lost(g3, r.size)),
            format!("{:.4}", r.truncated.max_abs),
            format!("{:.4}", r.truncated.rms()),
            format!("{:.4}", r.quantized.max_abs),
            format!("{:.4}", r.quantized.rms()),
            if r.size == FABRIC_SIZE {
                "chosen: area / accuracy trade-off".to_owned()
            } else {
                "-".to_owned()
            },
        ]);
    }
    table.push(vec![
        format!("{FABRIC_SIZE}, fabric taps"),
        lut_bits(FABRIC_SIZE).to_string(),
        format!("{:.4}", taps_sigma(&GAUSS_TAPS[3])),
        "-".to_owned(),
        "-".to_owned(),
        "-".to_owned(),
        format!("{:.4}", study.fabric.max_abs),
        format!("{:.4}", study.fabric.rms()),
        "the fabric's kernels (taps.rs)".to_owned(),
    ]);
    table
}

/// Thesis table 4.2: the σ its 5-tap kernels actually had, against ours.
fn sigma_table() -> Table {
    let design = design_sigmas();
    let thesis = ["1.1592 (design 1.4142)", "0.8292", "0.9354", "1.1040"];
    let mut table = Table::new(
        "sigma",
        "table 4.2, discrete sigma of the 5-tap kernels (eq. 4.4); octave: \
         sqrt(1 + G1^2 + G2^2 + G3^2) from the base sigma 1, the goal is 2 (eq. 4.3)",
        &[
            "kernel",
            "design sigma",
            "sampled 5 taps",
            "fabric taps",
            "thesis discrete sigma (table 4.2)",
        ],
    );
    let sampled5: Vec<f64> = design
        .iter()
        .map(|&s| discrete_sigma(&sampled(s, FABRIC_SIZE)))
        .collect();
    let fabric: Vec<f64> = GAUSS_TAPS.iter().map(taps_sigma).collect();
    for (i, thesis) in thesis.into_iter().enumerate() {
        table.push(vec![
            format!("G{i}"),
            format!("{:.4}", design[i]),
            format!("{:.4}", sampled5[i]),
            format!("{:.4}", fabric[i]),
            thesis.to_owned(),
        ]);
    }
    let octave = |s: &[f64]| fixed(Some(s[1..].iter().fold(1.0, |a, s| a + s * s).sqrt()), 4);
    table.push(vec![
        "octave G1..G3".to_owned(),
        octave(&design),
        octave(&sampled5),
        octave(&fabric),
        "2.040 (design 1.988)".to_owned(),
    ]);
    table
}

/// Error against size (left) and LUT bits against size (right), the two curves of fig. 4.8.
fn draw(path: &Path, study: &KernelStudy, seed: u64) -> Result<(), Box<dyn std::error::Error>> {
    let root = BitMapBackend::new(path, (1300, 620)).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(
        &format!(
            "kernel size (fig. 4.8): G0..G3 cascade vs {REFERENCE_TAPS} taps, {} road frame(s), seed {seed}",
            study.images
        ),
        (FAMILY, 22),
    )?;
    let (left, right) = root.split_horizontally(760);
    let sizes = SIZES[0] as f64 - 0.5..SIZES[SIZES.len() - 1] as f64 + 0.5;

    let curves = [
        ("max, f64", BLUE, curve(study, |r| r.truncated.max_abs)),
        ("RMS, f64", CYAN, curve(study, |r| r.truncated.rms())),
        (
            "max, 10-bit taps",
            RED,
            curve(study, |r| r.quantized.max_abs),
        ),
        (
            "RMS, 10-bit taps",
            MAGENTA,
            curve(study, |r| r.quantized.rms()),
        ),
    ];
    let fabric = [study.fabric.max_abs, study.fabric.rms()];
    let errors = log_range(
        curves
            .iter()
            .flat_map(|c| c.2.iter().map(|p| p.1))
            .chain(fabric),
    );
    let mut chart = ChartBuilder::on(&left)
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(80)
        .build_cartesian_2d(sizes.clone(), errors.log_scale())?;
    chart
        .configure_mesh()
        .x_labels(2 * SIZES.len())
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .x_desc("kernel size n (taps)")
        .y_desc("error vs reference (grey levels)")
        .label_style((FAMILY, 14))
        .draw()?;
    for (name, colour, points) in curves {
        chart
            .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))?
            .label(name)
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 20, y)], colour.stroke_width(2)));
        chart.draw_series(
            points
                .into_iter()
                .map(|p| Circle::new(p, 3, colour.filled())),
        )?;
    }
    chart
        .draw_series(
            fabric
                .into_iter()
                .map(|e| TriangleMarker::new((FABRIC_SIZE as f64, e), 8, BLACK.filled())),
        )?
        .label("fabric taps (max, RMS)")
        .legend(|(x, y)| TriangleMarker::new((x + 10, y), 6, BLACK.filled()));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FAMILY, 14))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;

    let bits: Vec<(f64, f64)> = SIZES
        .iter()
        .map(|&n| (n as f64, lut_bits(n) as f64))
        .collect();
    let mut area = ChartBuilder::on(&right)
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(80)
        .build_cartesian_2d(sizes, log_range(bits.iter().map(|b| b.1)).log_scale())?;
    area.configure_mesh()
        .x_labels(2 * SIZES.len())
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| format!("{y:.0}"))
        .x_desc("kernel size n (taps)")
        .y_desc("DA LUT bits per 1-D stage")
        .label_style((FAMILY, 14))
        .draw()?;
    area.draw_series(LineSeries::new(bits.clone(), BLACK.stroke_width(2)))?;
    area.draw_series(bits.into_iter().map(|p| Circle::new(p, 3, BLACK.filled())))?;
    area.draw_series(std::iter::once(TriangleMarker::new(
        (FABRIC_SIZE as f64, lut_bits(FABRIC_SIZE) as f64),
        8,
        RED.filled(),
    )))?
    .label("the fabric (n = 5)")
    .legend(|(x, y)| TriangleMarker::new((x + 10, y), 6, RED.filled()));
    area.configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .label_font((FAMILY, 14))
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}

fn curve(study: &KernelStudy, value: impl Fn(&SizeResult) -> f64) -> Vec<(f64, f64)> {
    study
        .sizes
        .iter()
        .map(|r| (r.size as f64, value(r)))
        .collect()
}

/// A logarithmic axis range around the positive `values`.
fn log_range(values: impl Iterator<Item = f64>) -> Range<f64> {
    let (lo, hi) = values
        .filter(|v| *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    if hi == 0.0 {
        return 1e-6..1.0;
    }
    lo * 0.5..hi * 2.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use stereocal_firmware::fabric::convolver::{da_column, da_row};
    use stereocal_firmware::fabric::taps::GAUSS_LUTS;

    #[test]
    fn design_sigmas_are_the_fabric_taps() {
        for (design, taps) in design_sigmas().iter().zip(&GAUSS_TAPS) {
            assert!(
                (design - taps_sigma(taps)).abs() < 1e-3,
                "{design} vs {taps:?}"
            );
        }
        // The octave ends at σ 2 from the base σ 1 (thesis eq. 4.3).
        let s = design_sigmas();
        let total = (1.0 + s[1] * s[1] + s[2] * s[2] + s[3] * s[3]).sqrt();
        assert!((total - 2.0).abs() < 1e-9);
    }

    #[test]
    fn kernels_are_sane() {
        for &sigma in &design_sigmas() {
            let mut cut = f64::INFINITY;
            for &n in &SIZES {
                let k = sampled(sigma, n);
                assert!((k.iter().sum::<f64>() - 1.0).abs() < 1e-12);
                assert_eq!(quantize(&k).iter().sum::<u32>(), 1 << TAP_BITS);
                // More taps cut off less, and approach the reference σ from below.
                let lost = weight_lost(sigma, n);
                assert!((0.0..cut).contains(&lost), "σ {sigma}, n {n}: {lost}");
                cut = lost;
                let reference = discrete_sigma(&sampled(sigma, REFERENCE_TAPS));
                assert!(discrete_sigma(&k) <= reference + 1e-12);
            }
            assert!(weight_lost(sigma, 11) < 1e-5);
        }
        assert_eq!(lut_bits(5), 32 * 14);
        assert_eq!(lut_bits(3), 8 * 12);
    }

    #[test]
    fn q88_gaussian_is_the_fabric_da_passes() {
        let image = Plane {
            width: 9,
            height: 7,
            data: (0..63u16).map(|i| (i * 997 % 65_000) + 3).collect(),
        };
        for (taps, lut) in GAUSS_TAPS.iter().zip(&GAUSS_LUTS) {
            let wide: Vec<u32> = taps.iter().map(|&t| u32::from(t)).collect();
            let da = image
                .rows_transposed(5, |s| da_row(lut, [s[0], s[1], s[2], s[3], s[4]]))
                .rows_transposed(5, |s| da_column(lut, [s[0], s[1], s[2], s[3], s[4]]));
            assert_eq!(gaussian_q88(&image, &wide), da);
        }
    }

    #[test]
    fn error_falls_with_size_and_the_fabric_is_close() {
        // A small textured image: a diagonal ramp with a checker pattern.
        let (w, h) = (48, 40);
        let data = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                ((x * 3 + y * 2) % 200 + if (x / 3 + y / 3) % 2 == 0 { 40 } else { 0 }) as u8
            })
            .collect();
        let mut study = KernelStudy::new();
        study.add_image(&Plane {
            width: w,
            height: h,
            data,
        });
        let max: Vec<f64> = study.sizes.iter().map(|r| r.truncated.max_abs).collect();
        assert!(max.windows(2).all(|p| p[1] < p[0]), "{max:?}");
        assert!(max[0] > 1.0 && max[max.len() - 1] < 1e-2, "{max:?}");
        // Quantisation limits the 10-bit kernels to about the Q8.8 rounding, never better
        // than the truncation alone by more than that.
        // 10-bit taps and Q8.8 rounding move the error by a fraction of a grey level: they
        // set a floor the large kernels cannot go below.
        for r in &study.sizes {
            assert!(
                (r.quantized.max_abs - r.truncated.max_abs).abs() < 0.1,
                "{r:?}"
            );
            assert!(r.quantized.rms() <= r.quantized.max_abs);
        }
        assert!(study.sizes[4].quantized.max_abs > 10.0 * study.sizes[4].truncated.max_abs);
        let five = study.sizes[1];
        assert_eq!(five.size, FABRIC_SIZE);
        assert!(
            study.fabric.max_abs < 2.0 * five.quantized.max_abs,
            "{study:?}"
        );
    }
}
