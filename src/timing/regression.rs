//! `dermis compare`: whether a pass got slower between two measurements, pass
//! by pass, each judged by the rule of [`super::verdict`] (a significant
//! change, Holm-corrected over the judged passes, whose whole interval lies
//! beyond the noise threshold; else unchanged or inconclusive).
//!
//! Times are compared in ruler units where both sides timed the ruler (each
//! frame's pass time over the same frame's `ruler_copy`), so that a busy
//! machine, which slows both, cancels; else in ms.

pub use super::measurement::{check_report_schema, MeasuredFrame, Measurement, FRAME_ROW};
pub use super::verdict::{Test, Verdict};

use super::measurement::{join_split_passes, samples, setup_differences};
use super::run::{is_ruler, RULER_COPY};
use super::significance::holm;
use super::stats::{median, Stats};
use super::verdict::{evidence, more_samples, verdict};
use crate::error::{Error, Result};
use serde::Serialize;

/// The default noise threshold: the relative change below which a difference
/// is not reported — the median |change| of passes of ≥ 5 ms between two
/// interleaved sets of 10 identical runs on lavapipe, over 20 such pairs
/// (docs/guide/compare-in-ci.md, "Comparing runs": 5.9 %).
pub const DEFAULT_NOISE_THRESHOLD: f64 = 0.06;
/// Significance level of the Holm-corrected test (criterion.rs's default).
pub const DEFAULT_SIGNIFICANCE: f64 = 0.05;

/// Setup keys whose difference changes the work itself: timings of such runs
/// measure different things (an error unless allowed).
const WORKLOAD_KEYS: [&str; 6] = [
    "scene",
    "mesh",
    "view",
    "render_width",
    "render_height",
    "irradiance_resolution",
];

/// What a pass's time is measured in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Unit {
    /// Ruler units where they scatter less than ms between samples (each
    /// side's own scatter, judged before comparing), else ms.
    Auto,
    /// Each pass over the ruler of its frame (or run): a busier machine cancels.
    Ruler,
    Ms,
}

/// Coefficient of variation (sample standard deviation over the mean).
fn scatter(v: &[f64]) -> Option<f64> {
    let s = Stats::of(v).filter(|_| v.len() >= 2)?;
    (s.mean_ns > 0.0).then(|| s.std_ns / s.mean_ns)
}

/// How to decide.
#[derive(Clone, Debug, Serialize)]
pub struct CompareOptions {
    pub unit: Unit,
    /// Relative change below which nothing is reported (0.06 = 6 %).
    pub noise_threshold: f64,
    /// Family-wise significance level (Holm over the passes).
    pub significance: f64,
    /// Compare runs whose work differs (scene, view, sizes).
    pub allow_setup_change: bool,
    /// The passes a change targets (`--passes`): only they and the frame's
    /// sum are judged, Holm over them alone; the others are shown, not
    /// judged. Empty: every pass is judged.
    pub passes: Vec<String>,
}

impl Default for CompareOptions {
    fn default() -> Self {
        Self {
            unit: Unit::Auto,
            noise_threshold: DEFAULT_NOISE_THRESHOLD,
            significance: DEFAULT_SIGNIFICANCE,
            allow_setup_change: false,
            passes: Vec::new(),
        }
    }
}

/// One pass's comparison.
#[derive(Clone, Debug, Serialize)]
pub struct PassChange {
    pub name: String,
    /// "ruler" (each frame over its ruler) or "ms".
    pub unit: &'static str,
    /// "run" (each run's median is one sample) or "frame".
    pub sample: &'static str,
    pub base_samples: usize,
    pub new_samples: usize,
    pub base_ms: Option<f64>,
    pub new_ms: Option<f64>,
    /// Median ns/texel as a multiple of the ruler's, where known.
    pub base_x_ruler: Option<f64>,
    pub new_x_ruler: Option<f64>,
    /// median(new) / median(base) − 1 in `unit`.
    pub change: Option<f64>,
    /// The same in ms (informative where `unit` is the ruler).
    pub change_ms: Option<f64>,
    pub ci_low: Option<f64>,
    pub ci_high: Option<f64>,
    /// What gave `p` and the interval.
    pub test: Test,
    /// A sample stands out of its side's scatter (the t-test's assumption in
    /// doubt: it costs power, not false alarms).
    pub outlier: bool,
    pub p: f64,
    /// Holm-adjusted over the judged passes (the others are corrected among
    /// themselves).
    pub p_holm: f64,
    pub verdict: Verdict,
    /// A ruler pass: shown, not judged.
    pub ruler: bool,
    /// In the family whose verdicts count: not a ruler and, with `--passes`,
    /// named there (or the frame's sum).
    pub judged: bool,
    /// For an inconclusive pass: about how many more samples per side would
    /// decide it; `None` where no number would (the change sits on the threshold).
    pub more_samples: Option<usize>,
}

/// Two measurements compared pass by pass.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    pub base: String,
    pub new: String,
    pub options: CompareOptions,
    /// Fingerprint differences, pooled-run differences, sample-size notes.
    pub warnings: Vec<String>,
    /// Setup keys that differ (the change under test, if meant).
    pub setup_changes: Vec<String>,
    pub passes: Vec<PassChange>,
    pub only_in_base: Vec<String>,
    pub only_in_new: Vec<String>,
    /// Split passes joined to compare with one pass of the other side
    /// ([`join_split_passes`]): "blur2 = blur2_u + blur2_v in BASE".
    pub joined: Vec<String>,
}

impl Comparison {
    pub fn count(&self, verdict: Verdict) -> usize {
        self.passes
            .iter()
            .filter(|p| p.judged && p.verdict == verdict)
            .count()
    }

    pub fn regressed(&self) -> bool {
        self.count(Verdict::Regressed) > 0
    }
}

/// Compares `new` with `base`.
pub fn compare(base: &Measurement, new: &Measurement, opts: &CompareOptions) -> Result<Comparison> {
    check_options(opts)?;
    let (mut base, mut new) = (base.clone(), new.clone());
    let mut joined = join_split_passes(&mut base, &new);
    joined.extend(join_split_passes(&mut new, &base));
    let (base, new) = (&base, &new);
    let (mut warnings, setup_changes) = check_comparable(base, new, opts)?;
    let by_run = base.runs() >= 2 && new.runs() >= 2;
    if !by_run {
        warnings.push(format!(
            "one run on a side ({} vs {}): frames of one process share its state; \
             use render --runs or dermis interleave for repetitions",
            base.runs(),
            new.runs()
        ));
    }
    let ruler = in_ruler_units(base, new, opts, by_run, &mut warnings)?;
    let mut names: Vec<String> = base
        .pass_order
        .iter()
        .filter(|n| new.pass_order.contains(n))
        .cloned()
        .collect();
    names.push(FRAME_ROW.into());
    if let Some(missing) = opts.passes.iter().find(|p| !names.contains(p)) {
        return Err(Error::Input(format!(
            "--passes: {missing:?} is not a pass both sides ran (they share: {})",
            names.join(", ")
        )));
    }
    let only_in_base = only(&base.pass_order, &new.pass_order);
    let only_in_new = only(&new.pass_order, &base.pass_order);

    let judged = |name: &String| {
        !is_ruler(name)
            && (opts.passes.is_empty() || name == FRAME_ROW || opts.passes.contains(name))
    };
    let family = names.iter().filter(|n| judged(n)).count().max(1);
    let others = (names.len() - family).max(1);
    // Each family's intervals jointly at 1 − α (Bonferroni), as its p-values
    // are corrected jointly.
    let mut rows: Vec<PassChange> = names
        .iter()
        .map(|name| {
            let m = if judged(name) { family } else { others };
            let confidence = 1.0 - opts.significance / m as f64;
            let mut r = pass_change(base, new, name, ruler, by_run, confidence);
            r.judged = judged(name);
            r
        })
        .collect();
    holm_adjust(&mut rows);
    for r in &mut rows {
        decide(r, opts, family);
    }
    Ok(Comparison {
        base: base.source.clone(),
        new: new.source.clone(),
        options: opts.clone(),
        warnings,
        setup_changes,
        passes: rows,
        only_in_base,
        only_in_new,
        joined,
    })
}

/// The threshold and the level must be fractions.
fn check_options(opts: &CompareOptions) -> Result<()> {
    if !(opts.noise_threshold >= 0.0 && opts.noise_threshold < 1.0) {
        return Err(Error::Input(format!(
            "--noise-threshold {}: give a fraction in [0, 1) (0.06 = 6 %)",
            opts.noise_threshold
        )));
    }
    if !(opts.significance > 0.0 && opts.significance < 1.0) {
        return Err(Error::Input(format!(
            "--significance {}: give a level in (0, 1)",
            opts.significance
        )));
    }
    Ok(())
}

/// Refuses sides without frames, timed by different clocks, or (unless
/// allowed) rendering different work; returns the machine differences as
/// warnings and the setup differences.
fn check_comparable(
    base: &Measurement,
    new: &Measurement,
    opts: &CompareOptions,
) -> Result<(Vec<String>, Vec<String>)> {
    for m in [base, new] {
        if m.frames.is_empty() {
            return Err(Error::Input(format!(
                "{}: no measured frames (render with --frames 2 or more: the first is warm-up)",
                m.source
            )));
        }
    }
    let (fb, fnew) = (&base.fingerprint, &new.fingerprint);
    if fb.clock != fnew.clock {
        return Err(Error::Input(format!(
            "{} was timed by {} and {} by {}: the clocks measure different spans",
            base.source, fb.clock, new.source, fnew.clock
        )));
    }
    let warnings: Vec<String> = fb
        .differences(fnew)
        .into_iter()
        .map(|d| format!("different machine or settings: {d}"))
        .collect();
    let setup_changes = setup_differences(&base.setup, &new.setup);
    let workload: Vec<&String> = setup_changes
        .iter()
        .filter(|c| {
            WORKLOAD_KEYS
                .iter()
                .any(|k| c.starts_with(&format!("{k}:")))
        })
        .collect();
    if !workload.is_empty() && !opts.allow_setup_change {
        return Err(Error::Input(format!(
            "{} and {} rendered different work ({}): their timings do not compare \
             (--allow-setup-change to compare anyway)",
            base.source,
            new.source,
            workload
                .iter()
                .map(|s| s.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    Ok((warnings, setup_changes))
}

/// Whether passes are compared over the ruler (else in ms), per `opts.unit`;
/// why not, where auto chose ms, goes to `warnings`.
fn in_ruler_units(
    base: &Measurement,
    new: &Measurement,
    opts: &CompareOptions,
    by_run: bool,
    warnings: &mut Vec<String>,
) -> Result<bool> {
    let has_ruler = base.has_ruler() && new.has_ruler();
    let common: Vec<&String> = base
        .pass_order
        .iter()
        .filter(|n| new.pass_order.contains(n) && !is_ruler(n))
        .collect();
    Ok(match opts.unit {
        Unit::Ms => false,
        Unit::Ruler if !has_ruler => {
            return Err(Error::Input(
                "--unit ruler: both sides need the ruler (render --ruler)".into(),
            ))
        }
        Unit::Ruler => true,
        Unit::Auto if !has_ruler => {
            warnings.push(
                "no ruler on both sides (render --ruler): changes are in ms, and a busier \
                 machine moves them"
                    .into(),
            );
            false
        }
        // Decided on each side's own scatter, before anything is compared.
        Unit::Auto => {
            let spread = |in_ruler: bool| {
                let cv: Vec<f64> = common
                    .iter()
                    .flat_map(|n| [base, new].map(|m| scatter(&samples(m, n, in_ruler, by_run))))
                    .flatten()
                    .collect();
                median(&cv).unwrap_or(f64::INFINITY)
            };
            let (in_ruler, in_ms) = (spread(true), spread(false));
            if in_ruler >= in_ms {
                warnings.push(format!(
                    "the ruler does not steady these timings (scatter {:.1} % over the ruler, \
                     {:.1} % in ms): compared in ms",
                    100.0 * in_ruler,
                    100.0 * in_ms
                ));
            }
            in_ruler < in_ms
        }
    })
}

/// One pass's row before Holm's correction and the verdict (`decide`).
fn pass_change(
    base: &Measurement,
    new: &Measurement,
    name: &str,
    ruler: bool,
    by_run: bool,
    confidence: f64,
) -> PassChange {
    let ruler_pass = is_ruler(name);
    let in_ruler = ruler && !ruler_pass;
    let (b, n) = (
        samples(base, name, in_ruler, by_run),
        samples(new, name, in_ruler, by_run),
    );
    let (b_ms, n_ms) = (
        samples(base, name, false, by_run),
        samples(new, name, false, by_run),
    );
    let e = evidence(&b, &n, confidence);
    let ci = e.change;
    let ms = |v: &[f64]| median(v).map(|x| x / 1e6);
    // ns/texel over the ruler's: the per-frame ratio scaled by the texels.
    let x_ruler = |m: &Measurement| {
        let t = *m.texels.get(name)? as f64;
        let r = *m.texels.get(RULER_COPY)? as f64;
        let ratio = median(&samples(m, name, true, by_run)).filter(|_| ruler)?;
        Some(ratio * r / t)
    };
    PassChange {
        name: name.to_string(),
        unit: if in_ruler { "ruler" } else { "ms" },
        sample: if by_run { "run" } else { "frame" },
        base_samples: b.len(),
        new_samples: n.len(),
        base_ms: ms(&b_ms),
        new_ms: ms(&n_ms),
        base_x_ruler: x_ruler(base),
        new_x_ruler: x_ruler(new),
        change: ci.map(|c| c.0),
        change_ms: median(&n_ms)
            .zip(median(&b_ms).filter(|&v| v > 0.0))
            .map(|(n, b)| n / b - 1.0),
        ci_low: ci.map(|c| c.1),
        ci_high: ci.map(|c| c.2),
        test: e.test,
        outlier: e.outlier,
        p: e.p,
        p_holm: 1.0,
        verdict: Verdict::Inconclusive,
        ruler: ruler_pass,
        judged: false,
        more_samples: None,
    }
}

/// Holm over the judged rows; the others are corrected on their own.
fn holm_adjust(rows: &mut [PassChange]) {
    for judged in [true, false] {
        let idx: Vec<usize> = (0..rows.len())
            .filter(|&i| rows[i].judged == judged)
            .collect();
        let adj = holm(&idx.iter().map(|&i| rows[i].p).collect::<Vec<_>>());
        for (&i, a) in idx.iter().zip(adj) {
            rows[i].p_holm = a;
        }
    }
}

fn only(a: &[String], b: &[String]) -> Vec<String> {
    a.iter().filter(|n| !b.contains(n)).cloned().collect()
}

/// The verdict of a row, and for an inconclusive one how many more samples.
fn decide(r: &mut PassChange, opts: &CompareOptions, family: usize) {
    let (Some(est), Some(lo), Some(hi)) = (r.change, r.ci_low, r.ci_high) else {
        r.verdict = Verdict::Inconclusive;
        return;
    };
    let t = opts.noise_threshold;
    r.verdict = verdict((est, lo, hi), r.p_holm, t, opts.significance);
    if r.verdict == Verdict::Inconclusive {
        let n = r.base_samples.min(r.new_samples);
        r.more_samples = more_samples(r.test, n, (est, lo, hi), t, opts.significance, family);
    }
}

/// The comparison as a fixed-width table, then the verdicts' counts.
pub fn table(c: &Comparison) -> String {
    let pct = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{:+.1}%", 100.0 * v));
    let ms = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{v:.3}"));
    let p = |v: f64| {
        if v >= 1e-3 {
            format!("{v:.3}")
        } else {
            format!("{v:.1e}")
        }
    };
    let xr = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.2}"));
    let mut s = format!("base: {}\nnew:  {}\n", c.base, c.new);
    for w in &c.warnings {
        s += &format!("warning: {w}\n");
    }
    if !c.setup_changes.is_empty() {
        s += &format!("setup changed: {}\n", c.setup_changes.join(", "));
    }
    s += &format!(
        "{:<24} {:>10} {:>10} {:>7} {:>7} {:>8} {:>19} {:>9} {:>9}  {}\n",
        "pass",
        "base ms",
        "new ms",
        "base×r",
        "new×r",
        "change",
        "95% CI",
        "p (test)",
        "p (Holm)",
        "verdict"
    );
    for r in &c.passes {
        let ci = match (r.ci_low, r.ci_high) {
            (Some(a), Some(b)) => format!("[{}, {}]", pct(Some(a)), pct(Some(b))),
            _ => "n/a".into(),
        };
        let verdict = if r.ruler {
            format!("({}, ruler, ms)", r.verdict.name())
        } else if !r.judged {
            format!("({}, not in --passes)", r.verdict.name())
        } else {
            match (r.verdict, r.more_samples) {
                (Verdict::Inconclusive, Some(k)) => {
                    format!("inconclusive: ~{k} more {}s per side", r.sample)
                }
                (Verdict::Inconclusive, None) => {
                    "inconclusive: the change sits on the threshold".into()
                }
                (v, _) => v.name().to_string(),
            }
        };
        s += &format!(
            "{:<24} {:>10} {:>10} {:>7} {:>7} {:>8} {:>19} {:>9} {:>9}  {}\n",
            r.name,
            ms(r.base_ms),
            ms(r.new_ms),
            xr(r.base_x_ruler),
            xr(r.new_x_ruler),
            pct(r.change),
            ci,
            format!(
                "{} {}{}",
                p(r.p),
                r.test.short(),
                if r.outlier { "!" } else { "" }
            ),
            p(r.p_holm),
            verdict
        );
    }
    let unit = if c.passes.iter().any(|r| r.unit == "ruler") {
        "ruler units"
    } else {
        "ms"
    };
    let sample = c.passes.first().map_or("frame", |r| r.sample);
    s += &format!(
        "{} regressed, {} improved, {} unchanged, {} inconclusive (change in {unit}, \
         one sample per {sample}; threshold ±{:.1} %, α = {} Holm-corrected; \
         t: Welch on log-times, U: Mann-Whitney, !: a run stands out)\n",
        c.count(Verdict::Regressed),
        c.count(Verdict::Improved),
        c.count(Verdict::Unchanged),
        c.count(Verdict::Inconclusive),
        100.0 * c.options.noise_threshold,
        c.options.significance
    );
    for (side, names) in [("base", &c.only_in_base), ("new", &c.only_in_new)] {
        if !names.is_empty() {
            s += &format!("only in {side}: {}\n", names.join(", "));
        }
    }
    for j in &c.joined {
        s += &format!("joined: {j}\n");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A measurement of `runs` runs × `frames` frames of pass "blur" at
    /// `ns(run, frame)` and a ruler at 1000 ns × `load(run, frame)`, where
    /// blur is scaled by the same load.
    fn measurement(
        runs: usize,
        frames: usize,
        blur: impl Fn(usize, usize) -> f64,
        load: impl Fn(usize, usize) -> f64,
    ) -> Measurement {
        let mut m = Measurement {
            source: "m".into(),
            pass_order: vec!["blur".into(), "skin".into(), RULER_COPY.into()],
            ..Default::default()
        };
        for r in 0..runs {
            for f in 0..frames {
                let l = load(r, f);
                m.frames.push(MeasuredFrame {
                    run: format!("run{r}"),
                    passes: [
                        ("blur".to_string(), blur(r, f) * l),
                        ("skin".to_string(), 5000.0 * l),
                        (RULER_COPY.to_string(), 1000.0 * l),
                    ]
                    .into(),
                });
            }
        }
        m
    }

    /// Deterministic noise in [−1, 1).
    fn noise(i: usize) -> f64 {
        let x = (i as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 11;
        (x as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }

    fn row<'a>(c: &'a Comparison, name: &str) -> &'a PassChange {
        c.passes.iter().find(|p| p.name == name).unwrap()
    }

    #[test]
    fn a_pass_split_in_two_on_one_side_is_joined() {
        // base: blur_u + blur_v (1000 + 1000 × n); new: one pass blur.
        let mut base = measurement(6, 3, |r, f| 1000.0 + 10.0 * noise(r * 3 + f), |_, _| 1.0);
        base.pass_order = ["blur_u", "blur_v", "skin", RULER_COPY]
            .map(String::from)
            .into();
        for f in &mut base.frames {
            let t = f.passes.remove("blur").unwrap();
            f.passes.insert("blur_u".into(), 1000.0);
            f.passes.insert("blur_v".into(), t);
        }
        let new = measurement(
            6,
            3,
            |r, f| 1000.0 + 10.0 * noise(r * 3 + f + 50),
            |_, _| 1.0,
        );
        let c = compare(&base, &new, &CompareOptions::default()).unwrap();
        assert!(
            c.only_in_base.is_empty() && c.only_in_new.is_empty(),
            "{c:?}"
        );
        assert_eq!(c.joined, ["blur = blur_u + blur_v in m"]);
        let r = row(&c, "blur");
        assert!(
            (r.base_ms.unwrap() / r.new_ms.unwrap() - 2.0).abs() < 0.05,
            "{r:?}"
        );
        assert_eq!(r.verdict, Verdict::Improved);
        assert_eq!(c.passes[0].name, "blur");
    }

    #[test]
    fn identical_distributions_are_unchanged() {
        let a = measurement(
            10,
            5,
            |r, f| 3000.0 * (1.0 + 0.005 * noise(r * 7 + f)),
            |_, _| 1.0,
        );
        let b = measurement(
            10,
            5,
            |r, f| 3000.0 * (1.0 + 0.005 * noise(r * 7 + f + 100)),
            |_, _| 1.0,
        );
        let c = compare(&a, &b, &CompareOptions::default()).unwrap();
        let blur = row(&c, "blur");
        assert_eq!(blur.verdict, Verdict::Unchanged, "{}", table(&c));
        assert_eq!(blur.sample, "run");
        assert!(!c.regressed());
    }

    #[test]
    fn a_twenty_percent_shift_is_a_regression_bracketed_by_its_interval() {
        let a = measurement(
            10,
            5,
            |r, f| 3000.0 * (1.0 + 0.01 * noise(r * 7 + f)),
            |_, _| 1.0,
        );
        let b = measurement(
            10,
            5,
            |r, f| 3600.0 * (1.0 + 0.01 * noise(r * 7 + f + 50)),
            |_, _| 1.0,
        );
        let c = compare(&a, &b, &CompareOptions::default()).unwrap();
        let blur = row(&c, "blur");
        assert_eq!(blur.verdict, Verdict::Regressed, "{}", table(&c));
        // The samples' own change is 20 % ± their 1 % noise; the interval is that narrow.
        let (lo, hi) = (blur.ci_low.unwrap(), blur.ci_high.unwrap());
        assert!((blur.change.unwrap() - 0.2).abs() < 0.01, "{blur:?}");
        assert!(lo > 0.18 && hi < 0.22 && hi - lo < 0.02, "{lo} {hi}");
        assert_eq!(row(&c, "skin").verdict, Verdict::Unchanged);
        assert!(c.regressed());
        // The other way round it is an improvement.
        let back = compare(&b, &a, &CompareOptions::default()).unwrap();
        assert_eq!(row(&back, "blur").verdict, Verdict::Improved);
    }

    #[test]
    fn a_busier_machine_cancels_in_ruler_units() {
        // Runs ±20 % apart from machine load, the new side 30 % busier still:
        // the ruler steadies it, so it is chosen, and nothing changed.
        let load = |side: f64| move |r: usize, _| side * (1.0 + 0.2 * noise(r + 77));
        let a = measurement(
            10,
            4,
            |r, f| 3000.0 * (1.0 + 0.005 * noise(r * 5 + f)),
            load(1.0),
        );
        let b = measurement(
            10,
            4,
            |r, f| 3000.0 * (1.0 + 0.005 * noise(r * 5 + f + 9)),
            load(1.3),
        );
        let c = compare(&a, &b, &CompareOptions::default()).unwrap();
        assert_eq!(row(&c, "blur").unit, "ruler");
        assert_eq!(row(&c, "blur").verdict, Verdict::Unchanged, "{}", table(&c));
        assert!(row(&c, "blur").change_ms.unwrap() > 0.2);
        assert!(!c.regressed(), "a ruler is shown, not judged");
        // In ms the same data is a regression (or at least no "unchanged").
        let ms = CompareOptions {
            unit: Unit::Ms,
            ..Default::default()
        };
        let c = compare(&a, &b, &ms).unwrap();
        assert_ne!(row(&c, "blur").verdict, Verdict::Unchanged, "{}", table(&c));
    }

    #[test]
    fn a_ruler_noisier_than_the_passes_is_not_used() {
        // A steady machine, a ruler that jitters ±50 % (a tiny pass on a host
        // clock): auto compares in ms.
        let mut a = measurement(
            10,
            3,
            |r, f| 3000.0 * (1.0 + 0.01 * noise(r * 3 + f)),
            |_, _| 1.0,
        );
        for (i, f) in a.frames.iter_mut().enumerate() {
            f.passes
                .insert(RULER_COPY.into(), 1000.0 * (1.0 + 0.5 * noise(i + 300)));
        }
        let c = compare(&a, &a, &CompareOptions::default()).unwrap();
        assert_eq!(row(&c, "blur").unit, "ms");
        assert!(
            c.warnings.iter().any(|w| w.contains("does not steady")),
            "{:?}",
            c.warnings
        );
        assert_eq!(row(&c, "blur").verdict, Verdict::Unchanged);
    }

    #[test]
    fn heavy_overlap_is_inconclusive_and_says_how_much_more() {
        // ±20 % noise, 3 runs a side, a 4 % shift: nothing can be decided.
        let a = measurement(
            3,
            3,
            |r, f| 3000.0 * (1.0 + 0.2 * noise(r * 3 + f)),
            |_, _| 1.0,
        );
        let b = measurement(
            3,
            3,
            |r, f| 3120.0 * (1.0 + 0.2 * noise(r * 3 + f + 40)),
            |_, _| 1.0,
        );
        let c = compare(&a, &b, &CompareOptions::default()).unwrap();
        let blur = row(&c, "blur");
        assert_eq!(blur.verdict, Verdict::Inconclusive, "{}", table(&c));
        assert!(blur.more_samples.is_some_and(|k| k >= 1), "{blur:?}");
        assert!(table(&c).contains("more runs per side"), "{}", table(&c));
    }

    #[test]
    fn one_run_a_side_compares_frames_and_warns() {
        let a = measurement(1, 20, |_, f| 3000.0 * (1.0 + 0.01 * noise(f)), |_, _| 1.0);
        let b = measurement(
            1,
            20,
            |_, f| 3900.0 * (1.0 + 0.01 * noise(f + 3)),
            |_, _| 1.0,
        );
        let c = compare(&a, &b, &CompareOptions::default()).unwrap();
        assert_eq!(row(&c, "blur").sample, "frame");
        assert_eq!(row(&c, "blur").verdict, Verdict::Regressed);
        assert!(
            c.warnings.iter().any(|w| w.contains("one run")),
            "{:?}",
            c.warnings
        );
    }

    #[test]
    fn setups_and_clocks_are_checked_first() {
        let mut a = measurement(2, 2, |_, _| 1.0, |_, _| 1.0);
        let mut b = a.clone();
        a.setup
            .insert("irradiance_resolution".into(), "1024".into());
        b.setup
            .insert("irradiance_resolution".into(), "2048".into());
        let e = compare(&a, &b, &CompareOptions::default()).unwrap_err();
        assert!(
            e.to_string().contains("irradiance_resolution: 1024 → 2048"),
            "{e}"
        );
        let allowed = CompareOptions {
            allow_setup_change: true,
            ..Default::default()
        };
        assert!(compare(&a, &b, &allowed).is_ok());
        // A kernel change is the change under test: listed, not refused.
        b.setup
            .insert("irradiance_resolution".into(), "1024".into());
        a.setup.insert("kernel".into(), "deon7".into());
        b.setup.insert("kernel".into(), "accurate".into());
        b.fingerprint.cpu_cores = 16;
        let c = compare(&a, &b, &CompareOptions::default()).unwrap();
        assert_eq!(c.setup_changes, ["kernel: deon7 → accurate"]);
        assert!(c.warnings.iter().any(|w| w.contains("cpu_cores: 0 → 16")));
        b.fingerprint.clock = "host-fence".into();
        a.fingerprint.clock = "gpu-timestamp".into();
        assert!(compare(&a, &b, &CompareOptions::default()).is_err());
    }
}
