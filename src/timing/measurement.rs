//! What `dermis compare` compares: one side's measured frames (of one or more
//! runs, pooled), read from run reports, and a pass's samples from them — one
//! per run (the median of its frames) or one per frame, in ns or over the
//! ruler.

use super::fingerprint::Fingerprint;
use super::run::{is_ruler, RunReport, RULER_COPY, SCHEMA_VERSION};
use super::stats::median;
use crate::error::{Error, Result};
use serde::Serialize;
use std::collections::BTreeMap;

/// The row of each frame's passes summed (rulers excluded).
pub const FRAME_ROW: &str = "frame (sum of passes)";

/// Setup keys that vary between identical runs (the metered exposure).
const RUN_KEYS: [&str; 1] = ["exposure_ev"];

/// One side of a comparison: the measured (post-warm-up) frames of one or
/// more runs, and where they were measured.
#[derive(Clone, Debug, Default)]
pub struct Measurement {
    /// The files it was read from.
    pub source: String,
    pub fingerprint: Fingerprint,
    /// The setup as key → value text (RunSetup's JSON fields).
    pub setup: BTreeMap<String, String>,
    /// Pass names in first-seen order.
    pub pass_order: Vec<String>,
    /// Texels each pass computes (for × ruler).
    pub texels: BTreeMap<String, u64>,
    pub frames: Vec<MeasuredFrame>,
}

/// One measured frame: its run (a key unique across pooled reports) and
/// each pass's time in ns.
#[derive(Clone, Debug, Default)]
pub struct MeasuredFrame {
    pub run: String,
    pub passes: BTreeMap<String, f64>,
}

/// Refuses what is not a run report this dermis reads: no `schema_version`
/// (older than schema 2, or not a report), or a newer one than
/// [`SCHEMA_VERSION`].
pub fn check_report_schema(value: &serde_json::Value, source: &str) -> Result<()> {
    match value.get("schema_version").and_then(|v| v.as_u64()) {
        Some(v) if v > u64::from(SCHEMA_VERSION) => Err(Error::Input(format!(
            "{source}: report schema {v} is newer than this dermis reads ({SCHEMA_VERSION})"
        ))),
        None if value.get("per_frame").is_some() => Err(Error::Input(format!(
            "{source}: a report older than schema 2 (no fingerprint): render it again"
        ))),
        None => Err(Error::Input(format!(
            "{source}: not a dermis run report (no schema_version)"
        ))),
        Some(_) => Ok(()),
    }
}

impl Measurement {
    /// The measured frames of a run report (schema 2 or later).
    pub fn from_report(report: &RunReport, source: &str) -> Result<Self> {
        if report.schema_version < 2 {
            return Err(Error::Input(format!(
                "{source}: report schema {} is older than 2 (no fingerprint): render it again",
                report.schema_version
            )));
        }
        let setup = flat_setup(&report.setup)?;
        let frames = report
            .measured()
            .map(|f| MeasuredFrame {
                run: format!("{}#{}", report.run_id, f.run),
                passes: first_of_each(f),
            })
            .collect();
        Ok(Self {
            source: source.to_string(),
            fingerprint: report.fingerprint.clone(),
            setup,
            pass_order: report.passes.iter().map(|p| p.name.clone()).collect(),
            texels: report
                .passes
                .iter()
                .filter_map(|p| Some((p.name.clone(), p.texels?)))
                .collect(),
            frames,
        })
    }

    /// Reads a report (`--report FILE.json`) from its JSON text.
    pub fn from_report_json(text: &str, source: &str) -> Result<Self> {
        let value: serde_json::Value = serde_json::from_str(text)
            .map_err(|e| Error::Input(format!("{source}: not JSON: {e}")))?;
        check_report_schema(&value, source)?;
        let report: RunReport = serde_json::from_value(value)
            .map_err(|e| Error::Input(format!("{source}: not a dermis run report: {e}")))?;
        Self::from_report(&report, source)
    }

    /// Several measurements of one configuration as one (e.g. one report per
    /// process of an interleaved run): setups must agree; differing machines
    /// are returned as warnings.
    pub fn pool(parts: Vec<Measurement>) -> Result<(Self, Vec<String>)> {
        let mut parts = parts.into_iter();
        let mut all = parts
            .next()
            .ok_or_else(|| Error::Input("no measurement to pool".into()))?;
        let mut warnings = Vec::new();
        for m in parts {
            let diff = setup_differences(&all.setup, &m.setup);
            if !diff.is_empty() {
                return Err(Error::Input(format!(
                    "{} and {} were rendered with different setups ({}): pool only runs of one setup",
                    all.source,
                    m.source,
                    diff.join(", ")
                )));
            }
            for d in all.fingerprint.differences(&m.fingerprint) {
                warnings.push(format!("{} vs {}: {d}", all.source, m.source));
            }
            for p in &m.pass_order {
                if !all.pass_order.contains(p) {
                    all.pass_order.push(p.clone());
                }
            }
            all.texels.extend(m.texels);
            all.frames.extend(m.frames);
            all.source = format!("{}, {}", all.source, m.source);
        }
        Ok((all, warnings))
    }

    pub(super) fn runs(&self) -> usize {
        let mut runs: Vec<&str> = self.frames.iter().map(|f| f.run.as_str()).collect();
        runs.sort_unstable();
        runs.dedup();
        runs.len()
    }

    pub(super) fn has_ruler(&self) -> bool {
        !self.frames.is_empty()
            && self
                .frames
                .iter()
                .all(|f| f.passes.contains_key(RULER_COPY))
    }
}

/// Each pass's time in a frame; of two passes of one name the first, as the
/// report's statistics take it (FrameTiming::pass_ns).
fn first_of_each(f: &super::FrameTiming) -> BTreeMap<String, f64> {
    let mut out = BTreeMap::new();
    for p in &f.passes {
        if let Some(ns) = p.gpu_ns.filter(|v| v.is_finite()) {
            out.entry(p.name.clone()).or_insert(ns);
        }
    }
    out
}

/// The setup's fields as text, for comparing setups.
fn flat_setup(setup: &impl Serialize) -> Result<BTreeMap<String, String>> {
    let value = serde_json::to_value(setup).map_err(|e| Error::Input(e.to_string()))?;
    let mut out = BTreeMap::new();
    if let serde_json::Value::Object(map) = value {
        for (k, v) in map {
            let text = match v {
                serde_json::Value::String(s) => s,
                other => other.to_string(),
            };
            out.insert(k, text);
        }
    }
    Ok(out)
}

/// "kernel: deon7 → accurate" per differing key (run-to-run keys left out).
pub(super) fn setup_differences(
    a: &BTreeMap<String, String>,
    b: &BTreeMap<String, String>,
) -> Vec<String> {
    let keys: std::collections::BTreeSet<&String> = a.keys().chain(b.keys()).collect();
    keys.into_iter()
        .filter(|k| !RUN_KEYS.contains(&k.as_str()))
        .filter_map(|k| {
            let (x, y) = (a.get(k), b.get(k));
            (x != y).then(|| {
                format!(
                    "{k}: {} → {}",
                    x.map_or("–", String::as_str),
                    y.map_or("–", String::as_str)
                )
            })
        })
        .collect()
}

/// A pass's samples: per frame, or per run (the median of its frames), in ns
/// or over the ruler — per frame the same frame's ruler; per run the run's
/// median ruler, which is steadier than any one frame's. `FRAME_ROW` sums the
/// non-ruler passes.
pub(super) fn samples(m: &Measurement, name: &str, in_ruler: bool, by_run: bool) -> Vec<f64> {
    let ns = |f: &MeasuredFrame| -> Option<f64> {
        if name == FRAME_ROW {
            let v: f64 = f
                .passes
                .iter()
                .filter(|(n, _)| !is_ruler(n))
                .map(|(_, v)| v)
                .sum();
            (v > 0.0).then_some(v)
        } else {
            f.passes.get(name).copied()
        }
    };
    let ruler = |f: &MeasuredFrame| f.passes.get(RULER_COPY).copied().filter(|&r| r > 0.0);
    if !by_run {
        return m
            .frames
            .iter()
            .filter_map(|f| match in_ruler {
                true => Some(ns(f)? / ruler(f)?),
                false => ns(f),
            })
            .collect();
    }
    let mut runs: Vec<&str> = Vec::new();
    for f in &m.frames {
        if !runs.contains(&f.run.as_str()) {
            runs.push(&f.run);
        }
    }
    runs.iter()
        .filter_map(|run| {
            let frames = m.frames.iter().filter(|f| f.run == *run);
            let time = median(&frames.clone().filter_map(ns).collect::<Vec<_>>())?;
            match in_ruler {
                true => Some(time / median(&frames.filter_map(ruler).collect::<Vec<_>>())?),
                false => Some(time),
            }
        })
        .collect()
}

/// A pass `X` one side runs whole and the other as `X_u` then `X_v` (a blur
/// level one build blurs in one stencil pass, another in two): `side`'s two are joined,
/// frame by frame, into one pass `X` in `X_u`'s place, counted at `X_v`'s
/// texels (the level's), so the rows compare like with like. Returns what was
/// joined.
pub(super) fn join_split_passes(side: &mut Measurement, other: &Measurement) -> Vec<String> {
    let mut joined = Vec::new();
    for name in &other.pass_order {
        let (u, v) = (format!("{name}_u"), format!("{name}_v"));
        let split = |m: &Measurement| m.pass_order.contains(&u) && m.pass_order.contains(&v);
        if side.pass_order.contains(name) || !split(side) || split(other) {
            continue;
        }
        for f in &mut side.frames {
            if let (Some(a), Some(b)) = (f.passes.remove(&u), f.passes.remove(&v)) {
                f.passes.insert(name.clone(), a + b);
            }
        }
        side.pass_order.retain(|p| *p != v);
        if let Some(p) = side.pass_order.iter_mut().find(|p| **p == u) {
            *p = name.clone();
        }
        if let Some(t) = side.texels.get(&v).copied() {
            side.texels.insert(name.clone(), t);
        }
        joined.push(format!("{name} = {u} + {v} in {}", side.source));
    }
    joined
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pooling_joins_runs_of_one_setup_only() {
        let a = frames(3);
        let mut b = frames(3);
        for f in &mut b.frames {
            f.run = "other".into();
        }
        let (all, warnings) = Measurement::pool(vec![a.clone(), b.clone()]).unwrap();
        assert_eq!((all.frames.len(), all.runs()), (6, 2));
        assert!(warnings.is_empty());
        b.setup.insert("view".into(), "irradiance".into());
        assert!(Measurement::pool(vec![a, b]).is_err());
    }

    /// One run of `n` frames of pass "blur" at 1 ns.
    fn frames(n: usize) -> Measurement {
        Measurement {
            source: "m".into(),
            pass_order: vec!["blur".into()],
            frames: (0..n)
                .map(|_| MeasuredFrame {
                    run: "run0".into(),
                    passes: [("blur".to_string(), 1.0)].into(),
                })
                .collect(),
            ..Default::default()
        }
    }
}
