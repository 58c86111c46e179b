//! Writing a sweep's files (each through [`super::atomic`]).

use super::{csv, plot, Sweep};
use crate::atomic::write_atomic;
use crate::error::{Error, Result};
use std::path::Path;

pub fn json(sweep: &Sweep) -> Result<String> {
    serde_json::to_string_pretty(sweep).map_err(|e| Error::Input(format!("sweep.json: {e}")))
}

/// `sweep.csv` and the plots (what `--replot` redraws).
pub fn write_csv_and_plots(sweep: &Sweep, dir: &Path) -> Result<()> {
    write_atomic(&dir.join("sweep.csv"), csv(sweep))?;
    plot::write_plots(sweep, dir)
}

/// `sweep.json`, `sweep.csv` and the plots into `dir` (created).
pub fn write_all(sweep: &Sweep, dir: &Path) -> Result<()> {
    create_dir(dir)?;
    write_atomic(&dir.join("sweep.json"), &json(sweep)?)?;
    write_csv_and_plots(sweep, dir)
}

/// Creates `dir` and its parents; an error names it.
pub fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| Error::Io {
        path: dir.display().to_string(),
        source,
    })
}
