//! What `dermis compare` reads: a run report, a folder of them (pooled as
//! runs), or a sweep, whose points are measurements of one run of their
//! measured frames (the samples their passes kept), keyed by point id.

use super::{Point, Sweep};
use crate::error::{Error, Result};
use crate::timing::regression::{MeasuredFrame, Measurement};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One side of `dermis compare`.
pub enum Side {
    /// A report, or a folder of reports pooled as runs; warnings of pooling.
    Runs(Box<Measurement>, Vec<String>),
    /// A sweep's points by id.
    Sweep(Vec<(String, Measurement)>),
}

pub fn load(path: &Path) -> Result<Side> {
    let files = if path.is_dir() {
        let mut files: Vec<PathBuf> = std::fs::read_dir(path)
            .map_err(|source| Error::Io {
                path: path.display().to_string(),
                source,
            })?
            .filter_map(|e| Some(e.ok()?.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "json"))
            .collect();
        files.sort();
        if files.is_empty() {
            return Err(Error::Input(format!(
                "{}: no .json reports in this folder",
                path.display()
            )));
        }
        files
    } else {
        vec![path.to_path_buf()]
    };
    let text = std::fs::read_to_string(&files[0]).map_err(|source| Error::Io {
        path: files[0].display().to_string(),
        source,
    })?;
    if files.len() == 1 && text.contains("\"points\"") && !text.contains("\"per_frame\"") {
        let sweep = super::load(&files[0])?;
        let source = files[0].display().to_string();
        return Ok(Side::Sweep(measurements(&sweep, &source)?));
    }
    let (mut m, warnings) = pool(&files)?;
    if files.len() > 1 {
        m.source = format!("{} ({} reports)", path.display(), files.len());
    }
    Ok(Side::Runs(Box::new(m), warnings))
}

/// Run reports read and pooled as runs of one setup, with pooling's warnings.
pub fn pool(files: &[PathBuf]) -> Result<(Measurement, Vec<String>)> {
    let parts = files
        .iter()
        .map(|f| {
            let text = std::fs::read_to_string(f).map_err(|source| Error::Io {
                path: f.display().to_string(),
                source,
            })?;
            Measurement::from_report_json(&text, &f.display().to_string())
        })
        .collect::<Result<Vec<_>>>()?;
    Measurement::pool(parts)
}

/// Every point of `sweep` with its samples; `source` names the file.
pub fn measurements(sweep: &Sweep, source: &str) -> Result<Vec<(String, Measurement)>> {
    if sweep.fingerprint.device.is_empty() {
        return Err(Error::Input(format!(
            "{source}: a sweep written before fingerprints and samples: run it again"
        )));
    }
    Ok(sweep
        .points
        .iter()
        .map(|p| (p.id.clone(), measurement(sweep, p, source)))
        .collect())
}

fn measurement(sweep: &Sweep, p: &Point, source: &str) -> Measurement {
    let frames = p
        .passes
        .iter()
        .map(|s| s.samples_ns.len())
        .max()
        .unwrap_or(0);
    let v = p.variant;
    let setup = [
        ("scene", sweep.scene.clone()),
        ("environment", sweep.environment.clone()),
        ("render_width", sweep.width.to_string()),
        ("render_height", sweep.height.to_string()),
        ("irradiance_resolution", v.resolution.to_string()),
        ("kernel", super::name(&v.kernel)),
        ("chain", super::name(&v.chain)),
        ("view", "final".into()),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    Measurement {
        source: format!("{source} {}", p.id),
        fingerprint: sweep.fingerprint.clone(),
        setup,
        pass_order: p.passes.iter().map(|s| s.name.clone()).collect(),
        texels: p
            .passes
            .iter()
            .filter_map(|s| Some((s.name.clone(), s.texels?)))
            .collect(),
        frames: (0..frames)
            .map(|i| MeasuredFrame {
                run: format!("{} {}", sweep.run_id, p.id),
                passes: p
                    .passes
                    .iter()
                    .filter_map(|s| Some((s.name.clone(), (*s.samples_ns.get(i)?)?)))
                    .collect::<BTreeMap<_, _>>(),
            })
            .collect(),
    }
}
