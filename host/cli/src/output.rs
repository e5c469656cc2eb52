//! What every estimating command does at the end: the files, the table or the JSON.

use std::path::Path;

use indicatif::{ProgressBar, ProgressStyle};
use stereocal::output::record::FrameRecord;
use stereocal::output::report::{summary_table, write_outputs, TableExtras};
use stereocal::output::summary::Summary;
use stereocal::session::tuned_fabric_config;
use stereocal_firmware::fabric::latency::first_pixel_of_last_octave;
use stereocal_hdl::regs::output_mode::SobelOutput;

/// How a command finishes.
pub struct Finish<'a> {
    /// Directory for verge.csv and verge.png, if any.
    pub out: Option<&'a Path>,
    /// Also matches.csv there (the records keep their pairs: [`SessionConfig::keep_pairs`]).
    ///
    /// [`SessionConfig::keep_pairs`]: stereocal::session::SessionConfig::keep_pairs
    pub matches: bool,
    /// JSON on stdout instead of the table.
    pub json: bool,
    /// Title of the plot and the table.
    pub title: &'a str,
    /// Fields the command adds to the JSON summary (e.g. `hil`'s instruction counts).
    pub json_extra: serde_json::Map<String, serde_json::Value>,
}

/// A progress bar on stderr; indicatif hides it when stderr is not a terminal.
pub fn progress_bar(len: u64, message: &'static str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    if let Ok(style) =
        ProgressStyle::with_template("{msg} {bar:40} {pos}/{len} frame pairs [{elapsed}<{eta}]")
    {
        bar.set_style(style);
    }
    bar.set_message(message);
    bar
}

/// Adds `record` to `records`, saying on stderr why its pair was dropped if it was (above
/// the progress bar, which stays).
pub fn keep(records: &mut Vec<FrameRecord>, record: FrameRecord, bar: &ProgressBar) {
    if let Some(why) = &record.dropped_because {
        bar.suspend(|| eprintln!("frame {}: dropped: {why}", record.frame));
    }
    bar.inc(1);
    records.push(record);
}

/// Writes the files (all or none), then prints the summary.
pub fn finish(
    records: &[FrameRecord],
    summary: &Summary,
    truth_known: bool,
    (width, height): (u32, u32),
    how: Finish<'_>,
) -> anyhow::Result<()> {
    let written = match how.out {
        Some(dir) => write_outputs(dir, records, how.title, how.matches)?,
        None => Vec::new(),
    };
    if how.json {
        let mut json = serde_json::to_value(summary)?;
        if let Some(object) = json.as_object_mut() {
            object.extend(how.json_extra);
        }
        println!("{}", serde_json::to_string_pretty(&json)?);
    } else {
        // The latency does not depend on the Sobel output mode.
        let fabric = tuned_fabric_config(width as u16, height as u16, SobelOutput::Rows);
        let latency = first_pixel_of_last_octave(fabric.width, fabric.height, fabric.octaves);
        let extras = TableExtras {
            rows: vec![
                ("image size".into(), format!("{width}x{height}")),
                (
                    "pipeline latency".into(),
                    format!(
                        "{latency} clocks (first pixel in to first pixel of octave {})",
                        fabric.octaves - 1
                    ),
                ),
            ],
        };
        println!("{}", how.title);
        print!("{}", summary_table(summary, truth_known, &extras));
    }
    // The table is on stdout, the file list on stderr: keep them in that order on a terminal.
    std::io::Write::flush(&mut std::io::stdout())?;
    for path in written {
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
