//! `dermis sweep` and `dermis sweep merge`.

use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};
use dermis::gpu::{Context, ContextOptions};
use dermis::scene::file::{Chain, Kernel};
use dermis::scene::{Overrides, SceneArg};
use dermis::sweep::{self as sw, output};

use super::{check_out_dir, to_json, AFTER_HELP};

#[derive(Args)]
#[command(
    mut_arg("irradiance_res", |a| a.hide(true)),
    mut_arg("kernel", |a| a.hide(true)),
    mut_arg("chain", |a| a.hide(true)),
    mut_arg("skybox", |a| a.hide(true))
)]
pub struct SweepArgs {
    #[command(subcommand)]
    command: Option<SweepCommand>,
    #[command(flatten)]
    scene: SceneArg,
    /// Irradiance resolutions (powers of two, 256..8192), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "256,512,1024,2048,4096")]
    resolutions: Vec<u32>,
    /// Blur kernels, comma-separated.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "deon7,accurate"
    )]
    kernels: Vec<Kernel>,
    /// Diffusion chains, comma-separated.
    #[arg(
        long,
        value_enum,
        value_delimiter = ',',
        default_value = "full,adaptive"
    )]
    chains: Vec<Chain>,
    /// Frames per point (≥ 2; the first is warm-up, the rest give medians).
    #[arg(long, default_value_t = 4)]
    frames: u32,
    /// Pre-roll per point: after its first frame, unreported frames for this
    /// many milliseconds, so that a GPU's clocks are up (default: 1000 on GPUs,
    /// 0 on CPU devices such as lavapipe).
    #[arg(long, value_name = "MS")]
    warmup_ms: Option<u32>,
    /// Irradiance resolution of the reference (accurate kernel, full chain).
    #[arg(long, default_value_t = 4096)]
    reference_resolution: u32,
    #[command(flatten)]
    overrides: Overrides,
    /// Directory for the CSV, JSON and plots (created).
    #[arg(long, default_value = "sweep")]
    out_dir: PathBuf,
    /// Render nothing: redraw the plots and CSV of --out-dir from its sweep.json.
    #[arg(long)]
    replot: bool,
    /// Render only this shard of the points: I/N (1-based; same as hash:I/N, by a
    /// hash of each point's id, stable as points are added), count:I/N (every
    /// N-th point from the I-th: balanced), or auto (from Slurm, Kubernetes,
    /// GitLab, Bazel or DERMIS_SHARD; see docs/guide/sweep.md). Without it,
    /// DERMIS_SHARD (same syntax) is read. Writes points-shard-I-of-N.jsonl
    /// into --out-dir; merge with `dermis sweep merge`.
    #[arg(long, value_name = "I/N|hash:I/N|count:I/N|auto")]
    shard: Option<String>,
    /// Render nothing: print the points (id, resolution, kernel, chain) in
    /// canonical order and the sweep hash.
    #[arg(long)]
    list_points: bool,
    /// With --list-points: print JSON.
    #[arg(long, requires = "list_points")]
    json: bool,
    /// Skip the points already in --out-dir's log for this sweep (same sweep
    /// hash), appending the rest to it.
    #[arg(long)]
    resume: bool,
}

#[derive(Subcommand)]
enum SweepCommand {
    /// Merge the points logs (*.jsonl) of a sharded sweep into sweep.json,
    /// sweep.csv and the plots, as an unsharded sweep writes them. Every point
    /// must appear; of duplicates the later run's is kept (header timestamp,
    /// then argument and file-name order, then line order).
    #[command(after_help = AFTER_HELP)]
    Merge(MergeArgs),
}

#[derive(Args)]
struct MergeArgs {
    /// Folders (their *.jsonl) or files.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// Where to write; default: the first input folder.
    #[arg(long)]
    out_dir: Option<PathBuf>,
    /// Merge even when the shards' reference images differ (their errors
    /// are then against different images).
    #[arg(long)]
    allow_reference_mismatch: bool,
}

/// `dermis sweep` and `dermis sweep merge`.
pub fn sweep(args: SweepArgs, context: &ContextOptions) -> dermis::Result<()> {
    if let Some(SweepCommand::Merge(merge_args)) = args.command {
        return merge(merge_args);
    }
    check_out_dir("--out-dir", &args.out_dir)?;
    if args.replot {
        let sweep = sw::load(&args.out_dir.join("sweep.json"))?;
        output::write_csv_and_plots(&sweep, &args.out_dir)?;
        outln!("redrew {}", args.out_dir.display());
        return Ok(());
    }
    // What the sweep sets itself (hidden from its help).
    let o = &args.overrides;
    for (given, flag, instead) in [
        (
            o.irradiance_res.is_some(),
            "irradiance-res",
            "give --resolutions",
        ),
        (o.kernel.is_some(), "kernel", "give --kernels"),
        (o.chain.is_some(), "chain", "give --chains"),
        (
            o.skybox.is_some(),
            "skybox",
            "it is off: the face mask is the alpha",
        ),
    ] {
        if given {
            return Err(dermis::Error::Input(format!(
                "sweep: --{flag} is set by the sweep; {instead}"
            )));
        }
    }
    let opts = sw::SweepOptions {
        scene: args.scene.load(&args.overrides)?,
        scene_label: args.scene.path()?.display().to_string(),
        resolutions: args.resolutions,
        kernels: args.kernels,
        chains: args.chains,
        frames: args.frames,
        warmup_ms: args.warmup_ms,
        reference_resolution: args.reference_resolution,
    };
    sw::validate(&opts)?;
    let env = |k: &str| std::env::var(k).ok();
    let resolved = sw::shard::resolve(args.shard.as_deref(), &env)?;
    if let Some(r) = &resolved {
        eprintln!("{r}");
    }
    let shard = resolved.as_ref().map(|r| r.shard);
    if args.list_points {
        return list_points(&opts, shard, args.json);
    }
    if let Some(r) = &resolved {
        sw::shard::acknowledge(r)?;
    }
    let out_dir = args.out_dir;
    std::fs::create_dir_all(&out_dir).map_err(|source| dermis::Error::Io {
        path: out_dir.display().to_string(),
        source,
    })?;
    let log = out_dir.join(shard.map_or_else(|| "points.jsonl".into(), |s| s.file_name()));
    // Held to the end: a second sweep into this log is refused.
    let _lock = sw::log::Lock::acquire(&log)?;
    let ctx = Context::new(context)?;
    outln!("{}", sw::TABLE_HEADER);
    let how = sw::RunOptions {
        shard,
        log: Some(log.clone()),
        resume: args.resume,
    };
    let sweep = sw::run(&ctx, &opts, &how, |p| outln!("{}", sw::table_row(p)))?;
    if shard.is_some() {
        outln!(
            "wrote {} ({} points); merge the shards with `dermis sweep merge`",
            log.display(),
            sweep.points.len()
        );
    } else {
        output::write_all(&sweep, &out_dir)?;
        outln!("wrote {}", out_dir.display());
    }
    Ok(())
}

/// `dermis sweep --list-points`.
fn list_points(
    opts: &sw::SweepOptions,
    shard: Option<sw::shard::Shard>,
    json: bool,
) -> dermis::Result<()> {
    let list = sw::points::list(opts, shard);
    if json {
        outln!("{}", to_json(Path::new("stdout"), &list)?);
        return Ok(());
    }
    for p in &list.points {
        outln!("{}", p.id);
    }
    outln!(
        "sweep hash {} ({} points)",
        list.sweep_hash,
        list.points.len()
    );
    Ok(())
}

/// `dermis sweep merge`.
fn merge(args: MergeArgs) -> dermis::Result<()> {
    if let Some(dir) = &args.out_dir {
        check_out_dir("--out-dir", dir)?;
    }
    let merged = sw::merge::merge(
        &args.inputs,
        sw::merge::MergeOptions {
            allow_reference_mismatch: args.allow_reference_mismatch,
        },
    )?;
    for w in &merged.warnings {
        eprintln!("warning: {w}");
    }
    let out_dir = args
        .out_dir
        .unwrap_or_else(|| sw::merge::default_out_dir(&args.inputs));
    output::write_all(&merged.sweep, &out_dir)?;
    outln!(
        "merged {} points from {} run(s) into {}",
        merged.sweep.points.len(),
        merged.sweep.shards.len(),
        out_dir.display()
    );
    Ok(())
}
