//! The `stereocal` command line: the calibration library, the renderer and the tools behind
//! one binary (its contract: `docs/ARCHITECTURE.md`, "The command line").

mod command;
mod experiment;
mod hil;
mod inject;
mod live;
mod options;
mod output;
mod real;
mod reliability;
mod synthetic;

use std::process::ExitCode;

use clap::Parser;

fn main() -> ExitCode {
    match command::Cli::parse().run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {}", describe(&err));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line, `outer: inner: …`. Many of our errors already name
/// their cause in their own message (so that a library user printing only the top error sees
/// it too); a cause whose text the message before it already holds is left out.
fn describe(err: &anyhow::Error) -> String {
    let mut out = String::new();
    let mut previous = String::new();
    for cause in err.chain() {
        let text = cause.to_string();
        if !previous.contains(&text) {
            if !out.is_empty() {
                out.push_str(": ");
            }
            out.push_str(&text);
        }
        previous = text;
    }
    out
}
