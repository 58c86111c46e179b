//! A sweep's points as `dermis compare` measurements: each point one run of
//! its measured frames (the samples its passes kept), keyed by point id.

use super::{Point, Sweep};
use crate::error::{Error, Result};
use crate::profile::compare::{MeasuredFrame, Measurement};
use std::collections::BTreeMap;

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
