//! Writes the wire decoder's fuzz seeds captured from real frames:
//!
//! ```text
//! cargo run --release -p stereocal-tools --example decoder_corpus -- ../shared/data/real shared/fuzz/corpus/decoder
//! ```
//!
//! A 320x240 window of the ETH3D two-view pair `terrace` goes through the
//! in-process device in both Sobel output modes, and the bytes the device sent are cut at frame
//! delimiters into seeds: the first frame of every packet kind that occurs (with its delimiter)
//! and, per mode, the stream's first and last 4 KiB rounded to whole frames (a frame start and
//! its first point batches; the last Sobel packets and the frame end). Seeds stay small so
//! libFuzzer mutates structure, not bulk; the names say where each one came from.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use stereocal::calib::Calibration;
use stereocal::link::{InProcessLink, Recording};
use stereocal::session::{Session, SessionConfig};
use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_wire::{decode, DELIMITER};

/// Window cut from the left and right images (top-left corner, size).
const WINDOW: (u32, u32, u32, u32) = (200, 100, 320, 240);
/// Largest multi-frame seed.
const CHUNK: usize = 4096;

fn main() -> Result<()> {
    let mut args = std::env::args_os().skip(1);
    let (Some(data), Some(out)) = (args.next(), args.next()) else {
        bail!("usage: decoder_corpus <shared/data/real> <corpus directory>");
    };
    let scene = PathBuf::from(data).join("eth3d_two_view/terrace");
    let out = PathBuf::from(out);
    std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
    let left = window(&scene.join("im0.png"))?;
    let right = window(&scene.join("im1.png"))?;
    for (mode, name) in [
        (SobelOutput::Rows, "rows"),
        (SobelOutput::Patches, "patches"),
    ] {
        let bytes = capture(&left, &right, mode)?;
        write_seeds(&bytes, name, &out)?;
    }
    Ok(())
}

/// The grey window of one image.
fn window(path: &Path) -> Result<Vec<u8>> {
    let (x, y, w, h) = WINDOW;
    let img = image::open(path)
        .with_context(|| format!("reading {}", path.display()))?
        .into_luma8();
    Ok(image::imageops::crop_imm(&img, x, y, w, h)
        .to_image()
        .into_raw())
}

/// Every byte the in-process device sends for one pair.
fn capture(left: &[u8], right: &[u8], sobel_output: SobelOutput) -> Result<Vec<u8>> {
    let (_, _, w, h) = WINDOW;
    // The estimate is irrelevant here; any valid head will do.
    let calib = Calibration::from_toml_str(
        "baseline_m = 0.3\n[left]\nfx = 300.0\nfy = 300.0\ncx = 160.0\ncy = 120.0\n\
         [right]\nfx = 300.0\nfy = 300.0\ncx = 160.0\ncy = 120.0\n",
        "decoder_corpus",
    )?;
    let mut device = Recording::new(InProcessLink::new()?);
    let config = SessionConfig {
        sobel_output,
        ..SessionConfig::default()
    };
    let mut session = Session::with_device(&mut device, calib, w as u16, h as u16, config)?;
    session.process(0, Some((left, right)), (w as usize, h as usize), 0, None)?;
    drop(session);
    Ok(device.take_received())
}

/// Cuts `bytes` into delimited frames and writes the seeds named `<mode>-*`.
fn write_seeds(bytes: &[u8], mode: &str, out: &Path) -> Result<()> {
    let frames: Vec<&[u8]> = bytes.split_inclusive(|&b| b == DELIMITER).collect();
    let mut kinds_seen = Vec::new();
    for frame in &frames {
        let mut body = frame.to_vec();
        let Ok((_, packet)) = decode(&mut body) else {
            bail!("{mode}: the device sent a frame that does not decode");
        };
        let kind = format!("{:?}", packet.kind());
        if !kinds_seen.contains(&kind) {
            write(out, &format!("{mode}-{}", kind.to_lowercase()), frame)?;
            kinds_seen.push(kind);
        }
    }
    let head = fitting(frames.iter());
    write(out, &format!("{mode}-head"), &frames[..head].concat())?;
    let tail = fitting(frames.iter().rev());
    write(
        out,
        &format!("{mode}-tail"),
        &frames[frames.len() - tail..].concat(),
    )
}

/// How many of `frames`, taken in order, fit together in [`CHUNK`] bytes (at least one).
fn fitting<'a>(frames: impl Iterator<Item = &'a &'a [u8]>) -> usize {
    let mut len = 0;
    let mut n = 0;
    for frame in frames {
        if n > 0 && len + frame.len() > CHUNK {
            break;
        }
        len += frame.len();
        n += 1;
    }
    n
}

fn write(out: &Path, name: &str, bytes: &[u8]) -> Result<()> {
    let path = out.join(format!("real-{name}"));
    std::fs::write(&path, bytes).with_context(|| format!("writing {}", path.display()))
}
