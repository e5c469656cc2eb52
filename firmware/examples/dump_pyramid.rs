//! Writes the fabric's intermediate images for one picture, like thesis figs. 4.6, 4.9, 4.13:
//!
//! ```text
//! cargo run --release -p stereocal-firmware --example dump_pyramid -- <image> <outdir>
//! ```
//!
//! Output (octave `k`, scale `i`, DoG `d`):
//! - `pyramid.png`: all scale images G0..G3 of every octave, one row of images per octave;
//! - `dog_o{k}.png`: the three DoG images side by side, grey 128 = 0, 8 grey levels per DoG
//!   grey level;
//! - `extrema.png`: the input with every refined point as a circle of radius 2·2^k at its
//!   sub-pixel position (red maxima, blue minima; brighter for coarser octaves);
//! - `sobel_mag_o{k}.png`, `sobel_ori_o{k}.png`: magnitude code, and orientation as hue
//!   (brightness from the magnitude, black where there is no gradient).

use image::{GrayImage, Luma, Rgb, RgbImage};
use std::error::Error;
use std::path::{Path, PathBuf};
use stereocal_firmware::fabric::fast::Probe;
use stereocal_firmware::fabric::{Config, Extremum, FastFrontEnd, FrontEnd, SobelEntry};

/// Scale and DoG rows of every octave, as images.
struct Collect {
    scale: Vec<Vec<GrayImage>>,
    dog: Vec<Vec<GrayImage>>,
}

impl Probe for Collect {
    fn scale_row(&mut self, o: u8, s: u8, y: u16, row: &[u16]) {
        let img = &mut self.scale[o as usize][s as usize];
        for (x, &v) in row.iter().enumerate() {
            img.put_pixel(x as u32, y as u32, Luma([(v >> 8) as u8]));
        }
    }
    fn dog_row(&mut self, o: u8, d: u8, y: u16, row: &[i16]) {
        let img = &mut self.dog[o as usize][d as usize];
        for (x, &v) in row.iter().enumerate() {
            img.put_pixel(
                x as u32,
                y as u32,
                Luma([(128 + (v as i32 >> 5)).clamp(0, 255) as u8]),
            );
        }
    }
}

fn hue(ori: u8, mag: u8) -> Rgb<u8> {
    let h = ori as f32 / 64.0 * 6.0;
    let v = (mag as f32 * 4.0).min(255.0);
    let f = h - h.floor();
    let (p, q, t) = (0.0, v * (1.0 - f), v * f);
    let (r, g, b) = match h as u32 % 6 {
        0 => (v, t, p),
        1 => (q, v, p),
        2 => (p, v, t),
        3 => (p, q, v),
        4 => (t, p, v),
        _ => (v, p, q),
    };
    Rgb([r as u8, g as u8, b as u8])
}

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().collect();
    let [_, input, out] = args.as_slice() else {
        return Err("usage: dump_pyramid <image> <outdir>".into());
    };
    let grey = image::open(input)
        .map_err(|e| format!("{input}: {e}"))?
        .into_luma8();
    let (w, h) = grey.dimensions();
    if w > 1280 || h > u16::MAX as u32 {
        return Err(format!("{input}: {w}x{h} is wider than the 1280-pixel line buffers").into());
    }
    let out = PathBuf::from(out);
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;

    let cfg = Config::new(w as u16, h as u16);
    let mut fe = Box::new(FastFrontEnd::<1280, 640, 320, 160>::new());
    fe.start_frame(&cfg).map_err(|e| format!("{input}: {e}"))?;
    let dims: Vec<(u32, u32)> = (0..cfg.octaves)
        .map(|k| {
            let (a, b) =
                stereocal_firmware::fabric::geometry::octave_dims(cfg.width, cfg.height, k);
            (a as u32, b as u32)
        })
        .collect();
    let mut probe = Collect {
        scale: dims
            .iter()
            .map(|&(a, b)| vec![GrayImage::new(a, b); 4])
            .collect(),
        dog: dims
            .iter()
            .map(|&(a, b)| vec![GrayImage::new(a, b); 3])
            .collect(),
    };
    let mut points: Vec<Extremum> = Vec::new();
    let mut sobel: Vec<SobelEntry> = Vec::new();
    let drain = |fe: &mut FastFrontEnd<1280, 640, 320, 160>,
                 p: &mut Vec<Extremum>,
                 s: &mut Vec<SobelEntry>| {
        while let Some(x) = fe.pop_point() {
            p.push(x);
        }
        while let Some(x) = fe.pop_sobel() {
            s.push(x);
        }
    };
    for row in grey.as_raw().chunks_exact(w as usize) {
        fe.push_row_probed(row, &mut probe)?;
        drain(&mut fe, &mut points, &mut sobel);
    }
    while !fe.blank_row_probed(&mut probe) {
        drain(&mut fe, &mut points, &mut sobel);
    }
    drain(&mut fe, &mut points, &mut sobel);
    let o = fe.overflow();
    if o.points + o.sobel > 0 {
        return Err(format!("FIFO overflow: {o:?}").into());
    }

    let save =
        |img: &dyn Fn(&Path) -> image::ImageResult<()>, name: &str| -> Result<(), Box<dyn Error>> {
            let p = out.join(name);
            img(&p).map_err(|e| format!("{}: {e}", p.display()))?;
            Ok(())
        };

    // Pyramid montage: octave k in row k, scales side by side.
    let (mw, mh) = (4 * w, dims.iter().map(|d| d.1).sum::<u32>());
    let mut montage = GrayImage::new(mw, mh);
    let mut y0 = 0;
    for (k, &(ow, oh)) in dims.iter().enumerate() {
        for s in 0..4 {
            image::imageops::replace(
                &mut montage,
                &probe.scale[k][s],
                (s as u32 * ow) as i64,
                y0 as i64,
            );
        }
        y0 += oh;
        let mut d = GrayImage::new(3 * ow, oh);
        for i in 0..3 {
            image::imageops::replace(&mut d, &probe.dog[k][i], (i as u32 * ow) as i64, 0);
        }
        save(&|p| d.save(p), &format!("dog_o{k}.png"))?;
    }
    save(&|p| montage.save(p), "pyramid.png")?;

    // Extrema overlay.
    let mut ov = RgbImage::from_fn(w, h, |x, y| {
        let v = grey.get_pixel(x, y)[0] / 2 + 64;
        Rgb([v, v, v])
    });
    for p in &points {
        let s = (1u32 << p.octave) as f32;
        let cx = (p.x as f32 + p.dx.to_num::<f32>()) * s;
        let cy = (p.y as f32 + p.dy.to_num::<f32>()) * s;
        let r = 2.0 * s;
        let lum = 155 + 25 * p.octave;
        let col = if p.dog > 0 {
            Rgb([lum, 30, 30])
        } else {
            Rgb([30, 60, lum])
        };
        for a in 0..64 {
            let t = a as f32 / 64.0 * std::f32::consts::TAU;
            let (x, y) = (cx + r * t.cos(), cy + r * t.sin());
            if x >= 0.0 && y >= 0.0 && (x as u32) < w && (y as u32) < h {
                ov.put_pixel(x as u32, y as u32, col);
            }
        }
    }
    save(&|p| ov.save(p), "extrema.png")?;

    // Sobel magnitude and orientation per octave.
    for (k, &(ow, oh)) in dims.iter().enumerate() {
        let mut mag = GrayImage::new(ow, oh);
        let mut ori = RgbImage::new(ow, oh);
        for s in sobel.iter().filter(|s| s.octave as usize == k) {
            mag.put_pixel(
                s.x as u32,
                s.y as u32,
                Luma([s.magnitude.saturating_mul(4)]),
            );
            ori.put_pixel(s.x as u32, s.y as u32, hue(s.orientation, s.magnitude));
        }
        save(&|p| mag.save(p), &format!("sobel_mag_o{k}.png"))?;
        save(&|p| ori.save(p), &format!("sobel_ori_o{k}.png"))?;
    }
    let per: Vec<usize> = (0..cfg.octaves)
        .map(|k| points.iter().filter(|p| p.octave == k).count())
        .collect();
    println!(
        "{input}: {w}x{h}, {} points per octave {per:?}, {} Sobel pixels -> {}",
        points.len(),
        sobel.len(),
        out.display()
    );
    Ok(())
}
