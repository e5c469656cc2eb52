//! The files of one experiment directory (tables as CSV, figures as PNG), staged and moved
//! into place together, so a failed run never leaves a table beside a stale figure.

use std::path::{Path, PathBuf};

use super::{ExperimentError, Table};
use stereocal::output::output_dir::StagedOutput;
use stereocal::output::plot::{ensure_font, PlotError};

/// Staged tables and figures for one directory.
pub(crate) struct Files {
    dir: PathBuf,
    staged: StagedOutput,
}

impl Files {
    pub(crate) fn new(dir: &Path) -> Result<Self, ExperimentError> {
        Ok(Self {
            dir: dir.to_owned(),
            staged: StagedOutput::new(dir)?,
        })
    }

    /// Stages `table` as `<stem>.csv`.
    pub(crate) fn table(&mut self, table: &Table) -> Result<(), ExperimentError> {
        let name = format!("{}.csv", table.stem);
        let err = |source| ExperimentError::Csv {
            path: self.dir.join(&name),
            source,
        };
        let path = self.staged.path(&name);
        let file = std::fs::File::create(&path).map_err(|e| err(e.into()))?;
        table.write_csv(std::io::BufWriter::new(file)).map_err(err)
    }

    /// Stages the figure `name` drawn by `draw` (with the embedded font registered); errors
    /// name the file's final path.
    pub(crate) fn figure(
        &mut self,
        name: &str,
        draw: impl FnOnce(&Path) -> Result<(), Box<dyn std::error::Error>>,
    ) -> Result<(), ExperimentError> {
        ensure_font();
        let path = self.staged.path(name);
        draw(&path).map_err(|e| {
            ExperimentError::Plot(PlotError {
                path: self.dir.join(name),
                message: e.to_string(),
            })
        })
    }

    /// Moves every staged file into the directory; returns their paths.
    pub(crate) fn commit(self) -> Result<Vec<PathBuf>, ExperimentError> {
        Ok(self.staged.commit()?)
    }
}
