//! An output directory that receives its files all at once or not at all.
//!
//! Files are written into a hidden staging directory beside their destination and renamed into
//! place only when every one of them was written, so an error (or Ctrl-C) part-way through a run
//! never leaves a half-written `verge.csv` beside a stale `verge.png`.

use std::io::Write;
use std::path::{Path, PathBuf};

/// An output directory that could not be prepared or committed.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {action}: {source}")]
pub struct OutputError {
    pub path: PathBuf,
    pub action: &'static str,
    pub source: std::io::Error,
}

/// Files being staged for one output directory.
pub struct StagedOutput {
    dest: PathBuf,
    staging: tempfile::TempDir,
    names: Vec<String>,
}

impl StagedOutput {
    /// Creates `dest` if needed and a staging directory inside it.
    pub fn new(dest: &Path) -> Result<Self, OutputError> {
        std::fs::create_dir_all(dest).map_err(|source| OutputError {
            path: dest.to_owned(),
            action: "cannot create output directory",
            source,
        })?;
        let staging = tempfile::Builder::new()
            .prefix(".stereocal-staging-")
            .tempdir_in(dest)
            .map_err(|source| OutputError {
                path: dest.to_owned(),
                action: "cannot create a staging directory",
                source,
            })?;
        Ok(StagedOutput {
            dest: dest.to_owned(),
            staging,
            names: Vec::new(),
        })
    }

    /// Where to write the file `name` now; it appears in the destination on `commit`.
    pub fn path(&mut self, name: &str) -> PathBuf {
        if !self.names.iter().any(|n| n == name) {
            self.names.push(name.to_owned());
        }
        self.staging.path().join(name)
    }

    /// Moves every staged file into the destination. Renames within one directory are atomic.
    pub fn commit(self) -> Result<Vec<PathBuf>, OutputError> {
        let mut written = Vec::new();
        for name in &self.names {
            let from = self.staging.path().join(name);
            let to = self.dest.join(name);
            std::fs::rename(&from, &to).map_err(|source| OutputError {
                path: to.clone(),
                action: "cannot move the finished file into place",
                source,
            })?;
            written.push(to);
        }
        Ok(written)
    }
}

/// Replaces the file at `path` with `contents` by one rename from a temporary file beside it,
/// so an error or a kill part-way leaves the previous file whole (a document in the
/// repository, say, that a long run regenerates).
pub fn write_atomically(path: &Path, contents: &[u8]) -> Result<(), OutputError> {
    let err = |action| {
        move |source| OutputError {
            path: path.to_owned(),
            action,
            source,
        }
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".stereocal-staging-");
    // The mode `fs::write` would give (0o666 less the umask), not a temporary file's 0o600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut file = builder
        .tempfile_in(dir)
        .map_err(err("cannot create a temporary file beside it"))?;
    file.write_all(contents)
        .map_err(err("cannot write the temporary file"))?;
    file.persist(path)
        .map_err(|e| err("cannot move the finished file into place")(e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn files_appear_only_on_commit() {
        let dir = tempfile::tempdir().unwrap();
        let dest = dir.path().join("out");
        let mut staged = StagedOutput::new(&dest).unwrap();
        std::fs::write(staged.path("a.csv"), "x").unwrap();
        assert!(!dest.join("a.csv").exists());
        let written = staged.commit().unwrap();
        assert_eq!(written, vec![dest.join("a.csv")]);
        assert_eq!(std::fs::read_to_string(dest.join("a.csv")).unwrap(), "x");
        let leftovers: Vec<_> = std::fs::read_dir(&dest).unwrap().collect();
        assert_eq!(leftovers.len(), 1, "staging directory removed");
    }

    #[test]
    fn dropped_stage_leaves_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let dest = dir.path().join("out");
        let mut staged = StagedOutput::new(&dest).unwrap();
        std::fs::write(staged.path("a.csv"), "x").unwrap();
        drop(staged);
        assert_eq!(std::fs::read_dir(&dest).unwrap().count(), 0);
    }

    #[test]
    fn a_file_written_atomically_replaces_the_old_one_and_leaves_nothing_beside_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("doc.md");
        std::fs::write(&path, "old").unwrap();
        write_atomically(&path, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        let missing = dir.path().join("no-such-dir").join("doc.md");
        let e = write_atomically(&missing, b"x").unwrap_err();
        assert!(e.to_string().contains("no-such-dir"), "{e}");
    }
}
