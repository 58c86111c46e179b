//! The `dermis` command line. Rendering logic lives in the library.

use clap::{Parser, Subcommand};
use dermis::gpu::{Context, ContextOptions};
use dermis::light::extract;
use dermis::profile::compare::{self, Comparison, Measurement};
use dermis::render::output::{write_sheet, Format};
use dermis::render::{compare_occlusion, debug_sheet, render_scene, RenderOptions, View};
use dermis::scene::file::{
    default_scene_path, scene_by_name, Chain, Kernel, LightsMode, Occlusion, ToneCurve, UvOrigin,
};
use dermis::scene::{Overrides, Scene};
use dermis::sweep::compare as compare_input;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Environment variables and exit codes, shown by every command's `--help`.
const AFTER_HELP: &str = "\
Environment:
  DERMIS_DEVICE=SUBSTRING   device to use (as --device)
  DERMIS_VALIDATION=1       Khronos validation + synchronization validation (as --validation)
  DERMIS_CACHE_DIR=DIR      occlusion transfer cache (default $XDG_CACHE_HOME/dermis or ~/.cache/dermis)
  RUST_LOG=LEVEL            log filter (overrides -v)
  LP_NUM_THREADS=N          lavapipe's rasterizer threads (recorded in reports)
  DISPLAY                   the X display `dermis view` opens its window on

Exit status:
  0 success, 2 bad input (files, sizes, options), 1 anything else (device, driver,
  window system); compare and interleave with --fail-on-regression: 3 when a pass
  regressed.";

#[derive(Parser)]
#[command(
    name = "dermis",
    version,
    about = "Realistic face rendering on Vulkan, measured pass by pass",
    after_help = AFTER_HELP,
    subcommand_help_heading = "Commands"
)]
struct Cli {
    /// Use the first Vulkan device whose name contains this (case-insensitive).
    #[arg(long, global = true, env = "DERMIS_DEVICE")]
    device: Option<String>,
    /// Enable the Khronos validation layer with synchronization validation.
    #[arg(long, global = true, env = "DERMIS_VALIDATION", value_parser = clap::builder::BoolishValueParser::new())]
    validation: bool,
    /// More log output (-v info, -vv debug); RUST_LOG overrides.
    #[arg(short, long, global = true, action = clap::ArgAction::Count)]
    verbose: u8,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Describe the Vulkan device dermis would use.
    #[command(after_help = AFTER_HELP)]
    Info {
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Print an environment's 27 SH coefficients (9 per channel), projected on the GPU.
    #[command(after_help = AFTER_HELP)]
    Sh {
        /// A .hdr/.exr file, a cross, `cube:...`, `uniform:R,G,B` or `sky[:...]`.
        env: String,
        /// Rotation about +Y, degrees.
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        rotate: f32,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
        /// Also print the GPU passes' timings.
        #[arg(long)]
        timings: bool,
    },
    /// List the bright sources (suns, softboxes) taken out of an environment as lights.
    ///
    /// Per light: its direction (world, after --rotate), elevation and azimuth,
    /// solid angle, angular radius, power (RGB irradiance at normal incidence) and
    /// share of the map's energy; then the residual's share (docs/lighting.md).
    /// Shares are fractions in --json. Runs on the CPU.
    #[command(after_help = AFTER_HELP)]
    Lights {
        /// A .hdr/.exr file, a cross, `cube:...`, `uniform:R,G,B` or `sky[:...]`.
        env: String,
        /// Rotation of the environment about +Y, degrees (as `environment.rotation_deg`).
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        rotate: f32,
        /// `auto` (compact sources holding ≥ 5 % of the energy) or the N strongest (0..=8).
        #[arg(
            long,
            default_value = "auto",
            value_name = "auto|N",
            allow_hyphen_values = true
        )]
        lights: LightsMode,
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Compute (and cache) the per-vertex occlusion transfer ahead of rendering.
    #[command(after_help = AFTER_HELP)]
    Precompute {
        /// Scene file (its mesh and `skin.occlusion` are used), or `builtin`;
        /// default: assets/default.toml.
        #[arg(long)]
        scene: Option<PathBuf>,
        /// glTF mesh, replacing the scene's.
        #[arg(long)]
        mesh: Option<PathBuf>,
        /// Millimetres per mesh unit (e.g. 50.3 for the Lee Perry-Smith scan).
        #[arg(long)]
        mm_per_unit: Option<f32>,
        /// How visibility is computed (default: the scene's, raytrace).
        #[arg(long, value_enum)]
        occlusion: Option<Occlusion>,
    },
    /// Time against quality: render every irradiance resolution × blur kernel ×
    /// diffusion chain with the rulers and compare each final image and diffuse
    /// term with a reference over the face (RMSE and max relative to the mean,
    /// 99th percentile, PSNR). Writes points.jsonl, sweep.csv, sweep.json,
    /// time_vs_error.{svg,png} and passes.{svg,png} into --out-dir; with --shard,
    /// only this shard's points-shard-I-of-N.jsonl, for `dermis sweep merge`
    /// (docs/performance.md, docs/recipes/).
    #[command(after_help = AFTER_HELP, args_conflicts_with_subcommands = true)]
    Sweep(SweepArgs),
    /// Lighting against the truth: for each environment, the direct term
    /// (`--view direct`, grey albedo) with the paper's SH9 alone and with the
    /// bright sources extracted as shadowed lights, each against the CPU
    /// reference (`--view reference`); prints the mean, median and 90th
    /// percentile of the per-pixel relative error over the mesh (docs/lighting.md).
    #[command(after_help = AFTER_HELP)]
    Reference {
        /// Scene file, or `builtin`; default: assets/default.toml. Its
        /// environment is replaced by each of --envs.
        #[arg(long)]
        scene: Option<PathBuf>,
        /// An environment (as --env of render); repeat for several. Default:
        /// the scene's own.
        #[arg(long = "env")]
        envs: Vec<String>,
        /// Image width in pixels.
        #[arg(long, default_value_t = 96)]
        width: u32,
        /// Image height in pixels.
        #[arg(long, default_value_t = 120)]
        height: u32,
        /// The reference's target relative standard error per pixel.
        #[arg(long, default_value_t = 0.005)]
        target_error: f32,
        /// Directory for each environment's images (EXR) and a PNG of the
        /// reference, SH9 and SH9 + lights side by side.
        #[arg(long)]
        out_dir: Option<PathBuf>,
        /// Print JSON instead of a table.
        #[arg(long)]
        json: bool,
    },
    /// Open the interactive viewer: the scene in a window (winit, Vulkan
    /// swapchain) with an orbit camera, the paper's controls and live per-pass
    /// timings.
    ///
    /// Mouse and keys: left drag orbits, right or middle drag pans, the wheel
    /// zooms; Shift + left drag turns the environment; right click opens the
    /// controls; F12 writes a screenshot (PNG), R reloads the scene file, Esc
    /// quits.
    #[command(after_help = AFTER_HELP)]
    View {
        /// Scene file, or `builtin`; default: assets/default.toml.
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Environment, replacing the scene's (as render --env).
        #[arg(long)]
        env: Option<String>,
        /// Side of the UV-space irradiance texture, replacing the scene's.
        #[arg(long)]
        irradiance_res: Option<u32>,
        /// Window width in pixels (default: the scene's render width plus the
        /// panel's, 360).
        #[arg(long)]
        width: Option<u32>,
        /// Window height in pixels (default: the scene's render height).
        #[arg(long)]
        height: Option<u32>,
        /// Render N window frames and exit (resizing the window once halfway,
        /// and waiting for the last render to be shown): for headless tests.
        #[arg(long)]
        frames: Option<u32>,
        /// Where the last frame of a --frames run (and F12) writes its PNG.
        #[arg(long)]
        screenshot: Option<PathBuf>,
    },
    /// Compare two measurements pass by pass: the change of each pass's median
    /// (in ruler units where both sides ran --ruler, else ms), a bootstrap 95 %
    /// interval, a Mann-Whitney U p-value Holm-corrected over the passes, and a
    /// verdict: regressed / improved / unchanged / inconclusive (docs/performance.md,
    /// "Comparing runs").
    #[command(after_help = AFTER_HELP)]
    Compare {
        /// The base: a run report (render --report), a folder of reports (pooled
        /// as runs of one setup), or a sweep (sweep.json).
        base: PathBuf,
        /// The new measurement, of the same kind.
        new: PathBuf,
        #[command(flatten)]
        decide: DecideArgs,
    },
    /// Run two binaries or two option sets alternately (A B B A A B …: drift
    /// cancels), each run a process of `render --frames F --ruler --report`, then
    /// compare them as `dermis compare` does.
    #[command(after_help = AFTER_HELP)]
    Interleave {
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
    },
    /// Convert a run report for CI dashboards: github-action-benchmark
    /// (`customSmallerIsBetter`) and Bencher Metric Format JSON.
    #[command(after_help = AFTER_HELP)]
    Export {
        /// A run report (render --report).
        report: PathBuf,
        /// Write github-action-benchmark's customSmallerIsBetter JSON here.
        #[arg(long, value_name = "FILE.json")]
        github_benchmark: Option<PathBuf>,
        /// Write Bencher Metric Format (BMF) JSON here.
        #[arg(long, value_name = "FILE.json")]
        bencher: Option<PathBuf>,
    },
    /// Print the JSON Schema of run reports (docs/report.schema.json).
    #[command(after_help = AFTER_HELP)]
    ReportSchema,
    /// Render a scene to an image (by default the scanned head, assets/default.toml).
    #[command(after_help = AFTER_HELP)]
    Render {
        /// Scene file (docs/scene-format.md), or `builtin` for the built-in
        /// procedural head under the sky; default: assets/default.toml.
        #[arg(long)]
        scene: Option<PathBuf>,
        /// Output image: .png (8-bit sRGB) or .exr (linear float).
        #[arg(long, default_value = "dermis.png")]
        out: PathBuf,
        /// glTF mesh (.glb/.gltf), replacing the scene's.
        #[arg(long)]
        mesh: Option<PathBuf>,
        /// Millimetres per mesh unit (e.g. 50.3 for the Lee Perry-Smith scan).
        #[arg(long)]
        mm_per_unit: Option<f32>,
        /// Environment: a .hdr/.exr file, `sky[:elevation=..,azimuth=..,turbidity=..]`
        /// or `uniform:R,G,B`.
        #[arg(long)]
        env: Option<String>,
        /// Environment rotation about +Y, degrees.
        #[arg(long, allow_hyphen_values = true)]
        env_rotate: Option<f32>,
        /// Bright sources taken out of the environment as shadowed directional
        /// lights, replacing the scene's `environment.lights`: `auto` (compact
        /// sources holding ≥ 5 % of the energy) or a count 0..=8 (0: none).
        #[arg(long, value_name = "auto|N", allow_hyphen_values = true)]
        env_lights: Option<LightsMode>,
        /// Exposure in EV stops, replacing `render.exposure`; without either it is
        /// metered from the frame (the skin's log-average luminance to 0.18).
        #[arg(long, allow_hyphen_values = true)]
        exposure: Option<f32>,
        /// Tone curve, replacing `render.tone_curve`: `linear` (clip), `aces`
        /// (Narkowicz's ACES fit) or `neutral` (Khronos PBR Neutral).
        #[arg(long, value_enum)]
        tone_curve: Option<ToneCurve>,
        /// Glow (d'Eon & Luebke's two-Gaussian bloom), replacing `render.glow`.
        #[arg(long, value_name = "on|off", hide_possible_values = true, value_parser = clap::builder::BoolishValueParser::new())]
        glow: Option<bool>,
        /// Glow intensity (≥ 0), replacing `render.glow_intensity`.
        #[arg(long, allow_hyphen_values = true)]
        glow_intensity: Option<f32>,
        /// Draw the environment behind the head, replacing `render.skybox`.
        #[arg(long, value_name = "on|off", hide_possible_values = true, value_parser = clap::builder::BoolishValueParser::new())]
        skybox: Option<bool>,
        /// Display colour (linear, each in [0, 1]) where the skybox is off and
        /// the mesh does not cover, replacing `render.background`.
        #[arg(long, value_name = "R,G,B", value_parser = parse_rgb)]
        background: Option<[f32; 3]>,
        /// Scale on the profile's six variances (the paper's blurring width; 0:
        /// no blur), replacing `skin.blur_width`.
        #[arg(long, allow_hyphen_values = true)]
        blur_width: Option<f32>,
        /// Share of the blurred irradiance in the diffuse term, 0..1 (the
        /// paper's blurring amount; 0: unblurred), replacing `skin.blur_amount`.
        #[arg(long, allow_hyphen_values = true)]
        blur_amount: Option<f32>,
        /// The numbered UV checker as the albedo, replacing `textures.test_texture`.
        #[arg(long, value_name = "on|off", hide_possible_values = true, value_parser = clap::builder::BoolishValueParser::new())]
        test_texture: Option<bool>,
        /// Side of the UV-space irradiance texture (power of two, 256..8192).
        #[arg(long)]
        irradiance_res: Option<u32>,
        /// Per-vertex occlusion (default: the scene's, raytrace).
        #[arg(long, value_enum)]
        occlusion: Option<Occlusion>,
        /// Blur kernel of the diffusion chain, replacing the scene's `skin.kernel`.
        #[arg(long, value_enum)]
        kernel: Option<Kernel>,
        /// Resolutions of the diffusion chain, replacing the scene's `skin.chain`:
        /// `full` blurs every level at the irradiance resolution, `adaptive` each at
        /// the coarsest resolution its Gaussian allows.
        #[arg(long, value_enum)]
        chain: Option<Chain>,
        /// The maps' UV origin, replacing the scene's (bottom-left: flipped on load).
        #[arg(long, value_enum)]
        uv_origin: Option<UvOrigin>,
        /// Output width in pixels, replacing the scene's.
        #[arg(long)]
        width: Option<u32>,
        /// Output height in pixels, replacing the scene's.
        #[arg(long)]
        height: Option<u32>,
        /// What to write: a view with shading of its own (final, diffuse,
        /// specular, direct, reference, occlusion, depth, normals, albedo,
        /// regions, test-texture) or any image of the frame graph by name, as
        /// stored (irradiance, stretch, stretch1…5, blur1…6, prefiltered, …).
        /// `--view list` prints every view of the scene and exits.
        #[arg(long, default_value = "final", value_name = "VIEW|list")]
        view: View,
        /// Also write the debug sheet (PNG): the stretch and blur levels (the
        /// paper's Fig. 3), depth, occlusion and specular, labelled.
        #[arg(long, value_name = "FILE.png")]
        debug_sheet: Option<PathBuf>,
        /// Also write --view with occlusion on and off side by side (PNG, one
        /// exposure; the paper's Figs. 6–8).
        #[arg(long, value_name = "FILE.png")]
        compare_occlusion: Option<PathBuf>,
        /// Frames to render per run (≥ 1); with more than one the first is warm-up.
        #[arg(long, default_value_t = 1)]
        frames: u32,
        /// Warm-up frames per run, outside the statistics (default: 1 when
        /// --frames is more than 1, else 0).
        #[arg(long)]
        warmup: Option<u32>,
        /// Independent repetitions, each with a fresh upload, pipelines and
        /// warm-up, so that `dermis compare` has runs, not only frames of one
        /// pipeline state; the image is the last run's.
        #[arg(long, default_value_t = 1)]
        runs: u32,
        /// Print the per-pass GPU time table (median, min, max, p90 of measured frames).
        #[arg(long)]
        timings: bool,
        /// Write the run report (setup, version, device, per-pass statistics, every
        /// frame's pass times and starts, memory) as JSON.
        #[arg(long)]
        report: Option<PathBuf>,
        /// Write the frames and passes as a Chrome trace (Perfetto, chrome://tracing).
        #[arg(long)]
        trace: Option<PathBuf>,
        /// Write one CSV row per pass per frame, with the run's setup in each row.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Print the compiled render graph (passes, barriers, lifetimes).
        #[arg(long)]
        dump_graph: bool,
        /// Also time two ruler passes at the irradiance resolution (an RGBA16F copy,
        /// `ruler_copy`, and a read, `ruler_read`) and report every pass's ns/texel
        /// as a multiple of the copy's (docs/performance.md).
        #[arg(long)]
        ruler: bool,
    },
}

/// How `compare` and `interleave` decide and what they write.
#[derive(clap::Args)]
struct DecideArgs {
    /// What each pass's time is compared in: `ruler` (over the ruler pass of
    /// its frame or run: a busier machine cancels), `ms`, or `auto` (ruler units
    /// where they scatter less between samples than ms).
    #[arg(long, value_enum, default_value = "auto")]
    unit: compare::Unit,
    /// Relative change below which a pass is not reported changed (0.06 = 6 %:
    /// the A/A noise measured in docs/performance.md).
    #[arg(long, default_value_t = compare::DEFAULT_NOISE_THRESHOLD)]
    noise_threshold: f64,
    /// Family-wise significance level (Holm-corrected over the passes).
    #[arg(long, default_value_t = compare::DEFAULT_SIGNIFICANCE)]
    significance: f64,
    /// Compare even where the work differs (scene, mesh, view, sizes).
    #[arg(long)]
    allow_setup_change: bool,
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

#[derive(clap::Args)]
struct SweepArgs {
    #[command(subcommand)]
    command: Option<SweepCommand>,
    /// Scene file, or `builtin`; default: assets/default.toml. Its skybox is
    /// turned off: the face mask is the image's alpha.
    #[arg(long)]
    scene: Option<PathBuf>,
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
    /// Irradiance resolution of the reference (accurate kernel, full chain).
    #[arg(long, default_value_t = 4096)]
    reference_resolution: u32,
    /// Output width in pixels, replacing the scene's.
    #[arg(long)]
    width: Option<u32>,
    /// Output height in pixels, replacing the scene's.
    #[arg(long)]
    height: Option<u32>,
    /// Directory for the CSV, JSON and plots (created).
    #[arg(long, default_value = "sweep")]
    out_dir: PathBuf,
    /// Render nothing: redraw the plots and CSV of --out-dir from its sweep.json.
    #[arg(long)]
    replot: bool,
    /// Render only this shard of the points: I/N (1-based; same as hash:I/N, by a
    /// hash of each point's id, stable as points are added), count:I/N (every
    /// N-th point from the I-th: balanced), or auto (from Slurm, Kubernetes,
    /// GitLab, Bazel or DERMIS_SHARD; see docs/performance.md). Without it,
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
    Merge {
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
    },
}

/// `--background R,G,B`.
fn parse_rgb(s: &str) -> Result<[f32; 3], String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|c| c.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{s:?}: {e}"))?;
    v.try_into()
        .map_err(|_| format!("{s:?}: expected three numbers R,G,B"))
}

fn to_json(path: &Path, value: &impl serde::Serialize) -> dermis::Result<String> {
    serde_json::to_string_pretty(value)
        .map_err(|e| dermis::Error::Input(format!("{}: {e}", path.display())))
}

/// Whole or not at all: a temporary file renamed into place.
fn write_file(path: &Path, text: &str) -> dermis::Result<()> {
    dermis::atomic::write_atomic(path, text)
}

/// `dermis sweep` and `dermis sweep merge`.
fn sweep(args: SweepArgs, context: &ContextOptions) -> dermis::Result<()> {
    use dermis::sweep::{self as sw, output};
    if let Some(SweepCommand::Merge {
        inputs,
        out_dir,
        allow_reference_mismatch,
    }) = args.command
    {
        let merged = sw::merge::merge(
            &inputs,
            sw::merge::MergeOptions {
                allow_reference_mismatch,
            },
        )?;
        for w in &merged.warnings {
            eprintln!("warning: {w}");
        }
        let out_dir = out_dir.unwrap_or_else(|| sw::merge::default_out_dir(&inputs));
        output::write_all(&merged.sweep, &out_dir)?;
        println!(
            "merged {} points from {} run(s) into {}",
            merged.sweep.points.len(),
            merged.sweep.shards.len(),
            out_dir.display()
        );
        return Ok(());
    }
    let out_dir = args.out_dir;
    if args.replot {
        let sweep = sw::load(&out_dir.join("sweep.json"))?;
        output::write_csv_and_plots(&sweep, &out_dir)?;
        println!("redrew {}", out_dir.display());
        return Ok(());
    }
    let file = Overrides {
        width: args.width,
        height: args.height,
        ..Overrides::default()
    }
    .apply(scene_by_name(args.scene.as_deref())?)?;
    let opts = sw::SweepOptions {
        scene: file,
        scene_label: args
            .scene
            .unwrap_or_else(default_scene_path)
            .display()
            .to_string(),
        resolutions: args.resolutions,
        kernels: args.kernels,
        chains: args.chains,
        frames: args.frames,
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
        let list = sw::points::list(&opts, shard);
        if args.json {
            println!("{}", to_json(Path::new("stdout"), &list)?);
        } else {
            for p in &list.points {
                println!("{}", p.id);
            }
            println!(
                "sweep hash {} ({} points)",
                list.sweep_hash,
                list.points.len()
            );
        }
        return Ok(());
    }
    if let Some(r) = &resolved {
        sw::shard::acknowledge(r)?;
    }
    std::fs::create_dir_all(&out_dir).map_err(|source| dermis::Error::Io {
        path: out_dir.display().to_string(),
        source,
    })?;
    let log = out_dir.join(shard.map_or_else(|| "points.jsonl".into(), |s| s.file_name()));
    let ctx = Context::new(context)?;
    println!("{}", sw::TABLE_HEADER);
    let how = sw::RunOptions {
        shard,
        log: Some(log.clone()),
        resume: args.resume,
    };
    let sweep = sw::run(&ctx, &opts, &how, |p| println!("{}", sw::table_row(p)))?;
    if shard.is_some() {
        println!(
            "wrote {} ({} points); merge the shards with `dermis sweep merge`",
            log.display(),
            sweep.points.len()
        );
    } else {
        output::write_all(&sweep, &out_dir)?;
        println!("wrote {}", out_dir.display());
    }
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let level = match cli.verbose {
        0 => "warn",
        1 => "info",
        _ => "debug",
    };
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or(level)).init();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code() as u8)
        }
    }
}

fn run(cli: Cli) -> dermis::Result<ExitCode> {
    let mut context = ContextOptions::from_env();
    context.validation |= cli.validation;
    context.device = cli.device.or(context.device);
    match cli.command {
        Command::Info { json } => {
            let ctx = Context::new(&context)?;
            let info = &ctx.info;
            if json {
                println!("{}", serde_json::to_string_pretty(info).unwrap_or_default());
            } else {
                println!("device:            {} ({})", info.name, info.device_type);
                println!(
                    "driver:            {} {}",
                    info.driver_name, info.driver_info
                );
                println!("Vulkan:            {}", info.api_version);
                println!(
                    "timestamps:        {} (period {} ns, {} valid bits)",
                    if info.timestamps { "yes" } else { "no" },
                    info.timestamp_period_ns,
                    info.timestamp_valid_bits
                );
                println!("max image size:    {}", info.max_image_dimension_2d);
                for (i, h) in info.memory_heaps.iter().enumerate() {
                    println!(
                        "memory heap {i}:     {:.1} GiB{}",
                        h.size_bytes as f64 / (1u64 << 30) as f64,
                        if h.device_local {
                            " (device local)"
                        } else {
                            ""
                        }
                    );
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Precompute {
            scene,
            mesh,
            mm_per_unit,
            occlusion,
        } => {
            let file = scene_by_name(scene.as_deref())?;
            let file = Overrides {
                mesh,
                mm_per_unit,
                occlusion,
                ..Overrides::default()
            }
            .apply(file)?;
            let mesh = dermis::scene::load_mesh(&file)?;
            let ctx = Context::new(&context)?;
            let started = std::time::Instant::now();
            let t = dermis::light::occlusion::transfer_for(&ctx, &mesh, file.skin.occlusion)?;
            let secs = started.elapsed().as_secs_f64();
            println!(
                "{} vertices, occlusion {:?}: {:.2} s ({:.1} µs per vertex), cache {}",
                t.coeffs.len(),
                file.skin.occlusion,
                secs,
                secs * 1e6 / t.coeffs.len().max(1) as f64,
                dermis::light::occlusion::default_cache_dir().display()
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::Sh {
            env,
            rotate,
            json,
            timings,
        } => {
            let (w, h) = dermis::scene::PROCEDURAL_ENV_SIZE;
            let source: dermis::scene::env::EnvSource = env.parse()?;
            let (map, _) = dermis::scene::env::resolve(&source, w, h)?;
            let ctx = Context::new(&context)?;
            let (coeffs, report) = dermis::light::sh_pass::project(&ctx, &map, rotate, 1.0)?;
            let names = [
                "L00", "L1-1", "L10", "L11", "L2-2", "L2-1", "L20", "L21", "L22",
            ];
            if json {
                let obj: serde_json::Map<String, serde_json::Value> = names
                    .iter()
                    .zip(&coeffs)
                    .map(|(n, c)| (n.to_string(), serde_json::json!([c.x, c.y, c.z])))
                    .collect();
                let out = serde_json::json!({ "environment": env, "rotation_deg": rotate, "order": names, "coefficients": obj });
                println!("{}", serde_json::to_string_pretty(&out).unwrap_or_default());
            } else {
                for (n, c) in names.iter().zip(&coeffs) {
                    println!("{n:<5} {:>14.6} {:>14.6} {:>14.6}", c.x, c.y, c.z);
                }
            }
            if timings {
                eprint!("{}", report.table());
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Lights {
            env,
            rotate,
            lights,
            json,
        } => {
            let (w, h) = dermis::scene::PROCEDURAL_ENV_SIZE;
            let source: dermis::scene::env::EnvSource = env.parse()?;
            let (map, _) = dermis::scene::env::resolve(&source, w, h)?;
            let found = extract::extract(&map, lights).lights;
            let residual = 1.0 - found.iter().map(|l| l.share).sum::<f32>();
            let rows: Vec<_> = found
                .iter()
                .map(|l| {
                    let d = l.world_direction(rotate);
                    let (elevation, azimuth) = extract::elevation_azimuth_deg(d);
                    (l, d, elevation, azimuth)
                })
                .collect();
            if json {
                let lights_json: Vec<_> = rows
                    .iter()
                    .map(|(l, d, elevation, azimuth)| {
                        serde_json::json!({
                            "direction": [d.x, d.y, d.z],
                            "elevation_deg": elevation,
                            "azimuth_deg": azimuth,
                            "solid_angle_sr": l.solid_angle_sr,
                            "angular_radius_deg": l.angular_radius_rad.to_degrees(),
                            "power": [l.power.x, l.power.y, l.power.z],
                            "share": l.share,
                            "texels": l.texels,
                        })
                    })
                    .collect();
                let out = serde_json::json!({
                    "environment": env,
                    "rotation_deg": rotate,
                    "mode": lights,
                    "lights": lights_json,
                    "residual_share": residual,
                });
                println!("{}", serde_json::to_string_pretty(&out).unwrap_or_default());
            } else {
                println!(
                    "{env}, rotated {rotate}°, lights {lights}: {} found",
                    rows.len()
                );
                if !rows.is_empty() {
                    println!(
                        "{:>2} {:>9} {:>8}  {:<24}  {:>11} {:>7}  {:<30}  {:>7}",
                        "#",
                        "elevation",
                        "azimuth",
                        "direction (world)",
                        "solid angle",
                        "radius",
                        "power (R, G, B)",
                        "share"
                    );
                }
                for (i, (l, d, elevation, azimuth)) in rows.iter().enumerate() {
                    println!(
                        "{:>2} {:>8.2}° {:>7.2}°  ({:>6.3}, {:>6.3}, {:>6.3})  {:>8.5} sr {:>6.2}°  \
                         ({:>8.4}, {:>8.4}, {:>8.4})  {:>5.1} %",
                        i + 1,
                        elevation,
                        azimuth,
                        d.x,
                        d.y,
                        d.z,
                        l.solid_angle_sr,
                        l.angular_radius_rad.to_degrees(),
                        l.power.x,
                        l.power.y,
                        l.power.z,
                        100.0 * l.share
                    );
                }
                println!("residual: {:.1} % of the energy", 100.0 * residual);
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Sweep(args) => sweep(args, &context).map(|()| ExitCode::SUCCESS),
        Command::Reference {
            scene,
            envs,
            width,
            height,
            target_error,
            out_dir,
            json,
        } => {
            let file = scene_by_name(scene.as_deref())?;
            let environments = if envs.is_empty() {
                vec![file.environment.source.clone()]
            } else {
                envs.iter()
                    .map(|e| e.parse())
                    .collect::<Result<Vec<_>, _>>()?
            };
            if !(target_error > 0.0 && target_error < 1.0) {
                return Err(dermis::Error::Input(format!(
                    "--target-error {target_error}: must be in (0, 1)"
                )));
            }
            let opts = dermis::sweep::lighting::LightingOptions {
                scene: file,
                environments,
                width,
                height,
                settings: dermis::light::reference::Settings {
                    target_rel_err: target_error,
                    ..Default::default()
                },
                out_dir,
            };
            let ctx = Context::new(&context)?;
            let rows = dermis::sweep::lighting::run(&ctx, &opts, |r| {
                if !json {
                    eprintln!(
                        "{}: {} light(s) extracted; mean error {:.1} % → {:.1} % (reference {:.0} s)",
                        r.environment,
                        r.extracted,
                        100.0 * r.sh9.mean,
                        100.0 * r.sh9_lights.mean,
                        r.reference_seconds
                    );
                }
            })?;
            if json {
                println!("{}", to_json(Path::new("stdout"), &rows)?);
            } else {
                print!("{}", dermis::sweep::lighting::table(&rows));
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::View {
            scene,
            env,
            irradiance_res,
            width,
            height,
            frames,
            screenshot,
        } => {
            if frames == Some(0) {
                return Err(dermis::Error::Input("--frames 0: give 1 or more".into()));
            }
            let overrides = Overrides {
                env,
                irradiance_resolution: irradiance_res,
                width,
                height,
                ..Overrides::default()
            };
            let file = overrides.apply(scene_by_name(scene.as_deref())?)?;
            dermis::viewer::run(dermis::viewer::ViewerOptions {
                scene: file,
                scene_path: scene,
                overrides,
                context,
                frames,
                screenshot,
            })?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Compare { base, new, decide } => {
            match (compare_input::load(&base)?, compare_input::load(&new)?) {
                (compare_input::Side::Runs(base, w1), compare_input::Side::Runs(new, w2)) => {
                    report_comparison(&[(String::new(), *base, *new)], &decide, [w1, w2].concat())
                }
                (compare_input::Side::Sweep(base), compare_input::Side::Sweep(mut new)) => {
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
                    report_comparison(&pairs, &decide, warnings)
                }
                _ => Err(dermis::Error::Input(
                    "compare: give two reports (or folders of them) or two sweeps, not one of each"
                        .into(),
                )),
            }
        }
        Command::Interleave {
            runs,
            frames,
            base_bin,
            new_bin,
            base_args,
            new_args,
            out_dir,
            decide,
        } => {
            let me = std::env::current_exe().map_err(|source| dermis::Error::Io {
                path: "the running dermis binary".into(),
                source,
            })?;
            let sides = [
                ("base", base_bin.unwrap_or_else(|| me.clone()), base_args),
                ("new", new_bin.unwrap_or(me), new_args),
            ];
            let [base, new] = dermis::sweep::interleave::run(&sides, runs, frames, &out_dir)?;
            report_comparison(
                &[(String::new(), base.0, new.0)],
                &decide,
                [base.1, new.1].concat(),
            )
        }
        Command::Export {
            report,
            github_benchmark,
            bencher,
        } => {
            if github_benchmark.is_none() && bencher.is_none() {
                return Err(dermis::Error::Input(
                    "export: give --github-benchmark FILE or --bencher FILE".into(),
                ));
            }
            let text = read_text(&report)?;
            let r: dermis::profile::RunReport = serde_json::from_str(&text).map_err(|e| {
                dermis::Error::Input(format!(
                    "{}: not a dermis run report: {e}",
                    report.display()
                ))
            })?;
            if let Some(path) = github_benchmark {
                let v = dermis::profile::export::github_benchmark(&r);
                write_file(&path, &to_json(&path, &v)?)?;
            }
            if let Some(path) = bencher {
                write_file(
                    &path,
                    &to_json(&path, &dermis::profile::export::bencher(&r))?,
                )?;
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::ReportSchema => {
            let schema = schemars::schema_for!(dermis::profile::RunReport);
            println!("{}", to_json(Path::new("stdout"), &schema)?);
            Ok(ExitCode::SUCCESS)
        }
        Command::Render {
            scene,
            out,
            mesh,
            mm_per_unit,
            env,
            env_rotate,
            env_lights,
            exposure,
            tone_curve,
            glow,
            glow_intensity,
            skybox,
            background,
            blur_width,
            blur_amount,
            test_texture,
            irradiance_res,
            occlusion,
            kernel,
            chain,
            uv_origin,
            width,
            height,
            view,
            debug_sheet: sheet,
            compare_occlusion: comparison,
            frames,
            warmup,
            runs,
            timings,
            report,
            trace,
            csv,
            dump_graph,
            ruler,
        } => {
            let file = scene_by_name(scene.as_deref())?;
            let overrides = Overrides {
                mesh,
                mm_per_unit,
                env,
                env_rotate_deg: env_rotate,
                env_lights,
                exposure,
                irradiance_resolution: irradiance_res,
                occlusion,
                kernel,
                chain,
                uv_origin,
                width,
                height,
                blur_width,
                blur_amount,
                test_texture,
                tone_curve,
                skybox,
                background,
                glow,
                glow_intensity,
            };
            let hdr = Format::of(&out)? == Format::Exr;
            for path in [&sheet, &comparison].into_iter().flatten() {
                Format::of(path)?;
            }
            let opts = RenderOptions {
                frames,
                hdr,
                view,
                scene_path: Some(scene.unwrap_or_else(default_scene_path)),
                progress: std::io::stderr().is_terminal(),
                ruler,
                runs,
                warmup,
            };
            opts.warmup_frames()?;
            let file = overrides.apply(file)?;
            let loaded = Scene::load(file)?;
            let ctx = Context::new(&context)?;
            if opts.view.name() == "list" {
                for name in dermis::render::views(&ctx, &loaded)? {
                    println!("{name}");
                }
                return Ok(ExitCode::SUCCESS);
            }
            let output = render_scene(&ctx, &loaded, &opts)?;
            if dump_graph {
                print!("{}", output.plan);
            }
            dermis::render::output::write(&out, &output)?;
            if let Some(r) = &output.reference {
                eprintln!(
                    "reference: {} mesh pixels, {:.1} % converged to 0.5 %, mean standard error \
                     {:.2} %, {:.0} directions per pixel, {:.1} s",
                    r.mesh_pixels,
                    100.0 * r.converged,
                    100.0 * r.mean_rel_std_err,
                    r.samples as f64 / f64::from(r.mesh_pixels.max(1)),
                    r.seconds
                );
            }
            let r = &output.report;
            if let Some(w) = r.cold_warning().filter(|_| timings || report.is_some()) {
                eprintln!("{w}");
            }
            if timings {
                print!("{}{}", r.header(), r.table());
            }
            if let Some(path) = report {
                write_file(&path, &to_json(&path, r)?)?;
            }
            if let Some(path) = trace {
                write_file(&path, &to_json(&path, &dermis::profile::trace::trace(r))?)?;
            }
            if let Some(path) = csv {
                write_file(&path, &dermis::profile::csv::csv(r))?;
            }
            println!(
                "wrote {} (exposure {:+.2} EV, {})",
                out.display(),
                output.exposure,
                if output.metered.is_some() {
                    "metered"
                } else {
                    "given"
                }
            );
            if let Some(path) = sheet {
                write_sheet(&path, &debug_sheet(&ctx, &loaded, &opts)?)?;
                println!("wrote {}", path.display());
            }
            if let Some(path) = comparison {
                write_sheet(&path, &compare_occlusion(&ctx, &loaded, &opts)?)?;
                println!("wrote {}", path.display());
            }
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn read_text(path: &Path) -> dermis::Result<String> {
    std::fs::read_to_string(path).map_err(|source| dermis::Error::Io {
        path: path.display().to_string(),
        source,
    })
}

/// Compares each pair (a sweep's points by id; a report's one pair with no
/// label), prints the tables (or JSON), writes the JUnit file; status 3 on a
/// regression when asked.
fn report_comparison(
    pairs: &[(String, Measurement, Measurement)],
    decide: &DecideArgs,
    warnings: Vec<String>,
) -> dermis::Result<ExitCode> {
    let opts = compare::CompareOptions {
        unit: decide.unit,
        noise_threshold: decide.noise_threshold,
        significance: decide.significance,
        allow_setup_change: decide.allow_setup_change,
    };
    if pairs.is_empty() {
        return Err(dermis::Error::Input(format!(
            "compare: nothing in common to compare ({})",
            warnings.join("; ")
        )));
    }
    let mut results: Vec<(String, Comparison)> = Vec::new();
    for (label, base, new) in pairs {
        results.push((label.clone(), compare::compare(base, new, &opts)?));
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
        println!("{}", to_json(Path::new("stdout"), &value)?);
    } else {
        if !single {
            for w in &warnings {
                println!("warning: {w}");
            }
        }
        for (label, c) in &results {
            if !label.is_empty() {
                println!("\n== point {label}");
            }
            print!("{}", compare::table(c));
        }
    }
    let comparisons: Vec<&Comparison> = results.iter().map(|(_, c)| c).collect();
    if let Some(path) = &decide.junit {
        write_file(path, &dermis::profile::export::junit(&comparisons))?;
    }
    let regressed = comparisons.iter().any(|c| c.regressed());
    Ok(if decide.fail_on_regression && regressed {
        ExitCode::from(3)
    } else {
        ExitCode::SUCCESS
    })
}
