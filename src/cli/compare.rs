//! `dermis compare`, `interleave`, `export` and `report-schema`: measurements
//! after the fact.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::Args;
use dermis::sweep::side::{self as input, Side};
use dermis::timing::regression::{self, Comparison, Measurement};

use super::{check_distinct, check_out_dir, check_output, read_text, to_json, write_file};

/// How `compare` and `interleave` decide and what they write.
#[derive(Args)]
pub struct DecideArgs {
    /// What each pass's time is compared in: `ruler` (over the ruler pass of
    /// its frame or run: a busier machine cancels), `ms`, or `auto` (ruler units
    /// where they scatter less between samples than ms).
    #[arg(long, value_enum, default_value = "auto")]
    unit: regression::Unit,
    /// Relative change below which a pass is not reported changed (0.06 = 6 %:
    /// the A/A noise measured in docs/guide/compare-in-ci.md).
    #[arg(long, default_value_t = regression::DEFAULT_NOISE_THRESHOLD)]
    noise_threshold: f64,
    /// Family-wise significance level (Holm-corrected over the passes).
    #[arg(long, default_value_t = regression::DEFAULT_SIGNIFICANCE)]
    significance: f64,
    /// Compare even where the work differs (scene, mesh, view, sizes).
    #[arg(long)]
    allow_setup_change: bool,
    /// The passes the change targets, comma-separated: only they and the
    /// frame's sum are judged (Holm over them alone, so fewer runs decide);
    /// the others are shown, not judged.
    #[arg(long, value_delimiter = ',', value_name = "PASS,...")]
    passes: Vec<String>,
    /// Print the comparison as JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Also write a JUnit XML summary (one test case per pass, failed when regressed).
    #[arg(long, value_name = "FILE.xml")]
    junit: Option<PathBuf>,
    /// Exit with status 3 when any pass regressed.
    #[arg(long)]
    fail_on_regression: bool,
}

#[derive(Args)]
pub struct CompareArgs {
    /// The base: a run report (render --report), a folder of reports (pooled
    /// as runs of one setup), or a sweep (sweep.json).
    base: PathBuf,
    /// The new measurement, of the same kind.
    new: PathBuf,
    #[command(flatten)]
    decide: DecideArgs,
}

#[derive(Args)]
pub struct InterleaveArgs {
    /// Runs per side.
    #[arg(long, default_value_t = 10)]
    runs: u32,
    /// Frames per run (the first is warm-up).
    #[arg(long, default_value_t = 3)]
    frames: u32,
    /// The base's dermis binary (default: this one).
    #[arg(long)]
    base_bin: Option<PathBuf>,
    /// The new side's dermis binary (default: this one).
    #[arg(long)]
    new_bin: Option<PathBuf>,
    /// The base's render options, as one shell-quoted string
    /// (e.g. "--irradiance-res 1024").
    #[arg(long, default_value = "", allow_hyphen_values = true)]
    base_args: String,
    /// The new side's render options (e.g. "--irradiance-res 1024 --kernel accurate").
    #[arg(long, default_value = "", allow_hyphen_values = true)]
    new_args: String,
    /// Where the runs' reports (base/run-K.json, new/run-K.json: `dermis
    /// compare DIR/base DIR/new` compares them again) and images go (created).
    #[arg(long, default_value = "interleave")]
    out_dir: PathBuf,
    #[command(flatten)]
    decide: DecideArgs,
}

#[derive(Args)]
pub struct ExportArgs {
    /// A run report (render --report).
    report: PathBuf,
    /// Write github-action-benchmark's customSmallerIsBetter JSON here.
    #[arg(long, value_name = "FILE.json")]
    github_benchmark: Option<PathBuf>,
    /// Write Bencher Metric Format (BMF) JSON here.
    #[arg(long, value_name = "FILE.json")]
    bencher: Option<PathBuf>,
}

impl DecideArgs {
    fn check_outputs(&self) -> dermis::Result<()> {
        match &self.junit {
            Some(path) => check_output("--junit", path, &["xml"]),
            None => Ok(()),
        }
    }
}

/// `dermis compare`: two reports (or folders of them), or two sweeps point by point.
pub fn compare(args: CompareArgs) -> dermis::Result<ExitCode> {
    args.decide.check_outputs()?;
    match (input::load(&args.base)?, input::load(&args.new)?) {
        (Side::Runs(base, w1), Side::Runs(new, w2)) => report_comparison(
            &[(String::new(), *base, *new)],
            &args.decide,
            [w1, w2].concat(),
        ),
        (Side::Sweep(base), Side::Sweep(mut new)) => {
            let mut warnings = Vec::new();
            let mut pairs = Vec::new();
            for (id, b) in base {
                match new.iter().position(|(n, _)| *n == id) {
                    Some(i) => pairs.push((id, b, new.remove(i).1)),
                    None => warnings.push(format!("point {id} is only in the base")),
                }
            }
            warnings.extend(
                new.iter()
                    .map(|(id, _)| format!("point {id} is only in the new sweep")),
            );
            report_comparison(&pairs, &args.decide, warnings)
        }
        _ => Err(dermis::Error::Input(
            "compare: give two reports (or folders of them) or two sweeps, not one of each".into(),
        )),
    }
}

/// `dermis interleave`.
pub fn interleave(args: InterleaveArgs) -> dermis::Result<ExitCode> {
    args.decide.check_outputs()?;
    check_out_dir("--out-dir", &args.out_dir)?;
    let me = std::env::current_exe().map_err(|source| dermis::Error::Io {
        path: "the running dermis binary".into(),
        source,
    })?;
    let sides = [
        (
            "base",
            args.base_bin.unwrap_or_else(|| me.clone()),
            args.base_args,
        ),
        ("new", args.new_bin.unwrap_or(me), args.new_args),
    ];
    let [base, new] =
        dermis::sweep::interleave::run(&sides, args.runs, args.frames, &args.out_dir)?;
    report_comparison(
        &[(String::new(), base.0, new.0)],
        &args.decide,
        [base.1, new.1].concat(),
    )
}

/// `dermis export`.
pub fn export(args: ExportArgs) -> dermis::Result<()> {
    if args.github_benchmark.is_none() && args.bencher.is_none() {
        return Err(dermis::Error::Input(
            "export: give --github-benchmark FILE or --bencher FILE".into(),
        ));
    }
    for (flag, path) in [
        ("--github-benchmark", &args.github_benchmark),
        ("--bencher", &args.bencher),
    ] {
        if let Some(path) = path {
            check_output(flag, path, &["json"])?;
        }
    }
    check_distinct(&[
        ("--github-benchmark", args.github_benchmark.as_deref()),
        ("--bencher", args.bencher.as_deref()),
    ])?;
    let text = read_text(&args.report)?;
    let source = args.report.display().to_string();
    let value: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| dermis::Error::Input(format!("{source}: not JSON: {e}")))?;
    dermis::timing::regression::check_report_schema(&value, &source)?;
    let r: dermis::timing::RunReport = serde_json::from_value(value)
        .map_err(|e| dermis::Error::Input(format!("{source}: not a dermis run report: {e}")))?;
    if let Some(path) = args.github_benchmark {
        let v = dermis::timing::export::github_benchmark(&r);
        write_file(&path, &to_json(&path, &v)?)?;
    }
    if let Some(path) = args.bencher {
        write_file(
            &path,
            &to_json(&path, &dermis::timing::export::bencher(&r))?,
        )?;
    }
    Ok(())
}

/// `dermis report-schema`.
pub fn report_schema() -> dermis::Result<()> {
    let schema = schemars::schema_for!(dermis::timing::RunReport);
    outln!("{}", to_json(Path::new("stdout"), &schema)?);
    Ok(())
}

/// Compares each pair (a sweep's points by id; a report's one pair with no
/// label), prints the tables (or JSON), writes the JUnit file; status 3 on a
/// regression when asked.
fn report_comparison(
    pairs: &[(String, Measurement, Measurement)],
    decide: &DecideArgs,
    warnings: Vec<String>,
) -> dermis::Result<ExitCode> {
    let opts = regression::CompareOptions {
        unit: decide.unit,
        noise_threshold: decide.noise_threshold,
        significance: decide.significance,
        allow_setup_change: decide.allow_setup_change,
        passes: decide.passes.clone(),
    };
    if pairs.is_empty() {
        return Err(dermis::Error::Input(format!(
            "compare: nothing in common to compare ({})",
            warnings.join("; ")
        )));
    }
    let mut results: Vec<(String, Comparison)> = Vec::new();
    for (label, base, new) in pairs {
        results.push((label.clone(), regression::compare(base, new, &opts)?));
    }
    if let [(label, c)] = results.as_mut_slice() {
        if label.is_empty() {
            c.warnings.splice(0..0, warnings.iter().cloned());
        }
    }
    let single = results.len() == 1 && results[0].0.is_empty();
    if decide.json {
        let value = if single {
            serde_json::to_value(&results[0].1)
        } else {
            serde_json::to_value(serde_json::json!({
                "warnings": warnings,
                "points": results.iter().map(|(id, c)| serde_json::json!({"id": id, "comparison": c})).collect::<Vec<_>>(),
            }))
        }
        .map_err(|e| dermis::Error::Input(e.to_string()))?;
        outln!("{}", to_json(Path::new("stdout"), &value)?);
    } else {
        if !single {
            for w in &warnings {
                outln!("warning: {w}");
            }
        }
        for (label, c) in &results {
            if !label.is_empty() {
                outln!("\n== point {label}");
            }
            out!("{}", regression::table(c));
        }
    }
    let comparisons: Vec<&Comparison> = results.iter().map(|(_, c)| c).collect();
    if let Some(path) = &decide.junit {
        write_file(path, &dermis::timing::export::junit(&comparisons))?;
    }
    let regressed = comparisons.iter().any(|c| c.regressed());
    Ok(if decide.fail_on_regression && regressed {
        ExitCode::from(3)
    } else {
        ExitCode::SUCCESS
    })
}
