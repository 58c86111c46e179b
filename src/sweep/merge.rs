//! `dermis sweep merge`: the points logs of a sweep's shards into one sweep,
//! the same in structure as an unsharded run's (points in canonical order).
//!
//! Every run (header and its points) of every log is read. All must have this
//! dermis's schema version and one sweep hash. Runs are taken in order of their
//! header's timestamp, ties by input order (the arguments in order, a folder's
//! `*.jsonl` by name), then by position in the file; a point seen again in a
//! later run replaces the earlier one (a retried Kubernetes pod's, a re-run
//! GitHub job's). Every point of the sweep must then be present.

use super::log::{self, Segment};
use super::points::SWEEP_SCHEMA_VERSION;
use super::shard::{self, Mode, Shard, Spec};
use super::{ShardRun, Sweep};
use crate::error::{Error, Result};
use crate::timing::fingerprint::{run_id, timestamp};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, Default)]
pub struct MergeOptions {
    /// Merge shards whose reference images differ (a warning instead of an error).
    pub allow_reference_mismatch: bool,
}

pub struct Merged {
    pub sweep: Sweep,
    /// Fingerprint and reference differences, duplicates replaced, lines skipped.
    pub warnings: Vec<String>,
}

/// The logs named: files as given, folders' `*.jsonl` sorted by name.
pub fn inputs(paths: &[PathBuf]) -> Result<Vec<PathBuf>> {
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(p)
                .map_err(|source| Error::Io {
                    path: p.display().to_string(),
                    source,
                })?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|f| f.is_file() && f.extension().is_some_and(|x| x == "jsonl"))
                .collect();
            found.sort();
            if found.is_empty() {
                return Err(Error::Input(format!(
                    "sweep merge: {} holds no *.jsonl points logs",
                    p.display()
                )));
            }
            out.extend(found);
        } else if p.is_file() {
            out.push(p.clone());
        } else {
            return Err(Error::Input(format!(
                "sweep merge: {}: no such file or folder",
                p.display()
            )));
        }
    }
    if out.is_empty() {
        return Err(Error::Input(
            "sweep merge: give at least one folder or file".into(),
        ));
    }
    Ok(out)
}

/// Reads and merges the logs under `paths`.
pub fn merge(paths: &[PathBuf], opts: MergeOptions) -> Result<Merged> {
    let mut warnings = Vec::new();
    let mut segments = Vec::new();
    for f in inputs(paths)? {
        segments.extend(log::read(&f, &mut warnings)?);
    }
    let mut merged = merge_segments(segments, opts)?;
    warnings.append(&mut merged.warnings);
    merged.warnings = warnings;
    Ok(merged)
}

fn files_by(segments: &[Segment], key: impl Fn(&Segment) -> String) -> String {
    let mut by: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for s in segments {
        let f = s.file.display().to_string();
        let files = by.entry(key(s)).or_default();
        if !files.contains(&f) {
            files.push(f);
        }
    }
    by.iter()
        .map(|(k, files)| format!("{k}: {}", files.join(", ")))
        .collect::<Vec<_>>()
        .join("; ")
}

/// Merges runs given in input order (see the module's doc for "later").
pub fn merge_segments(mut segments: Vec<Segment>, opts: MergeOptions) -> Result<Merged> {
    if segments.is_empty() {
        return Err(Error::Input("sweep merge: no runs to merge".into()));
    }
    if segments
        .iter()
        .any(|s| s.header.schema_version != SWEEP_SCHEMA_VERSION)
    {
        return Err(Error::Input(format!(
            "sweep merge: schema versions differ from this dermis's ({SWEEP_SCHEMA_VERSION}): {}",
            files_by(&segments, |s| format!("schema {}", s.header.schema_version))
        )));
    }
    let hash = segments[0].header.sweep_hash.clone();
    if segments.iter().any(|s| s.header.sweep_hash != hash) {
        return Err(Error::Input(format!(
            "sweep merge: the logs are of different sweeps (scene, points, frames, size or \
             reference differ): {}",
            files_by(&segments, |s| format!("sweep {}", s.header.sweep_hash))
        )));
    }
    let mut warnings = Vec::new();
    let checksum = segments[0].header.reference_checksum.clone();
    if segments
        .iter()
        .any(|s| s.header.reference_checksum != checksum)
    {
        let what = format!(
            "the shards' reference images differ, so their errors are not measured against \
             the same image: {}",
            files_by(&segments, |s| format!(
                "reference {}",
                s.header.reference_checksum
            ))
        );
        if !opts.allow_reference_mismatch {
            return Err(Error::Input(format!(
                "sweep merge: {what} (--allow-reference-mismatch merges anyway)"
            )));
        }
        warnings.push(what);
    }
    let first = segments[0].header.clone();
    for s in &segments[1..] {
        let d = first.fingerprint.differences(&s.header.fingerprint);
        if !d.is_empty() {
            warnings.push(format!(
                "{} (run {}) ran elsewhere than {} (run {}): {}; its timings are not comparable",
                s.file.display(),
                s.header.run_id,
                segments[0].file.display(),
                first.run_id,
                d.join(", ")
            ));
        }
    }
    // Stable: equal timestamps keep input order.
    segments.sort_by(|a, b| a.header.timestamp.cmp(&b.header.timestamp));
    let ids = first.sweep_points.clone();
    // id → (segment, point), the later replacing the earlier.
    let mut taken: BTreeMap<String, (usize, super::Point)> = BTreeMap::new();
    for (si, s) in segments.iter().enumerate() {
        for p in &s.points {
            if !ids.contains(&p.id) {
                return Err(Error::Input(format!(
                    "sweep merge: {} holds point {:?}, which is not in sweep {hash}",
                    s.file.display(),
                    p.id
                )));
            }
            if let Some((prev, _)) = taken.get(&p.id) {
                warnings.push(format!(
                    "point {} appears more than once; the later run's is kept ({} run {} \
                     replaces {} run {})",
                    p.id,
                    s.file.display(),
                    s.header.run_id,
                    segments[*prev].file.display(),
                    segments[*prev].header.run_id
                ));
            }
            taken.insert(p.id.clone(), (si, p.clone()));
        }
    }
    let missing: Vec<String> = ids
        .iter()
        .filter(|id| !taken.contains_key(*id))
        .map(|id| {
            let owners: Vec<String> = segments
                .iter()
                .filter(|s| s.header.shard_points.contains(id))
                .map(|s| format!("{} of {}", s.header.shard, s.file.display()))
                .collect();
            match owners.is_empty() {
                true => format!("{id} (no log's shard includes it: is a shard's log missing?)"),
                false => format!("{id} (shard {} did not finish it)", owners.join(", ")),
            }
        })
        .collect();
    if !missing.is_empty() {
        let absent = absent_shards(&segments, &ids);
        let absent = match absent.is_empty() {
            true => String::new(),
            false => format!(
                "; no log of {} among the inputs (did that task fail, or write elsewhere?)",
                absent.join(", ")
            ),
        };
        return Err(Error::Input(format!(
            "sweep merge: {} of {} points missing: {}{absent}",
            missing.len(),
            ids.len(),
            missing.join("; ")
        )));
    }
    let mut sweep = first.sweep();
    sweep.run_id = run_id();
    sweep.timestamp = timestamp();
    sweep.shards = segments
        .iter()
        .enumerate()
        .map(|(si, s)| ShardRun {
            file: s.file.display().to_string(),
            shard: s.header.shard.clone(),
            run_id: s.header.run_id.clone(),
            timestamp: s.header.timestamp.clone(),
            fingerprint: s.header.fingerprint.clone(),
            reference_checksum: s.header.reference_checksum.clone(),
            points: ids
                .iter()
                .filter(|id| taken[*id].0 == si)
                .cloned()
                .collect(),
        })
        .collect();
    sweep.points = ids
        .iter()
        .filter_map(|id| taken.remove(id).map(|(_, p)| p))
        .collect();
    Ok(Merged { sweep, warnings })
}

/// The shards of the partitions the logs come from (`hash:2/3`: every shard of
/// 3 by hash) that no log is of, each with its file name: a whole shard lost.
fn absent_shards(segments: &[Segment], ids: &[String]) -> Vec<String> {
    let present: Vec<&str> = segments.iter().map(|s| s.header.shard.as_str()).collect();
    let mut partitions: Vec<(Mode, u32)> = Vec::new();
    for s in segments {
        if let Ok(Spec::Explicit(shard)) = shard::parse(&s.header.shard) {
            if !partitions.contains(&(shard.mode, shard.total)) {
                partitions.push((shard.mode, shard.total));
            }
        }
    }
    let mut absent = Vec::new();
    for (mode, total) in partitions {
        for index in 1..=total {
            let shard = Shard { mode, index, total };
            let name = shard.to_string();
            if !present.contains(&name.as_str()) {
                let points = shard.select(ids).len();
                absent.push(format!(
                    "shard {name} ({}, {points} point{})",
                    shard.file_name(),
                    if points == 1 { "" } else { "s" }
                ));
            }
        }
    }
    absent
}

/// The file a merged sweep's outputs go to when not given: the first input
/// folder (or the folder of the first file).
pub fn default_out_dir(paths: &[PathBuf]) -> PathBuf {
    paths.first().map_or_else(
        || PathBuf::from("."),
        |p| match p.is_dir() {
            true => p.clone(),
            false => p
                .parent()
                .map_or_else(|| PathBuf::from("."), Path::to_path_buf),
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::file::{Chain, Kernel};
    use crate::sweep::log::Header;
    use crate::sweep::metric::ImageError;
    use crate::sweep::{Point, Variant};
    use crate::timing::Fingerprint;

    fn variant(resolution: u32) -> Variant {
        Variant {
            resolution,
            kernel: Kernel::Deon7,
            chain: Chain::Full,
        }
    }

    fn point(resolution: u32, rmse: f64) -> Point {
        let e = ImageError {
            rmse_rel: rmse,
            max_rel: rmse,
            p99_rel: rmse,
            psnr_db: None,
            pixels: 1,
        };
        Point {
            id: variant(resolution).id(),
            variant: variant(resolution),
            passes: Vec::new(),
            total_ms: 1.0,
            chain_ms: 0.5,
            frame_span: Default::default(),
            transient_bytes: 0,
            final_error: e,
            diffuse_error: e,
        }
    }

    fn segment(file: &str, time: &str, points: Vec<Point>) -> Segment {
        let all: Vec<String> = [256, 512, 1024].map(|r| variant(r).id()).to_vec();
        Segment {
            file: file.into(),
            header: Header {
                record: "header".into(),
                schema_version: SWEEP_SCHEMA_VERSION,
                sweep_hash: "00000000000000aa".into(),
                shard: "hash:1/2".into(),
                shard_points: points.iter().map(|p| p.id.clone()).collect(),
                sweep_points: all,
                run_id: format!("run-{file}-{time}"),
                timestamp: time.into(),
                dermis_version: "0".into(),
                git_commit: "c".into(),
                fingerprint: Fingerprint {
                    device: "llvmpipe".into(),
                    ..Default::default()
                },
                reference_checksum: "0123".into(),
                reference: variant(2048),
                scene: "builtin".into(),
                environment: "sky".into(),
                width: 64,
                height: 80,
                frames: 2,
            },
            points,
        }
    }

    const T0: &str = "2026-11-25T10:00:00Z";
    const T1: &str = "2026-11-25T11:00:00Z";

    fn ok(segments: Vec<Segment>) -> Merged {
        merge_segments(segments, MergeOptions::default()).unwrap()
    }

    fn err(segments: Vec<Segment>) -> String {
        match merge_segments(segments, MergeOptions::default()) {
            Err(e @ Error::Input(_)) => e.to_string(),
            Err(e) => panic!("not an input error: {e}"),
            Ok(_) => panic!("merged"),
        }
    }

    #[test]
    fn merges_shards_into_canonical_order() {
        let m = ok(vec![
            segment("b.jsonl", T0, vec![point(1024, 0.1), point(256, 0.3)]),
            segment("a.jsonl", T0, vec![]),
            segment("c.jsonl", T0, vec![point(512, 0.2)]),
        ]);
        let ids: Vec<&str> = m.sweep.points.iter().map(|p| p.id.as_str()).collect();
        assert_eq!(
            ids,
            ["r256-deon7-full", "r512-deon7-full", "r1024-deon7-full"]
        );
        assert!(m.warnings.is_empty(), "{:?}", m.warnings);
        assert_eq!(m.sweep.shards.len(), 3);
        assert_eq!(m.sweep.shards[1].points, Vec::<String>::new());
        assert_eq!(m.sweep.sweep_hash, "00000000000000aa");
    }

    #[test]
    fn rejects_a_missing_point_naming_it() {
        let e = err(vec![segment(
            "a.jsonl",
            T0,
            vec![point(256, 0.3), point(1024, 0.1)],
        )]);
        assert!(e.contains("r512-deon7-full") && e.contains("1 of 3"), "{e}");
    }

    #[test]
    fn a_whole_missing_shard_is_named_with_its_file() {
        // Shards 1 and 3 of 3 by position; shard 2's log is not given.
        let ids: Vec<String> = [256, 512, 1024].map(|r| variant(r).id()).to_vec();
        let of = |index: u32, points: Vec<Point>| {
            let mut s = segment(&format!("points-shard-{index}-of-3.jsonl"), T0, points);
            s.header.shard = format!("count:{index}/3");
            s
        };
        let e = err(vec![
            of(1, vec![point(256, 0.3)]),
            of(3, vec![point(1024, 0.1)]),
        ]);
        assert!(
            e.contains(&ids[1])
                && e.contains("no log of shard count:2/3 (points-shard-2-of-3.jsonl, 1 point)"),
            "{e}"
        );
        // A shard that ran but did not finish is not called absent.
        let e = err(vec![
            of(1, vec![point(256, 0.3)]),
            of(2, vec![]),
            of(3, vec![point(1024, 0.1)]),
        ]);
        assert!(!e.contains("no log of"), "{e}");
    }

    #[test]
    fn rejects_mismatched_sweep_hashes_naming_the_files() {
        let mut b = segment("b.jsonl", T0, vec![point(512, 0.2)]);
        b.header.sweep_hash = "00000000000000bb".into();
        let e = err(vec![
            segment("a.jsonl", T0, vec![point(256, 0.3), point(1024, 0.1)]),
            b,
        ]);
        assert!(
            e.contains("a.jsonl") && e.contains("b.jsonl") && e.contains("00000000000000bb"),
            "{e}"
        );
    }

    #[test]
    fn rejects_another_schema_version() {
        let mut b = segment("b.jsonl", T0, vec![point(512, 0.2)]);
        b.header.schema_version = SWEEP_SCHEMA_VERSION + 1;
        let e = err(vec![
            segment("a.jsonl", T0, vec![point(256, 0.3), point(1024, 0.1)]),
            b,
        ]);
        assert!(e.contains("schema") && e.contains("b.jsonl"), "{e}");
    }

    #[test]
    fn the_later_of_two_duplicates_wins() {
        let all = || vec![point(256, 0.3), point(512, 0.2), point(1024, 0.1)];
        // By timestamp, whatever the input order.
        let m = ok(vec![
            segment("retry.jsonl", T1, vec![point(512, 0.25)]),
            segment("first.jsonl", T0, all()),
        ]);
        assert_eq!(m.sweep.points[1].final_error.rmse_rel, 0.25);
        assert_eq!(m.warnings.len(), 1, "{:?}", m.warnings);
        assert!(m.warnings[0].contains("r512-deon7-full"));
        // Equal timestamps: input order, then line order.
        let m = ok(vec![
            segment("a.jsonl", T0, all()),
            segment("b.jsonl", T0, vec![point(512, 0.4), point(512, 0.5)]),
        ]);
        assert_eq!(m.sweep.points[1].final_error.rmse_rel, 0.5);
    }

    #[test]
    fn reference_mismatches_are_refused_unless_allowed_and_fingerprints_warned() {
        let mut b = segment("b.jsonl", T0, vec![point(512, 0.2)]);
        b.header.reference_checksum = "4567".into();
        b.header.fingerprint.cpu_cores = 16;
        let a = segment("a.jsonl", T0, vec![point(256, 0.3), point(1024, 0.1)]);
        let e = err(vec![a.clone(), b.clone()]);
        assert!(
            e.contains("reference") && e.contains("--allow-reference-mismatch"),
            "{e}"
        );
        let m = merge_segments(
            vec![a, b],
            MergeOptions {
                allow_reference_mismatch: true,
            },
        )
        .unwrap();
        assert_eq!(m.warnings.len(), 2, "{:?}", m.warnings);
        assert!(m.warnings[1].contains("cpu_cores"), "{:?}", m.warnings);
    }
}
