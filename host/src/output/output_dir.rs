//! An output directory that receives its files all at once or not at all.
//!
//! Files are written into a hidden staging directory beside their destination and renamed into
//! place only when every one of them was written, so an error part-way through a run never
//! leaves a half-written `verge.csv` beside a stale `verge.png`. Every staging directory and
//! temporary file exists in a registry for as long as it exists on disk, so that Ctrl-C
//! ([`remove_staged_on_interrupt`]) removes them too instead of leaving them behind.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// How every staging directory and temporary file of this module begins.
pub const STAGING_PREFIX: &str = ".stereocal-staging-";

/// An output directory that could not be prepared or committed.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {action}: {source}")]
pub struct OutputError {
    /// The directory or file the action was on.
    pub path: PathBuf,
    /// What failed (`cannot create output directory`).
    pub action: &'static str,
    /// The operating system's error.
    pub source: std::io::Error,
}

/// The staging directories and temporary files on disk now. Whoever creates, commits or
/// removes one holds the lock meanwhile, and the interruption handler takes it for good, so
/// an interruption never cuts a commit in half.
static STAGED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn staged() -> MutexGuard<'static, Vec<PathBuf>> {
    // The list stays valid whatever a panicking holder was doing.
    STAGED.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Makes Ctrl-C (SIGINT) remove every staging directory and temporary file that exists, then
/// end the process with status 130. A commit under way finishes first, so a destination holds
/// either all of its previous files or all of the new ones. A process installs one Ctrl-C
/// handler: a command that stops gracefully on Ctrl-C instead (`stereocal live`) does not call
/// this, and writes its files after the stop.
pub fn remove_staged_on_interrupt() -> Result<(), ctrlc::Error> {
    ctrlc::set_handler(|| {
        let staged = staged();
        for path in staged.iter() {
            remove_staged(path);
        }
        std::process::exit(130);
    })
}

/// Removes a staging directory or temporary file that a writer may still be filling: renamed
/// first, so that the writer cannot create files under its name while it is being removed.
fn remove_staged(path: &Path) {
    let mut doomed = path.as_os_str().to_owned();
    doomed.push(".removing");
    let doomed = PathBuf::from(doomed);
    let target = if std::fs::rename(path, &doomed).is_ok() {
        doomed.as_path()
    } else {
        path
    };
    if target.is_dir() {
        let _ = std::fs::remove_dir_all(target);
    } else {
        let _ = std::fs::remove_file(target);
    }
}

/// A hidden directory that is filled and then moved into place whole (`synth` writes a whole
/// sequence so), in the registry for as long as it exists; dropped, it is removed.
pub struct StagingDir {
    path: PathBuf,
}

impl StagingDir {
    /// Creates a fresh staging directory inside `parent`.
    pub fn new_in(parent: &Path) -> std::io::Result<Self> {
        let mut staged = staged();
        let path = tempfile::Builder::new()
            .prefix(STAGING_PREFIX)
            .tempdir_in(parent)?
            .keep();
        staged.push(path.clone());
        Ok(StagingDir { path })
    }

    /// Where to write.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Renames the directory to `dest`, which must not exist or be an empty directory (it is
    /// replaced). An interruption waits for the rename, so `dest` is whole or absent.
    pub fn persist(self, dest: &Path) -> std::io::Result<()> {
        let mut staged = staged();
        if dest.exists() {
            std::fs::remove_dir(dest)?;
        }
        std::fs::rename(&self.path, dest)?;
        staged.retain(|p| *p != self.path);
        Ok(())
    }
}

impl Drop for StagingDir {
    fn drop(&mut self) {
        let mut staged = staged();
        // Nothing to report from a destructor: a directory that cannot be removed stays.
        let _ = std::fs::remove_dir_all(&self.path);
        staged.retain(|p| *p != self.path);
    }
}

/// Files being staged for one output directory.
pub struct StagedOutput {
    dest: PathBuf,
    staging: StagingDir,
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
        let staging = StagingDir::new_in(dest).map_err(|source| OutputError {
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
        self.staging.path.join(name)
    }

    /// Moves every staged file into the destination (renames within one file system are
    /// atomic), then removes the staging directory.
    pub fn commit(self) -> Result<Vec<PathBuf>, OutputError> {
        let _commit = staged();
        let mut written = Vec::new();
        for name in &self.names {
            let from = self.staging.path.join(name);
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
    builder.prefix(STAGING_PREFIX);
    // The mode `fs::write` would give (0o666 less the umask), not a temporary file's 0o600.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
    let mut file = {
        let mut staged = staged();
        let file = builder
            .tempfile_in(dir)
            .map_err(err("cannot create a temporary file beside it"))?;
        staged.push(file.path().to_owned());
        file
    };
    let temporary = file.path().to_owned();
    let written = file.write_all(contents);
    let mut staged = staged();
    // On failure the temporary file is dropped, which removes it, while the lock is held.
    let result = written
        .map_err(err("cannot write the temporary file"))
        .and_then(|()| {
            file.persist(path)
                .map(drop)
                .map_err(|e| err("cannot move the finished file into place")(e.error))
        });
    staged.retain(|p| *p != temporary);
    result
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
    fn the_interruption_handler_knows_a_staging_directory_while_it_exists() {
        let dir = tempfile::tempdir().unwrap();
        let staged_now = |dest: &Path| staged().iter().any(|p| p.starts_with(dest));
        let committed = dir.path().join("committed");
        let mut stage = StagedOutput::new(&committed).unwrap();
        std::fs::write(stage.path("a.csv"), "x").unwrap();
        assert!(staged_now(&committed));
        stage.commit().unwrap();
        assert!(!staged_now(&committed));
        let dropped = dir.path().join("dropped");
        let stage = StagedOutput::new(&dropped).unwrap();
        assert!(staged_now(&dropped));
        drop(stage);
        assert!(!staged_now(&dropped));
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
