//! `dermis render` and `dermis precompute`.

use std::io::IsTerminal;
use std::path::PathBuf;

use clap::Args;
use dermis::gpu::{Context, ContextOptions};
use dermis::render::output::{write_sheet, Format};
use dermis::render::{compare_occlusion, debug_sheet, render_scene, RenderOptions, View};
use dermis::scene::{Overrides, Scene, SceneArg};

use super::{check_distinct, check_output, to_json, write_file};

#[derive(Args)]
pub struct RenderArgs {
    #[command(flatten)]
    scene: SceneArg,
    /// Output image: .png (8-bit sRGB) or .exr (linear float).
    #[arg(long, default_value = "dermis.png")]
    out: PathBuf,
    #[command(flatten)]
    overrides: Overrides,
    /// What to write: a view with shading of its own (final, diffuse,
    /// specular, direct, reference, occlusion, depth, normals, albedo,
    /// regions, test-texture) or any image of the frame graph by name, as
    /// stored (irradiance, stretch, stretch1…stretch5, blur1…blur6,
    /// prefiltered, …).
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
    /// Pre-roll: after each run's first frame, render unreported frames for this
    /// many milliseconds, so that a GPU's clocks are up before the measured
    /// frames (default: 1000 on GPUs, 0 on CPU devices such as lavapipe).
    #[arg(long, value_name = "MS")]
    warmup_ms: Option<u32>,
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
    /// Also time three ruler passes at the irradiance resolution (an RGBA16F
    /// copy, `ruler_copy`, a read, `ruler_read`, and one workgroup of the read,
    /// `ruler_empty`) and report every pass's ns/texel
    /// as a multiple of the copy's (docs/guide/measure.md).
    #[arg(long)]
    ruler: bool,
    /// Count every pass's work with pipeline statistics queries (vertices,
    /// primitives, vertex, fragment and compute invocations) into the timing
    /// table, report, CSV and trace; needs the device's
    /// pipelineStatisticsQuery feature (docs/design/pass-analysis.md, "Work counters").
    #[arg(long)]
    counters: bool,
    /// After the measured runs, run the frame once more with every shader
    /// that has the variant skipping its work (one read and its output kept):
    /// each such pass's time there as a share of its time, and the bound-by
    /// verdict from it (docs/design/pass-analysis.md, "Controlled variants").
    #[arg(long)]
    variants: bool,
}

#[derive(Args)]
pub struct PrecomputeArgs {
    #[command(flatten)]
    scene: SceneArg,
    #[command(flatten)]
    overrides: Overrides,
}

/// `dermis render`.
pub fn render(args: RenderArgs, context: &ContextOptions) -> dermis::Result<()> {
    check_output("--out", &args.out, &["png", "exr"])?;
    for (flag, path, exts) in [
        ("--debug-sheet", &args.debug_sheet, &["png"][..]),
        ("--compare-occlusion", &args.compare_occlusion, &["png"]),
        ("--report", &args.report, &["json"]),
        ("--trace", &args.trace, &["json"]),
        ("--csv", &args.csv, &["csv"]),
    ] {
        if let Some(path) = path {
            check_output(flag, path, exts)?;
        }
    }
    check_distinct(&[
        ("--out", Some(&args.out)),
        ("--debug-sheet", args.debug_sheet.as_deref()),
        ("--compare-occlusion", args.compare_occlusion.as_deref()),
        ("--report", args.report.as_deref()),
        ("--trace", args.trace.as_deref()),
        ("--csv", args.csv.as_deref()),
    ])?;
    let file = args.scene.file()?;
    let hdr = Format::of(&args.out)? == Format::Exr;
    let opts = RenderOptions {
        frames: args.frames,
        hdr,
        view: args.view,
        scene_path: Some(args.scene.path()?),
        progress: std::io::stderr().is_terminal(),
        ruler: args.ruler,
        counters: args.counters,
        runs: args.runs,
        warmup: args.warmup,
        warmup_ms: args.warmup_ms,
        variants: args.variants,
    };
    opts.warmup_frames()?;
    let loaded = dermis::skin::with_medium_albedo(Scene::load(args.overrides.apply(file)?)?);
    let ctx = Context::new(context)?;
    if opts.view.name() == "list" {
        for name in dermis::render::views(&ctx, &loaded)? {
            outln!("{name}");
        }
        return Ok(());
    }
    let output = render_scene(&ctx, &loaded, &opts)?;
    if args.dump_graph {
        out!("{}", output.plan);
    }
    dermis::render::output::write(&args.out, &output)?;
    for w in dermis::render::output::warnings(&output) {
        eprintln!("warning: {w}");
    }
    if let Some(r) = &output.reference {
        eprintln!(
            "{}reference: {} mesh pixels, {:.1} % converged to 0.5 %, mean standard error \
             {:.2} %, {:.0} directions per pixel, {:.1} s",
            if r.converged < 1.0 {
                "warning: not every pixel converged (sample cap reached); "
            } else {
                ""
            },
            r.mesh_pixels,
            100.0 * r.converged,
            100.0 * r.mean_rel_std_err,
            r.samples as f64 / f64::from(r.mesh_pixels.max(1)),
            r.seconds
        );
    }
    let r = &output.report;
    if let Some(w) = r
        .cold_warning()
        .filter(|_| args.timings || args.report.is_some())
    {
        eprintln!("{w}");
    }
    if args.timings {
        out!("{}{}", r.header(), r.table());
    }
    if let Some(path) = args.report {
        write_file(&path, &to_json(&path, r)?)?;
    }
    if let Some(path) = args.trace {
        write_file(&path, &to_json(&path, &dermis::timing::trace::trace(r))?)?;
    }
    if let Some(path) = args.csv {
        write_file(&path, &dermis::timing::csv::csv(r))?;
    }
    outln!(
        "wrote {} (exposure {:+.2} EV, {})",
        args.out.display(),
        output.exposure,
        match output.metered {
            Some(m) if m.pixels == 0 => "nothing covered to meter",
            Some(_) => "metered",
            None => "given",
        }
    );
    if let Some(path) = args.debug_sheet {
        write_sheet(&path, &debug_sheet(&ctx, &loaded, &opts)?)?;
        outln!("wrote {}", path.display());
    }
    if let Some(path) = args.compare_occlusion {
        write_sheet(&path, &compare_occlusion(&ctx, &loaded, &opts)?)?;
        outln!("wrote {}", path.display());
    }
    Ok(())
}

/// `dermis precompute`.
pub fn precompute(args: PrecomputeArgs, context: &ContextOptions) -> dermis::Result<()> {
    let file = args.scene.load(&args.overrides)?;
    let scene = dermis::skin::with_medium_albedo(dermis::scene::Scene::load(file)?);
    let (mesh, skin) = (&scene.mesh, &scene.file.skin);
    // The cache is the point: a folder that cannot hold it fails before the work.
    let cache = dermis::light::occlusion::default_cache_dir();
    std::fs::create_dir_all(&cache)
        .and_then(|()| dermis::atomic::probe(&cache.join("probe")))
        .map_err(|e| {
            dermis::Error::Input(format!(
                "precompute: cannot write the cache folder {} ({e}); set DERMIS_CACHE_DIR to \
                 a writable folder",
                cache.display()
            ))
        })?;
    let ctx = Context::new(context)?;
    let started = std::time::Instant::now();
    let t = dermis::light::occlusion::transfer_for(&ctx, mesh, skin.occlusion)?;
    let secs = started.elapsed().as_secs_f64();
    outln!(
        "{} vertices, occlusion {:?}: {:.2} s ({:.1} µs per vertex), cache {}",
        t.coeffs.len(),
        skin.occlusion,
        secs,
        secs * 1e6 / t.coeffs.len().max(1) as f64,
        dermis::light::occlusion::default_cache_dir().display()
    );
    let started = std::time::Instant::now();
    dermis::light::occlusion::lobe_visibility_for(mesh, skin.occlusion);
    outln!(
        "specular occlusion (lobe visibility): {:.2} s",
        started.elapsed().as_secs_f64()
    );
    if skin.interreflection {
        let started = std::time::Instant::now();
        dermis::light::interreflection::bounce_for(mesh, &scene.albedo, &t, skin.occlusion);
        outln!("interreflection: {:.2} s", started.elapsed().as_secs_f64());
    }
    let settings = dermis::skin::SkinSettings::resolve(skin, &scene.file.render)?;
    let started = std::time::Instant::now();
    dermis::light::transmission::transmitted_for(
        mesh,
        &t,
        skin.occlusion,
        &settings.falloff(),
        settings.transmission,
    );
    outln!(
        "environment transmission: {:.2} s",
        started.elapsed().as_secs_f64()
    );
    match dermis::light::occlusion::store_failures() {
        0 => Ok(()),
        n => Err(dermis::Error::Input(format!(
            "precompute: {n} of the transfers could not be cached in {} (warnings above)",
            cache.display()
        ))),
    }
}
