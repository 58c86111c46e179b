//! `--shard`: which points of the sweep this process renders, as cargo-nextest's
//! `--partition` has it. `hash:I/N` takes the points whose id hashes to I − 1
//! mod N (a point keeps its shard when others are added or removed); `count:I/N`
//! takes every N-th point of the canonical order from the I-th (balanced). A bare
//! `I/N` is `hash:I/N`: a retried or extended sweep keeps its assignment.
//! `auto` reads the index and total from the job scheduler's environment.

use crate::cache::fnv1a64;
use crate::error::{Error, Result};
use std::fmt;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Hash,
    Count,
}

/// One shard of N; `index` is 1-based.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub mode: Mode,
    pub index: u32,
    pub total: u32,
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mode = match self.mode {
            Mode::Hash => "hash",
            Mode::Count => "count",
        };
        write!(f, "{mode}:{}/{}", self.index, self.total)
    }
}

impl Shard {
    /// Whether the point `id` at `position` in canonical order is this shard's.
    pub fn takes(&self, position: usize, id: &str) -> bool {
        let slot = match self.mode {
            Mode::Hash => fnv1a64(id.as_bytes()) % u64::from(self.total),
            Mode::Count => position as u64 % u64::from(self.total),
        };
        slot == u64::from(self.index - 1)
    }

    /// This shard's ids, in canonical order.
    pub fn select<'a>(&self, ids: &'a [String]) -> Vec<&'a String> {
        ids.iter()
            .enumerate()
            .filter(|(i, id)| self.takes(*i, id))
            .map(|(_, id)| id)
            .collect()
    }

    /// `points-shard-2-of-3.jsonl`.
    pub fn file_name(&self) -> String {
        format!("points-shard-{}-of-{}.jsonl", self.index, self.total)
    }
}

/// What `--shard` (or `DERMIS_SHARD`) said.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spec {
    Explicit(Shard),
    /// From the scheduler's environment, in the given mode.
    Auto(Mode),
}

fn bad(value: &str, why: impl fmt::Display) -> Error {
    Error::Input(format!(
        "--shard {value:?}: {why} (expected I/N with 1 ≤ I ≤ N, hash:I/N, count:I/N or auto)"
    ))
}

/// Parses `I/N`, `hash:I/N`, `count:I/N`, `auto`, `hash:auto`, `count:auto`.
pub fn parse(value: &str) -> Result<Spec> {
    let v = value.trim();
    let (mode, rest) = match v.split_once(':') {
        Some(("hash", rest)) => (Mode::Hash, rest),
        Some(("count", rest)) => (Mode::Count, rest),
        Some((m, _)) => return Err(bad(value, format!("unknown mode {m:?}"))),
        None => (Mode::Hash, v),
    };
    if rest == "auto" {
        return Ok(Spec::Auto(mode));
    }
    let (i, n) = rest.split_once('/').ok_or_else(|| bad(value, "no '/'"))?;
    let number = |s: &str, what: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|_| bad(value, format!("{what} {s:?} is not a number")))
    };
    let (index, total) = (number(i, "index")?, number(n, "total")?);
    check(index, total).map_err(|why| bad(value, why))?;
    Ok(Spec::Explicit(Shard { mode, index, total }))
}

fn check(index: u32, total: u32) -> std::result::Result<(), String> {
    if total == 0 {
        return Err("the total is 0".into());
    }
    if index == 0 || index > total {
        return Err(format!(
            "shard {index} is not in 1..={total} (shards count from 1)"
        ));
    }
    Ok(())
}

/// Where a resolved shard came from, for the message on stderr.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Resolved {
    pub shard: Shard,
    pub source: String,
    /// Bazel's `TEST_SHARD_STATUS_FILE`, to be touched (the test runner's
    /// "this binary shards" acknowledgement).
    pub status_file: Option<String>,
}

impl fmt::Display for Resolved {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "shard {}/{} by {} (from {})",
            self.shard.index,
            self.shard.total,
            match self.shard.mode {
                Mode::Hash => "id hash",
                Mode::Count => "position",
            },
            self.source
        )
    }
}

/// The shard this process runs, or `None` for the whole sweep.
///
/// `flag` is `--shard`'s value. Without it, `DERMIS_SHARD` is read (same
/// syntax). `auto` reads, first match wins: `DERMIS_SHARD` (unless itself
/// `auto`); Slurm job arrays (`SLURM_ARRAY_TASK_ID`, `SLURM_ARRAY_TASK_MIN`,
/// `SLURM_ARRAY_TASK_STEP`, `SLURM_ARRAY_TASK_COUNT`: index (ID − MIN) / STEP,
/// 0-based, of a regular array, checked against `SLURM_ARRAY_TASK_MAX`; with
/// `DERMIS_SHARD_TOTAL` set, the task ID itself is the 1-based shard of that
/// many, so a retried index keeps its shard); Kubernetes Indexed Jobs (`JOB_COMPLETION_INDEX`, 0-based, with the
/// total in `DERMIS_SHARD_TOTAL`: the Job's `completions` is not in the pod's
/// environment); GitLab `parallel:` (`CI_NODE_INDEX`, 1-based, `CI_NODE_TOTAL`);
/// Bazel test sharding (`TEST_SHARD_INDEX`, 0-based, `TEST_TOTAL_SHARDS`).
/// GitHub Actions sets nothing: pass `--shard` or `DERMIS_SHARD` explicitly.
pub fn resolve(
    flag: Option<&str>,
    env: &dyn Fn(&str) -> Option<String>,
) -> Result<Option<Resolved>> {
    let (spec, source) = match flag {
        Some(f) => (parse(f)?, "--shard"),
        None => match env("DERMIS_SHARD").filter(|v| !v.trim().is_empty()) {
            Some(v) => (
                parse(&v).map_err(|e| Error::Input(format!("DERMIS_SHARD: {e}")))?,
                "DERMIS_SHARD",
            ),
            None => return Ok(None),
        },
    };
    match spec {
        Spec::Explicit(shard) => Ok(Some(Resolved {
            shard,
            source: source.into(),
            status_file: None,
        })),
        Spec::Auto(mode) => from_env(mode, env).map(Some),
    }
}

fn from_env(mode: Mode, env: &dyn Fn(&str) -> Option<String>) -> Result<Resolved> {
    let get = |k: &str| env(k).filter(|v| !v.trim().is_empty());
    let num = |k: &str| -> Result<Option<u32>> {
        get(k)
            .map(|v| {
                v.trim()
                    .parse::<u32>()
                    .map_err(|_| Error::Input(format!("--shard auto: {k}={v:?} is not a number")))
            })
            .transpose()
    };
    let need = |k: &str, why: &str| -> Result<u32> {
        num(k)?.ok_or_else(|| Error::Input(format!("--shard auto: {why}, but {k} is not set")))
    };
    let done = |index0: u32, total: u32, source: String, status_file: Option<String>| {
        check(index0.saturating_add(1), total)
            .map_err(|why| Error::Input(format!("--shard auto ({source}): {why}")))?;
        Ok(Resolved {
            shard: Shard {
                mode,
                index: index0 + 1,
                total,
            },
            source,
            status_file,
        })
    };
    if let Some(v) = get("DERMIS_SHARD") {
        return match parse(&v).map_err(|e| Error::Input(format!("DERMIS_SHARD: {e}")))? {
            Spec::Explicit(mut shard) => {
                // An explicit mode in DERMIS_SHARD wins; a bare I/N takes auto's.
                if !v.contains(':') {
                    shard.mode = mode;
                }
                Ok(Resolved {
                    shard,
                    source: "DERMIS_SHARD".into(),
                    status_file: None,
                })
            }
            Spec::Auto(_) => Err(Error::Input(
                "DERMIS_SHARD=auto with --shard auto: set DERMIS_SHARD to I/N, or unset it".into(),
            )),
        };
    }
    if let Some(id) = num("SLURM_ARRAY_TASK_ID")? {
        let source = format!("SLURM_ARRAY_TASK_ID={id}");
        // The shard count given: the task ID is the shard (1-based), whatever
        // array it came from, so that a retry of one index (--array=2) runs
        // that shard, not the whole sweep as "shard 1/1".
        if let Some(total) = num("DERMIS_SHARD_TOTAL")? {
            if let Some(count) = num("SLURM_ARRAY_TASK_COUNT")?.filter(|&c| c > total) {
                return Err(Error::Input(format!(
                    "--shard auto: the Slurm array has {count} tasks (SLURM_ARRAY_TASK_COUNT) but \
                     DERMIS_SHARD_TOTAL={total}: submit --array=1-{total}, or set \
                     DERMIS_SHARD_TOTAL={count}"
                )));
            }
            // Every task of an array that names a task outside 1..=total
            // refuses (SLURM_ARRAY_TASK_MIN and MAX are the array's, the same
            // in each task): none renders a shard of a submission that cannot
            // complete, e.g. --array=1,4,9 with 3 shards.
            let range = (num("SLURM_ARRAY_TASK_MIN")?, num("SLURM_ARRAY_TASK_MAX")?);
            if let (Some(min), Some(max)) = range {
                if min == 0 || max > total {
                    return Err(Error::Input(format!(
                        "--shard auto: with DERMIS_SHARD_TOTAL={total} the Slurm task IDs are \
                         the shard numbers, 1..={total}, but this array's tasks run from \
                         SLURM_ARRAY_TASK_MIN={min} to MAX={max}; no task of it renders \
                         (submit --array=1-{total}, or a retry's --array=I,J with each in \
                         1..={total})"
                    )));
                }
            }
            if id == 0 || id > total {
                return Err(Error::Input(format!(
                    "--shard auto: with DERMIS_SHARD_TOTAL={total} the Slurm task ID is the \
                     shard number, 1..={total}, but SLURM_ARRAY_TASK_ID={id} (submit \
                     --array=1-{total}, or a retry's --array=I with I in 1..={total})"
                )));
            }
            return done(id - 1, total, format!("{source}, DERMIS_SHARD_TOTAL"), None);
        }
        let min = num("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
        let step = num("SLURM_ARRAY_TASK_STEP")?.unwrap_or(1).max(1);
        let count = need(
            "SLURM_ARRAY_TASK_COUNT",
            "SLURM_ARRAY_TASK_ID is set (a Slurm array task)",
        )?;
        // A regular array MIN-MAX:STEP has (MAX − MIN) / STEP + 1 tasks; a
        // list such as 1,4,9 (MIN 1, MAX 9, COUNT 3) does not, and its tasks
        // cannot be told apart from shards of another array.
        if let Some(max) = num("SLURM_ARRAY_TASK_MAX")? {
            let regular = max >= min
                && (max - min) % step == 0
                && u64::from((max - min) / step) + 1 == u64::from(count);
            if !regular {
                return Err(Error::Input(format!(
                    "--shard auto: the Slurm array is not a regular range: \
                     SLURM_ARRAY_TASK_MIN={min}, MAX={max}, STEP={step} but COUNT={count} \
                     (an index list such as --array=1,4,9, or a retry of some indices); \
                     submit --array=1-{count}, or give each task its shard: DERMIS_SHARD=I/N, \
                     or DERMIS_SHARD_TOTAL=N with the task ID as the shard number"
                )));
            }
        }
        if id < min || (id - min) % step != 0 {
            return Err(Error::Input(format!(
                "--shard auto: SLURM_ARRAY_TASK_ID={id} is not MIN {min} + a multiple of STEP {step} \
                 (use a regular array such as --array=1-{count})"
            )));
        }
        return done((id - min) / step, count, source, None);
    }
    if let Some(index0) = num("JOB_COMPLETION_INDEX")? {
        let total = need(
            "DERMIS_SHARD_TOTAL",
            "JOB_COMPLETION_INDEX is set (a Kubernetes Indexed Job; set DERMIS_SHARD_TOTAL to the Job's completions)",
        )?;
        return done(
            index0,
            total,
            format!("JOB_COMPLETION_INDEX={index0}"),
            None,
        );
    }
    if let Some(index1) = num("CI_NODE_INDEX")? {
        let total = need("CI_NODE_TOTAL", "CI_NODE_INDEX is set (GitLab parallel:)")?;
        if index1 == 0 {
            return Err(Error::Input(
                "--shard auto: CI_NODE_INDEX=0, but GitLab counts nodes from 1".into(),
            ));
        }
        return done(index1 - 1, total, format!("CI_NODE_INDEX={index1}"), None);
    }
    if let Some(index0) = num("TEST_SHARD_INDEX")? {
        let total = need(
            "TEST_TOTAL_SHARDS",
            "TEST_SHARD_INDEX is set (Bazel test sharding)",
        )?;
        return done(
            index0,
            total,
            format!("TEST_SHARD_INDEX={index0}"),
            get("TEST_SHARD_STATUS_FILE"),
        );
    }
    Err(Error::Input(
        "--shard auto: no shard in the environment; looked for DERMIS_SHARD, SLURM_ARRAY_TASK_ID, \
         JOB_COMPLETION_INDEX (+ DERMIS_SHARD_TOTAL), CI_NODE_INDEX, TEST_SHARD_INDEX \
         (GitHub Actions sets none: pass --shard I/N)"
            .into(),
    ))
}

/// Touches Bazel's shard status file when it asked for one.
pub fn acknowledge(resolved: &Resolved) -> Result<()> {
    if let Some(path) = &resolved.status_file {
        std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)
            .map_err(|source| Error::Io {
                path: path.clone(),
                source,
            })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn ids(n: usize) -> Vec<String> {
        (0..n)
            .map(|i| format!("r{}-deon7-full", 256 << (i % 6)) + &"x".repeat(i / 6))
            .collect()
    }

    fn env<'a>(pairs: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
        let map: HashMap<&str, &str> = pairs.iter().copied().collect();
        move |k| map.get(k).map(|v| v.to_string())
    }

    fn resolved(flag: Option<&str>, pairs: &[(&str, &str)]) -> Result<Option<Resolved>> {
        resolve(flag, &env(pairs))
    }

    fn shard_of(flag: Option<&str>, pairs: &[(&str, &str)]) -> (u32, u32, Mode) {
        let r = resolved(flag, pairs).unwrap().unwrap();
        (r.shard.index, r.shard.total, r.shard.mode)
    }

    #[test]
    fn every_point_is_in_exactly_one_shard() {
        let all = ids(20);
        for mode in [Mode::Hash, Mode::Count] {
            for total in 1..=8 {
                let mut seen = vec![0; all.len()];
                let mut sizes = Vec::new();
                for index in 1..=total {
                    let shard = Shard { mode, index, total };
                    let mine = shard.select(&all);
                    sizes.push(mine.len());
                    for id in mine {
                        seen[all.iter().position(|a| a == id).unwrap()] += 1;
                    }
                }
                assert!(seen.iter().all(|&s| s == 1), "{mode:?} N={total}: {seen:?}");
                if mode == Mode::Count {
                    let (lo, hi) = (sizes.iter().min().unwrap(), sizes.iter().max().unwrap());
                    assert!(hi - lo <= 1, "count is balanced: {sizes:?}");
                }
            }
        }
    }

    #[test]
    fn hash_assignment_is_stable_when_points_are_added() {
        let before = ids(12);
        let mut after = before.clone();
        after.insert(3, "r8192-accurate-adaptive".into());
        after.push("r128-deon7-full".into());
        for total in 1..=8 {
            for index in 1..=total {
                let s = Shard {
                    mode: Mode::Hash,
                    index,
                    total,
                };
                let old: Vec<&String> = s.select(&before);
                let new: Vec<&String> = s
                    .select(&after)
                    .into_iter()
                    .filter(|id| before.contains(id))
                    .collect();
                assert_eq!(old, new, "{s}");
            }
        }
    }

    #[test]
    fn parses_explicit_shards_and_rejects_malformed_ones() {
        let shard = |mode, index, total| Spec::Explicit(Shard { mode, index, total });
        assert_eq!(parse("2/3").unwrap(), shard(Mode::Hash, 2, 3));
        assert_eq!(parse("hash:1/1").unwrap(), shard(Mode::Hash, 1, 1));
        assert_eq!(parse("count:3/3").unwrap(), shard(Mode::Count, 3, 3));
        assert_eq!(parse("auto").unwrap(), Spec::Auto(Mode::Hash));
        assert_eq!(parse("count:auto").unwrap(), Spec::Auto(Mode::Count));
        for bad in [
            "0/3",
            "4/3",
            "x/y",
            "1/0",
            "0/0",
            "3",
            "",
            "slice:1/2",
            "-1/3",
            "1/3/4",
        ] {
            match parse(bad) {
                Err(e @ Error::Input(_)) => {
                    assert_eq!(e.exit_code(), 2);
                    assert!(e.to_string().contains("--shard"), "{e}");
                }
                other => panic!("{bad:?}: {other:?}"),
            }
        }
    }

    #[test]
    fn reads_each_scheduler_convention() {
        // Slurm: --array=1-3 (MIN 1), and --array=0-10:5 (MIN 0, STEP 5).
        let slurm = [
            ("SLURM_ARRAY_TASK_ID", "2"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
            ("SLURM_ARRAY_TASK_STEP", "1"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ];
        assert_eq!(shard_of(Some("auto"), &slurm), (2, 3, Mode::Hash));
        let r = resolved(Some("auto"), &slurm).unwrap().unwrap();
        assert_eq!(
            r.to_string(),
            "shard 2/3 by id hash (from SLURM_ARRAY_TASK_ID=2)"
        );
        let stepped = [
            ("SLURM_ARRAY_TASK_ID", "10"),
            ("SLURM_ARRAY_TASK_MIN", "0"),
            ("SLURM_ARRAY_TASK_STEP", "5"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ];
        assert_eq!(shard_of(Some("count:auto"), &stepped), (3, 3, Mode::Count));
        // Kubernetes: 0-based, total from DERMIS_SHARD_TOTAL.
        let k8s = [("JOB_COMPLETION_INDEX", "0"), ("DERMIS_SHARD_TOTAL", "3")];
        assert_eq!(shard_of(Some("auto"), &k8s), (1, 3, Mode::Hash));
        // GitLab: 1-based.
        let gitlab = [("CI_NODE_INDEX", "3"), ("CI_NODE_TOTAL", "3")];
        assert_eq!(shard_of(Some("auto"), &gitlab), (3, 3, Mode::Hash));
        // Bazel: 0-based, and a status file to touch.
        let bazel = [
            ("TEST_SHARD_INDEX", "1"),
            ("TEST_TOTAL_SHARDS", "4"),
            ("TEST_SHARD_STATUS_FILE", "/tmp/status"),
        ];
        let r = resolved(Some("auto"), &bazel).unwrap().unwrap();
        assert_eq!((r.shard.index, r.shard.total), (2, 4));
        assert_eq!(r.status_file.as_deref(), Some("/tmp/status"));
        // DERMIS_SHARD: read without --shard, and first under auto.
        assert_eq!(
            shard_of(None, &[("DERMIS_SHARD", "count:2/5")]),
            (2, 5, Mode::Count)
        );
        let both = [
            ("DERMIS_SHARD", "1/2"),
            ("CI_NODE_INDEX", "3"),
            ("CI_NODE_TOTAL", "3"),
        ];
        assert_eq!(shard_of(Some("count:auto"), &both), (1, 2, Mode::Count));
        // No flag, no DERMIS_SHARD: the whole sweep, whatever the scheduler says.
        assert_eq!(resolved(None, &slurm).unwrap(), None);
    }

    /// Slurm 22.05 for `--array=1,4,9`: MIN 1, MAX 9, COUNT 3 (and STEP 1).
    #[test]
    fn an_irregular_slurm_list_is_refused_saying_why() {
        for id in ["1", "4", "9"] {
            let env = [
                ("SLURM_ARRAY_TASK_ID", id),
                ("SLURM_ARRAY_TASK_MIN", "1"),
                ("SLURM_ARRAY_TASK_MAX", "9"),
                ("SLURM_ARRAY_TASK_STEP", "1"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ];
            let e = resolved(Some("auto"), &env).unwrap_err();
            assert_eq!(e.exit_code(), 2);
            let msg = e.to_string();
            assert!(
                msg.contains("not a regular range")
                    && msg.contains("MAX=9")
                    && msg.contains("COUNT=3")
                    && msg.contains("--array=1-3"),
                "{msg}"
            );
        }
        // Regular arrays with MAX pass: 1-3, 0-10:5, and one index (MIN = MAX).
        let regular: [&[(&str, &str)]; 3] = [
            &[
                ("SLURM_ARRAY_TASK_ID", "3"),
                ("SLURM_ARRAY_TASK_MIN", "1"),
                ("SLURM_ARRAY_TASK_MAX", "3"),
                ("SLURM_ARRAY_TASK_STEP", "1"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
            &[
                ("SLURM_ARRAY_TASK_ID", "5"),
                ("SLURM_ARRAY_TASK_MIN", "0"),
                ("SLURM_ARRAY_TASK_MAX", "10"),
                ("SLURM_ARRAY_TASK_STEP", "5"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
            &[
                ("SLURM_ARRAY_TASK_ID", "2"),
                ("SLURM_ARRAY_TASK_MIN", "2"),
                ("SLURM_ARRAY_TASK_MAX", "2"),
                ("SLURM_ARRAY_TASK_COUNT", "1"),
            ],
        ];
        let got: Vec<(u32, u32)> = regular
            .iter()
            .map(|env| {
                let (i, n, _) = shard_of(Some("auto"), env);
                (i, n)
            })
            .collect();
        assert_eq!(got, [(3, 3), (2, 3), (1, 1)]);
    }

    /// A retry of one index (`sbatch --array=2`) with the recipe's
    /// DERMIS_SHARD_TOTAL runs shard 2 of 3, not the whole sweep as 1/1.
    #[test]
    fn a_slurm_retry_with_the_shard_total_keeps_its_shard() {
        let retry = [
            ("SLURM_ARRAY_TASK_ID", "2"),
            ("SLURM_ARRAY_TASK_MIN", "2"),
            ("SLURM_ARRAY_TASK_MAX", "2"),
            ("SLURM_ARRAY_TASK_STEP", "1"),
            ("SLURM_ARRAY_TASK_COUNT", "1"),
            ("DERMIS_SHARD_TOTAL", "3"),
        ];
        assert_eq!(shard_of(Some("auto"), &retry), (2, 3, Mode::Hash));
        let r = resolved(Some("count:auto"), &retry).unwrap().unwrap();
        assert_eq!(
            r.to_string(),
            "shard 2/3 by position (from SLURM_ARRAY_TASK_ID=2, DERMIS_SHARD_TOTAL)"
        );
        // Without the total the same task is the whole sweep: the recipe sets it.
        let bare: Vec<(&str, &str)> = retry[..5].to_vec();
        assert_eq!(shard_of(Some("auto"), &bare), (1, 1, Mode::Hash));
        // Two of three retried as a list (--array=1,3) is fine with the total.
        let list = [
            ("SLURM_ARRAY_TASK_ID", "3"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
            ("SLURM_ARRAY_TASK_MAX", "3"),
            ("SLURM_ARRAY_TASK_COUNT", "2"),
            ("DERMIS_SHARD_TOTAL", "3"),
        ];
        assert_eq!(shard_of(Some("auto"), &list), (3, 3, Mode::Hash));
        // A list naming tasks past the total (--array=1,4,9 with 3 shards):
        // every task refuses, task 1 too, so none renders.
        for id in ["1", "4", "9"] {
            let env = [
                ("SLURM_ARRAY_TASK_ID", id),
                ("SLURM_ARRAY_TASK_MIN", "1"),
                ("SLURM_ARRAY_TASK_MAX", "9"),
                ("SLURM_ARRAY_TASK_STEP", "1"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
                ("DERMIS_SHARD_TOTAL", "3"),
            ];
            let e = resolved(Some("auto"), &env).unwrap_err().to_string();
            assert!(
                e.contains("SLURM_ARRAY_TASK_MIN=1 to MAX=9") && e.contains("1..=3"),
                "task {id}: {e}"
            );
        }
        // The total disagreeing with the array, or an ID outside it: refused.
        for (env, needle) in [
            (
                vec![
                    ("SLURM_ARRAY_TASK_ID", "1"),
                    ("SLURM_ARRAY_TASK_COUNT", "5"),
                    ("DERMIS_SHARD_TOTAL", "3"),
                ],
                "DERMIS_SHARD_TOTAL=3",
            ),
            (
                vec![
                    ("SLURM_ARRAY_TASK_ID", "0"),
                    ("SLURM_ARRAY_TASK_COUNT", "3"),
                    ("DERMIS_SHARD_TOTAL", "3"),
                ],
                "1..=3",
            ),
            (
                vec![
                    ("SLURM_ARRAY_TASK_ID", "4"),
                    ("SLURM_ARRAY_TASK_COUNT", "1"),
                    ("DERMIS_SHARD_TOTAL", "3"),
                ],
                "SLURM_ARRAY_TASK_ID=4",
            ),
        ] {
            let e = resolved(Some("auto"), &env).unwrap_err().to_string();
            assert!(e.contains(needle), "{env:?}: {e}");
        }
    }

    #[test]
    fn an_explicit_flag_wins_over_the_environment() {
        let env = [
            ("DERMIS_SHARD", "3/3"),
            ("SLURM_ARRAY_TASK_ID", "1"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ];
        let r = resolved(Some("count:1/2"), &env).unwrap().unwrap();
        assert_eq!(
            (r.shard.index, r.shard.total, r.shard.mode),
            (1, 2, Mode::Count)
        );
        assert_eq!(r.source, "--shard");
    }

    #[test]
    fn auto_rejects_a_missing_or_malformed_environment() {
        let cases: &[&[(&str, &str)]] = &[
            &[],
            &[("SLURM_ARRAY_TASK_ID", "1")],
            &[
                ("SLURM_ARRAY_TASK_ID", "x"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
            &[
                ("SLURM_ARRAY_TASK_ID", "4"),
                ("SLURM_ARRAY_TASK_MIN", "1"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
            &[
                ("SLURM_ARRAY_TASK_ID", "2"),
                ("SLURM_ARRAY_TASK_MIN", "0"),
                ("SLURM_ARRAY_TASK_STEP", "5"),
                ("SLURM_ARRAY_TASK_COUNT", "3"),
            ],
            &[("JOB_COMPLETION_INDEX", "0")],
            &[("JOB_COMPLETION_INDEX", "3"), ("DERMIS_SHARD_TOTAL", "3")],
            &[("CI_NODE_INDEX", "0"), ("CI_NODE_TOTAL", "3")],
            &[("CI_NODE_INDEX", "4"), ("CI_NODE_TOTAL", "3")],
            &[("TEST_SHARD_INDEX", "0"), ("TEST_TOTAL_SHARDS", "0")],
            &[("DERMIS_SHARD", "auto")],
            &[("DERMIS_SHARD", "0/3")],
        ];
        for env in cases {
            match resolved(Some("auto"), env) {
                Err(e @ Error::Input(_)) => assert_eq!(e.exit_code(), 2),
                other => panic!("{env:?}: {other:?}"),
            }
        }
        // Without --shard a malformed DERMIS_SHARD is an error too.
        assert!(resolved(None, &[("DERMIS_SHARD", "4/3")]).is_err());
        let msg = resolved(Some("auto"), &[]).unwrap_err().to_string();
        assert!(
            msg.contains("SLURM_ARRAY_TASK_ID") && msg.contains("--shard I/N"),
            "{msg}"
        );
    }
}
