//! The calibration library inside a user's program: their own frame source in, a verge per
//! frame out.
//!
//! ```text
//! cargo run --release -p stereocal --example embed                         # a rendered head
//! cargo run --release -p stereocal --example embed -- LEFT/ RIGHT/ CALIB   # your image directories
//! ```
//!
//! A program with cameras of its own replaces [`FrameSource`] with its grabber: anything that
//! yields two 8-bit grey images of one size and their capture time. The session does the
//! rest (device, wire, estimator, filter) and returns one record per pair, in order.

use std::error::Error;
use std::path::Path;
use std::process::ExitCode;

use stereocal::calib::Calibration;
use stereocal::image_sequence::{SizeLimits, StereoSequence};
use stereocal::output::record::FrameRecord;
use stereocal::session::{tuned_fabric_config, Session, SessionConfig};
use stereocal_hdl::regs::output_mode::SobelOutput;
use stereocal_synth::{SceneKind, Sequence, SequenceConfig};

/// One stereo pair from the user's cameras.
struct Pair {
    left: Vec<u8>,
    right: Vec<u8>,
    width: usize,
    height: usize,
    timestamp_us: u64,
}

/// What the program grabs its pairs from.
trait FrameSource {
    /// The pair after the last one, `None` at the end.
    fn next_pair(&mut self) -> Result<Option<Pair>, Box<dyn Error>>;
}

/// Image directories (`left/`, `right/`), paired by sorted file name, 10 pairs per second,
/// cropped to the sides the fabric takes.
struct Directories {
    sequence: StereoSequence,
    /// The fabric halves the image once per octave after the first, so its sides are
    /// multiples of this.
    step: usize,
    next: usize,
}

impl FrameSource for Directories {
    fn next_pair(&mut self) -> Result<Option<Pair>, Box<dyn Error>> {
        if self.next == self.sequence.len() {
            return Ok(None);
        }
        let (left, right) = self.sequence.pair(self.next, None)?;
        let (width, height) = (
            left.width / self.step * self.step,
            left.height / self.step * self.step,
        );
        let (Some(left), Some(right)) = (left.cropped(width, height), right.cropped(width, height))
        else {
            return Err(format!("pair {} is smaller than {width}x{height}", self.next).into());
        };
        let timestamp_us = self.next as u64 * 100_000;
        self.next += 1;
        Ok(Some(Pair {
            width: left.width,
            height: left.height,
            left: left.pixels,
            right: right.pixels,
            timestamp_us,
        }))
    }
}

/// The renderer's road scene, standing in for cameras when no directories are given.
struct Rendered {
    sequence: Sequence,
    next: usize,
}

impl FrameSource for Rendered {
    fn next_pair(&mut self) -> Result<Option<Pair>, Box<dyn Error>> {
        while self.next < self.sequence.len() {
            let frame = self.sequence.frame(self.next)?;
            self.next += 1;
            if let Some(images) = frame.images {
                return Ok(Some(Pair {
                    width: images.left.width() as usize,
                    height: images.left.height() as usize,
                    left: images.left.into_raw(),
                    right: images.right.into_raw(),
                    timestamp_us: frame.timestamp_us,
                }));
            }
        }
        Ok(None)
    }
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mut source, calib): (Box<dyn FrameSource>, Calibration) = match args.as_slice() {
        [left, right, calib] => {
            let limits = SizeLimits::fabric();
            let sequence = StereoSequence::open(Path::new(left), Path::new(right), limits)?;
            let octaves = tuned_fabric_config(16, 16, SobelOutput::Rows).octaves;
            let directories = Directories {
                sequence,
                step: 1 << (octaves - 1),
                next: 0,
            };
            (Box::new(directories), Calibration::load(calib)?)
        }
        [] => {
            let config = SequenceConfig {
                frames: 20,
                ..SequenceConfig::for_scene(SceneKind::Road)
            };
            let sequence = Sequence::builtin(SceneKind::Road, config)?;
            let calib = Calibration::from_toml_str(&sequence.calib_toml(), "<rendered head>")?;
            (Box::new(Rendered { sequence, next: 0 }), calib)
        }
        _ => return Err("usage: embed [LEFT_DIR RIGHT_DIR CALIB_FILE]".into()),
    };

    // The session starts on the first pair, when the image size is known.
    let mut session: Option<Session> = None;
    let mut frame = 0;
    while let Some(pair) = source.next_pair()? {
        let session = match &mut session {
            Some(session) => session,
            None => session.insert(Session::new(
                calib,
                u16::try_from(pair.width)?,
                u16::try_from(pair.height)?,
                SessionConfig::default(),
            )?),
        };
        let images = Some((pair.left.as_slice(), pair.right.as_slice()));
        let size = (pair.width, pair.height);
        // The device works a pair ahead: a record comes out once the next pair is in.
        if let Some(record) = session.submit(frame, images, size, pair.timestamp_us, None)? {
            print_record(&record);
        }
        frame += 1;
    }
    if let Some(session) = &mut session {
        while let Some(record) = session.flush()? {
            print_record(&record);
        }
    }
    Ok(())
}

fn print_record(record: &FrameRecord) {
    let deg = |v: Option<f64>| v.map_or_else(|| "-".to_owned(), |v| format!("{v:+.4}°"));
    println!(
        "pair {:3}: raw {:>9}  filtered {:>9}  ({:?}, {} inliers)",
        record.frame,
        deg(record.raw_verge_deg),
        deg(record.filtered_verge_deg),
        record.status,
        record.inliers
    );
}
