//! `dermis sweep`: time against quality. Renders the scene for every irradiance
//! resolution × blur kernel × diffusion chain, with the rulers, and compares the
//! final image and the diffuse term with a reference (by default 4096², accurate
//! kernel, full chain) over the face. Writes a CSV, a JSON and plots.

pub mod interleave;
pub mod log;
pub mod merge;
pub mod metric;
pub mod output;
pub mod plot;
pub mod points;
pub mod shard;
pub mod side;

use crate::error::{Error, Result};
use crate::gpu::Context;
use crate::render::progress::Task;
use crate::render::{render_scene, RenderOptions, View};
use crate::scene::file::{Chain, Kernel, SceneFile};
use crate::scene::Scene;
use crate::timing::csv::field;
use crate::timing::fingerprint::{run_id, timestamp};
use crate::timing::{Fingerprint, PassStats, RunReport, GIT_COMMIT, RULER_COPY, VERSION};
use metric::{compare, coverage_mask, ImageError};
use points::SWEEP_SCHEMA_VERSION;
use serde::{Deserialize, Serialize};
use shard::Shard;
use std::path::PathBuf;
use std::sync::Arc;

/// What to sweep.
#[derive(Clone, Debug)]
pub struct SweepOptions {
    /// The scene (its `render.skybox` is turned off: the face mask is the alpha).
    pub scene: SceneFile,
    /// Where it came from, for the outputs.
    pub scene_label: String,
    pub resolutions: Vec<u32>,
    pub kernels: Vec<Kernel>,
    pub chains: Vec<Chain>,
    /// Frames per point (the first is warm-up).
    pub frames: u32,
    /// Pre-roll per point (render::RenderOptions::warmup_ms).
    pub warmup_ms: Option<u32>,
    pub reference_resolution: u32,
}

/// The resolution, kernel and chain of one render.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Variant {
    pub resolution: u32,
    pub kernel: Kernel,
    pub chain: Chain,
}

/// One point of the sweep.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Point {
    /// `r1024-deon7-adaptive` ([`Variant::id`]); empty in sweeps written before ids.
    #[serde(default)]
    pub id: String,
    #[serde(flatten)]
    pub variant: Variant,
    /// Per pass over the measured frames, rulers included (with each measured
    /// frame's sample).
    pub passes: Vec<PassStats>,
    /// Sum of the pass medians without the rulers: the frame's cost.
    pub total_ms: f64,
    /// Sum of the diffusion chain's medians (blur and stretch passes).
    pub chain_ms: f64,
    /// The frame's GPU span (rulers included).
    pub frame_span: PassStats,
    pub transient_bytes: u64,
    pub final_error: ImageError,
    pub diffuse_error: ImageError,
}

/// Where a merged sweep's points came from: one run (a shard, or a resumed
/// part of one) of `sweep merge`'s inputs.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ShardRun {
    pub file: String,
    /// `hash:2/3`, or `all` for an unsharded run.
    pub shard: String,
    pub run_id: String,
    pub timestamp: String,
    pub fingerprint: Fingerprint,
    pub reference_checksum: String,
    /// Ids of the points taken from this run (after de-duplication).
    pub points: Vec<String>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Sweep {
    /// [`SWEEP_SCHEMA_VERSION`]; 0 in sweeps written before it.
    #[serde(default)]
    pub schema_version: u32,
    /// [`points::sweep_hash`]: equal hashes, comparable points.
    #[serde(default)]
    pub sweep_hash: String,
    /// This run's (or, merged, the merge's) id and UTC start time.
    #[serde(default)]
    pub run_id: String,
    #[serde(default)]
    pub timestamp: String,
    pub dermis_version: String,
    pub git_commit: String,
    pub device: String,
    pub driver: String,
    /// Merged: the first input's (differences are warned about).
    #[serde(default)]
    pub fingerprint: Fingerprint,
    pub scene: String,
    /// The scene's environment source.
    #[serde(default)]
    pub environment: String,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub reference: Variant,
    /// FNV-1a 64 of the reference's final and diffuse HDR images (f32 bytes).
    #[serde(default)]
    pub reference_checksum: String,
    pub points: Vec<Point>,
    /// Merged sweeps: the runs the points came from.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub shards: Vec<ShardRun>,
}

/// Checks the options before anything renders.
pub fn validate(opts: &SweepOptions) -> Result<()> {
    let res_ok = |r: u32| r.is_power_of_two() && (256..=8192).contains(&r);
    for &r in opts.resolutions.iter().chain([&opts.reference_resolution]) {
        if !res_ok(r) {
            return Err(Error::Input(format!(
                "sweep: irradiance resolution {r} is not a power of two in 256..=8192"
            )));
        }
    }
    if opts.resolutions.is_empty() || opts.kernels.is_empty() || opts.chains.is_empty() {
        return Err(Error::Input(
            "sweep: give at least one resolution, kernel and chain".into(),
        ));
    }
    if opts.frames < 2 {
        return Err(Error::Input(
            "sweep: --frames must be at least 2 (the first is warm-up)".into(),
        ));
    }
    Ok(())
}

/// The linear HDR image of `view` for `variant`, and the run report
/// (`frames`, and the pre-roll as render::RenderOptions::warmup_ms).
fn render(
    ctx: &Arc<Context>,
    scene: &mut Scene,
    variant: Variant,
    view: View,
    (frames, warmup_ms): (u32, Option<u32>),
) -> Result<(Vec<f32>, RunReport)> {
    scene.file.render.irradiance_resolution = variant.resolution;
    scene.file.skin.kernel = variant.kernel;
    scene.file.skin.chain = variant.chain;
    let out = render_scene(
        ctx,
        scene,
        &RenderOptions {
            frames,
            warmup_ms,
            hdr: true,
            ruler: view == View::FINAL,
            view,
            ..RenderOptions::default()
        },
    )?;
    let hdr = out
        .hdr
        .ok_or_else(|| Error::Input("sweep: the render returned no HDR image".into()))?;
    Ok((hdr, out.report))
}

/// FNV-1a 64 over the reference's final then diffuse image, as f32 bytes in
/// memory order (little-endian on every platform dermis runs on).
pub fn reference_checksum(final_image: &[f32], diffuse: &[f32]) -> String {
    crate::cache::hex(crate::cache::fnv1a64_parts([
        bytemuck::cast_slice::<f32, u8>(final_image),
        bytemuck::cast_slice::<f32, u8>(diffuse),
    ]))
}

/// The scene loaded once, the reference rendered: renders points against it.
pub struct Session<'a> {
    ctx: &'a Arc<Context>,
    opts: &'a SweepOptions,
    scene: Scene,
    ref_final: Vec<f32>,
    ref_diffuse: Vec<f32>,
    mask: Vec<bool>,
    pub reference: Variant,
    pub reference_checksum: String,
    /// The reference render's clock ("gpu-timestamp", "host-fence").
    pub clock: String,
}

impl<'a> Session<'a> {
    /// Loads the scene (skybox off) and renders the reference. Rendering is
    /// deterministic on one device and driver, so every shard renders its own.
    pub fn new(ctx: &'a Arc<Context>, opts: &'a SweepOptions) -> Result<Self> {
        validate(opts)?;
        let mut file = opts.scene.clone();
        file.render.skybox = false;
        let mut scene = crate::skin::with_medium_albedo(Scene::load(file)?);
        let reference = points::reference(opts);
        let task = Task::new(
            &format!("sweep: reference {} (2 renders)", reference.id()),
            2,
        );
        let (ref_final, report) = render(ctx, &mut scene, reference, View::FINAL, (1, None))?;
        task.add(1);
        let (ref_diffuse, _) = render(
            ctx,
            &mut scene,
            reference,
            View::named("diffuse"),
            (1, None),
        )?;
        drop(task);
        Ok(Self {
            ctx,
            opts,
            mask: coverage_mask(&ref_final),
            reference_checksum: reference_checksum(&ref_final, &ref_diffuse),
            ref_final,
            ref_diffuse,
            scene,
            reference,
            clock: report.fingerprint.clock,
        })
    }

    /// Renders and measures one point.
    pub fn point(&mut self, variant: Variant) -> Result<Point> {
        let (ctx, frames) = (self.ctx, (self.opts.frames, self.opts.warmup_ms));
        let (image, report) = render(ctx, &mut self.scene, variant, View::FINAL, frames)?;
        let (diffuse, _) = render(
            ctx,
            &mut self.scene,
            variant,
            View::named("diffuse"),
            (1, None),
        )?;
        let median = |p: &PassStats| p.time.map_or(0.0, |t| t.median_ns) / 1e6;
        // The chain by the tag its passes declare (skin::TAG).
        let is_ruler = |p: &PassStats| crate::timing::is_ruler(&p.name);
        let is_chain = |p: &PassStats| p.tags.iter().any(|t| t == crate::skin::TAG);
        Ok(Point {
            id: variant.id(),
            variant,
            total_ms: report
                .passes
                .iter()
                .filter(|p| !is_ruler(p))
                .map(median)
                .sum(),
            chain_ms: report
                .passes
                .iter()
                .filter(|p| is_chain(p))
                .map(median)
                .sum(),
            frame_span: report.frame_span.clone(),
            transient_bytes: report.memory.transient_pool_bytes,
            final_error: compare(&self.ref_final, &image, &self.mask)?,
            diffuse_error: compare(&self.ref_diffuse, &diffuse, &self.mask)?,
            passes: report.passes,
        })
    }
}

/// How one process runs its part of the sweep.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// `None`: every point.
    pub shard: Option<Shard>,
    /// The JSON Lines log: a header, then each point as it completes.
    pub log: Option<PathBuf>,
    /// Skip the points the log already holds for this sweep hash (and append).
    pub resume: bool,
}

/// A sweep's description without points, for this process (fresh run id,
/// timestamp and fingerprint).
pub fn describe(ctx: &Context, opts: &SweepOptions, session: &Session) -> Sweep {
    let mut fingerprint = Fingerprint::of(&ctx.info);
    fingerprint.clock = session.clock.clone();
    Sweep {
        schema_version: SWEEP_SCHEMA_VERSION,
        sweep_hash: points::sweep_hash(opts),
        run_id: run_id(),
        timestamp: timestamp(),
        dermis_version: VERSION.into(),
        git_commit: GIT_COMMIT.into(),
        device: fingerprint.device.clone(),
        driver: fingerprint.driver.clone(),
        fingerprint,
        scene: opts.scene_label.clone(),
        environment: opts.scene.environment.source.to_string(),
        width: opts.scene.render.width,
        height: opts.scene.render.height,
        frames: opts.frames,
        reference: session.reference,
        reference_checksum: session.reference_checksum.clone(),
        points: Vec::new(),
        shards: Vec::new(),
    }
}

/// Runs the sweep, or this process's shard of it; `progress` sees each point as
/// it completes. The sweep returned holds this run's points (and, resuming,
/// those the log held), in canonical order.
pub fn run(
    ctx: &Arc<Context>,
    opts: &SweepOptions,
    how: &RunOptions,
    mut progress: impl FnMut(&Point),
) -> Result<Sweep> {
    validate(opts)?;
    let all = points::variants(opts);
    let ids: Vec<String> = all.iter().map(Variant::id).collect();
    let mine: Vec<Variant> = all
        .iter()
        .enumerate()
        .filter(|(i, v)| how.shard.is_none_or(|s| s.takes(*i, &v.id())))
        .map(|(_, v)| *v)
        .collect();
    let hash = points::sweep_hash(opts);
    let mut done: Vec<Point> = match (&how.log, how.resume) {
        (Some(path), true) => log::completed(path, &hash)?,
        _ => Vec::new(),
    };
    done.retain(|p| mine.iter().any(|v| v.id() == p.id));
    let mut session = Session::new(ctx, opts)?;
    let mut sweep = describe(ctx, opts, &session);
    let mut writer = match &how.log {
        Some(path) => {
            let header = log::Header::new(&sweep, how.shard, &ids, &mine);
            Some(log::Writer::create(path, &header, how.resume)?)
        }
        None => None,
    };
    let todo: Vec<Variant> = mine
        .into_iter()
        .filter(|v| !done.iter().any(|p| p.id == v.id()))
        .collect();
    // The time left weighed by texels: a 4096² point costs 256 × a 256² one.
    let texels = |v: &Variant| u64::from(v.resolution).pow(2);
    let task = Task::new(
        &format!("sweep: {} points", todo.len()),
        todo.iter().map(texels).sum(),
    );
    for v in todo {
        let point = session.point(v)?;
        if let Some(w) = &mut writer {
            w.append(&point)?;
        }
        task.suspend(|| progress(&point));
        task.add(texels(&v));
        done.push(point);
    }
    drop(task);
    done.sort_by_key(|p| ids.iter().position(|id| *id == p.id));
    sweep.points = done;
    Ok(sweep)
}

pub(crate) fn name<T: Serialize>(v: &T) -> String {
    serde_json::to_value(v)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

pub const CSV_HEADER: &str = "resolution,kernel,chain,pass,median_ms,min_ms,max_ms,p90_ms,\
texels,ns_per_texel,gb_per_s,x_ruler,transient_bytes,final_rmse_rel,final_max_rel,\
final_p99_rel,final_psnr_db,diffuse_rmse_rel,diffuse_max_rel,diffuse_p99_rel,diffuse_psnr_db,\
point_id,run_id,sweep_hash,scene,environment,device,git_commit";

/// One row per point and pass, then a `total` row per point (ruler excluded).
/// Every row ends with the point id and the run's identity (run id, sweep
/// hash, scene, environment, device, commit), so concatenated files stay apart.
pub fn csv(sweep: &Sweep) -> String {
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
    let run = [
        &sweep.run_id,
        &sweep.sweep_hash,
        &sweep.scene,
        &sweep.environment,
        &sweep.device,
        &sweep.git_commit,
    ]
    .map(|s| field(s))
    .join(",");
    let mut out = format!("{CSV_HEADER}\n");
    for p in &sweep.points {
        let v = p.variant;
        let errors = [p.final_error, p.diffuse_error]
            .iter()
            .map(|e| {
                format!(
                    "{},{},{},{}",
                    e.rmse_rel,
                    e.max_rel,
                    e.p99_rel,
                    opt(e.psnr_db)
                )
            })
            .collect::<Vec<_>>()
            .join(",");
        let prefix = format!("{},{},{}", v.resolution, name(&v.kernel), name(&v.chain));
        let id = field(&p.id);
        let ms = |ns: Option<f64>| opt(ns.map(|v| v / 1e6));
        for s in &p.passes {
            let t = s.time;
            out += &format!(
                "{prefix},{},{},{},{},{},{},{},{},{},{},{errors},{id},{run}\n",
                field(&s.name),
                ms(t.map(|t| t.median_ns)),
                ms(t.map(|t| t.min_ns)),
                ms(t.map(|t| t.max_ns)),
                ms(t.map(|t| t.p90_ns)),
                s.texels.map_or(String::new(), |t| t.to_string()),
                opt(s.ns_per_texel),
                opt(s.gb_per_s),
                opt(s.x_ruler),
                p.transient_bytes,
            );
        }
        out += &format!(
            "{prefix},total,{},,,,,,,,{},{errors},{id},{run}\n",
            p.total_ms, p.transient_bytes
        );
    }
    out
}

/// Reads a sweep back from its `sweep.json` (to redraw the plots).
pub fn load(path: &std::path::Path) -> Result<Sweep> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::Io {
        path: path.display().to_string(),
        source,
    })?;
    let mut sweep: Sweep = serde_json::from_str(&text)
        .map_err(|e| Error::Input(format!("{}: {e}", path.display())))?;
    // Sweeps written before ids.
    for p in sweep.points.iter_mut().filter(|p| p.id.is_empty()) {
        p.id = p.variant.id();
    }
    Ok(sweep)
}

/// The table `dermis sweep` prints as points complete: its header…
pub const TABLE_HEADER: &str = "   res kernel    chain       frame ms   chain ms  ruler ns   \
final % diffuse %   pool MiB";

/// …and a point's row.
pub fn table_row(p: &Point) -> String {
    let v = p.variant;
    format!(
        "{:>6} {:<9} {:<9} {:>10.2} {:>10.2} {:>9.2} {:>9.3} {:>9.3} {:>10.1}",
        v.resolution,
        name(&v.kernel),
        name(&v.chain),
        p.total_ms,
        p.chain_ms,
        ruler_ns_per_texel(p).unwrap_or(f64::NAN),
        100.0 * p.final_error.rmse_rel,
        100.0 * p.diffuse_error.rmse_rel,
        p.transient_bytes as f64 / (1u64 << 20) as f64
    )
}

/// The ruler's ns/texel of a point (for tables).
pub fn ruler_ns_per_texel(p: &Point) -> Option<f64> {
    p.passes
        .iter()
        .find(|s| s.name == RULER_COPY)
        .and_then(|s| s.ns_per_texel)
}
