//! `dermis sweep`: time against quality. Renders the scene for every irradiance
//! resolution × blur kernel × diffusion chain, with the rulers, and compares the
//! final image and the diffuse term with a reference (by default 4096², accurate
//! kernel, full chain) over the face. Writes a CSV, a JSON and plots.

pub mod lighting;
pub mod metric;
pub mod plot;

use crate::error::{Error, Result};
use crate::gpu::Context;
use crate::profile::{PassStats, RunReport, GIT_COMMIT, RULER_COPY, VERSION};
use crate::render::{render_scene, RenderOptions, View};
use crate::scene::file::{Chain, Kernel, SceneFile};
use crate::scene::Scene;
use metric::{compare, coverage_mask, ImageError};
use serde::{Deserialize, Serialize};
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
    pub reference_resolution: u32,
}

/// The resolution, kernel and chain of one render.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct Variant {
    pub resolution: u32,
    pub kernel: Kernel,
    pub chain: Chain,
}

/// One point of the sweep.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Point {
    #[serde(flatten)]
    pub variant: Variant,
    /// Per pass over the measured frames, rulers included.
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

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Sweep {
    pub dermis_version: String,
    pub git_commit: String,
    pub device: String,
    pub driver: String,
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub reference: Variant,
    pub points: Vec<Point>,
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

/// The linear HDR image of `view` for `variant`, and the run report.
fn render(
    ctx: &Arc<Context>,
    scene: &mut Scene,
    variant: Variant,
    view: View,
    frames: u32,
) -> Result<(Vec<f32>, RunReport)> {
    scene.file.render.irradiance_resolution = variant.resolution;
    scene.file.skin.kernel = variant.kernel;
    scene.file.skin.chain = variant.chain;
    let out = render_scene(
        ctx,
        scene,
        &RenderOptions {
            frames,
            hdr: true,
            view,
            ruler: view == View::Final,
            ..RenderOptions::default()
        },
    )?;
    let hdr = out
        .hdr
        .ok_or_else(|| Error::Input("sweep: the render returned no HDR image".into()))?;
    Ok((hdr, out.report))
}

/// Runs the sweep; `progress` sees each point as it completes.
pub fn run(
    ctx: &Arc<Context>,
    opts: &SweepOptions,
    mut progress: impl FnMut(&Point),
) -> Result<Sweep> {
    validate(opts)?;
    let mut file = opts.scene.clone();
    file.render.skybox = false;
    let mut scene = Scene::load(file)?;
    let reference = Variant {
        resolution: opts.reference_resolution,
        kernel: Kernel::Accurate,
        chain: Chain::Full,
    };
    let (ref_final, _) = render(ctx, &mut scene, reference, View::Final, 1)?;
    let (ref_diffuse, _) = render(ctx, &mut scene, reference, View::Diffuse, 1)?;
    let mask = coverage_mask(&ref_final);
    let mut points = Vec::new();
    for &resolution in &opts.resolutions {
        for &kernel in &opts.kernels {
            for &chain in &opts.chains {
                let variant = Variant {
                    resolution,
                    kernel,
                    chain,
                };
                let (image, report) = render(ctx, &mut scene, variant, View::Final, opts.frames)?;
                let (diffuse, _) = render(ctx, &mut scene, variant, View::Diffuse, 1)?;
                let median = |p: &PassStats| p.time.map_or(0.0, |t| t.median_ns) / 1e6;
                let is_ruler = |p: &PassStats| p.name.starts_with("ruler_");
                let is_chain =
                    |p: &PassStats| p.name.starts_with("blur") || p.name.starts_with("stretch");
                let point = Point {
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
                    final_error: compare(&ref_final, &image, &mask)?,
                    diffuse_error: compare(&ref_diffuse, &diffuse, &mask)?,
                    passes: report.passes,
                };
                progress(&point);
                points.push(point);
            }
        }
    }
    Ok(Sweep {
        dermis_version: VERSION.into(),
        git_commit: GIT_COMMIT.into(),
        device: ctx.info.name.clone(),
        driver: format!("{} {}", ctx.info.driver_name, ctx.info.driver_info)
            .trim()
            .into(),
        scene: opts.scene_label.clone(),
        width: opts.scene.render.width,
        height: opts.scene.render.height,
        frames: opts.frames,
        reference,
        points,
    })
}

fn name<T: Serialize>(v: &T) -> String {
    serde_json::to_value(v)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

pub const CSV_HEADER: &str = "resolution,kernel,chain,pass,median_ms,min_ms,max_ms,p90_ms,\
texels,ns_per_texel,gb_per_s,x_ruler,transient_bytes,final_rmse_rel,final_max_rel,\
final_p99_rel,final_psnr_db,diffuse_rmse_rel,diffuse_max_rel,diffuse_p99_rel,diffuse_psnr_db";

/// One row per point and pass, then a `total` row per point (ruler excluded).
pub fn csv(sweep: &Sweep) -> String {
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
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
        let ms = |ns: Option<f64>| opt(ns.map(|v| v / 1e6));
        for s in &p.passes {
            let t = s.time;
            out += &format!(
                "{prefix},{},{},{},{},{},{},{},{},{},{},{errors}\n",
                s.name,
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
            "{prefix},total,{},,,,,,,,{},{errors}\n",
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
    serde_json::from_str(&text).map_err(|e| Error::Input(format!("{}: {e}", path.display())))
}

/// The ruler's ns/texel of a point (for tables).
pub fn ruler_ns_per_texel(p: &Point) -> Option<f64> {
    p.passes
        .iter()
        .find(|s| s.name == RULER_COPY)
        .and_then(|s| s.ns_per_texel)
}
