//! What can go wrong while generating.

use std::fmt;
use std::path::PathBuf;

/// A generation failure, naming the file or description entry at fault.
#[derive(Debug)]
pub enum RegenError {
    /// The description is not valid TOML or has unknown/missing keys (toml's message).
    Parse(String),
    /// The description parsed but breaks a rule; `at` names the register/field/port.
    Invalid { at: String, what: String },
    /// Reading the description or writing an output failed.
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

impl fmt::Display for RegenError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RegenError::Parse(msg) => write!(f, "{}: {msg}", crate::DESCRIPTION_PATH),
            RegenError::Invalid { at, what } => {
                write!(f, "{}: {at}: {what}", crate::DESCRIPTION_PATH)
            }
            RegenError::Io { path, source } => write!(f, "{}: {source}", path.display()),
        }
    }
}

impl std::error::Error for RegenError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            RegenError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}
