//! `dermis reference`: how close dermis's direct term comes to the truth. For
//! each environment, the scene's `--view direct` (albedo/π · E: SH9 through the
//! per-vertex transfer, plus the lights; no scattering) is rendered with the
//! paper's lighting alone (`environment.lights = 0`) and with the bright sources
//! taken out as shadowed lights (`auto`), and both are compared, per pixel, with
//! the CPU reference of the same quantity (light::reference): the mean, median
//! and 90th percentile of the relative error of luminance over the mesh.
//!
//! The albedo is a uniform grey (the scene's albedo map is dropped) and the
//! skybox off (alpha is the mesh's coverage), so the error is the lighting's.

use crate::error::{Error, Result};
use crate::gpu::Context;
use crate::light::reference::{render_view_with, Settings};
use crate::render::output::write_exr;
use crate::render::progress::Task;
use crate::render::{render_scene, RenderOptions, View};
use crate::scene::env::EnvSource;
use crate::scene::file::{LightsMode, SceneFile};
use crate::scene::Scene;
use crate::sweep::metric::{relative, RelativeError};
use crate::sweep::output::write_side_by_side;
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct LightingOptions {
    /// The scene (camera, mesh, normal map; its environment is replaced).
    pub scene: SceneFile,
    pub environments: Vec<EnvSource>,
    pub width: u32,
    pub height: u32,
    /// How long the reference samples.
    pub settings: Settings,
    /// Where to write each environment's reference and dermis images (EXR) and
    /// a PNG of the three side by side; nothing when `None`.
    pub out_dir: Option<PathBuf>,
}

/// One environment's errors.
#[derive(Clone, Debug, Serialize)]
pub struct LightingRow {
    pub environment: String,
    /// Sources `auto` took out of the map.
    pub extracted: usize,
    /// The paper: SH9 alone.
    pub sh9: RelativeError,
    /// SH9 of the rest + the extracted sources as shadowed lights.
    pub sh9_lights: RelativeError,
    /// Share of mesh pixels whose reference converged to its target.
    pub reference_converged: f32,
    pub reference_mean_rel_std_err: f32,
    pub reference_seconds: f64,
}

/// Runs every environment; `progress` sees each row as it completes.
pub fn run(
    ctx: &Arc<Context>,
    opts: &LightingOptions,
    mut progress: impl FnMut(&LightingRow),
) -> Result<Vec<LightingRow>> {
    if opts.environments.is_empty() {
        return Err(Error::Input(
            "reference: give at least one environment".into(),
        ));
    }
    if let Some(dir) = &opts.out_dir {
        crate::sweep::output::create_dir(dir)?;
    }
    let mut rows = Vec::new();
    for (k, env) in opts.environments.iter().enumerate() {
        let mut file = opts.scene.clone();
        file.environment.source = env.clone();
        file.textures.albedo = None;
        file.render.skybox = false;
        file.render.width = opts.width;
        file.render.height = opts.height;
        let mut scene = Scene::load(file)?;
        let task = Task::new(&format!("reference of {env}"), opts.height.into());
        let reference = render_view_with(&scene, opts.width, opts.height, &opts.settings, &|| {
            task.add(1)
        })?;
        drop(task);
        let mut direct = |lights: LightsMode| -> Result<(Vec<f32>, usize)> {
            scene.file.environment.lights = lights;
            let out = render_scene(
                ctx,
                &scene,
                &RenderOptions {
                    view: View::named("direct"),
                    hdr: true,
                    ..RenderOptions::default()
                },
            )?;
            Ok((
                out.hdr.unwrap_or_default(),
                out.report.setup.extracted_lights,
            ))
        };
        let (sh9, _) = direct(LightsMode::Count(0))?;
        let (lit, extracted) = direct(LightsMode::Auto)?;
        let mask: Vec<bool> = reference
            .rgba
            .chunks_exact(4)
            .zip(lit.chunks_exact(4))
            .map(|(r, a)| r[3] > 0.5 && a[3] > 0.5)
            .collect();
        let row = LightingRow {
            environment: env.to_string(),
            extracted,
            sh9: relative(&reference.rgba, &sh9, &mask)?,
            sh9_lights: relative(&reference.rgba, &lit, &mask)?,
            reference_converged: reference.converged,
            reference_mean_rel_std_err: reference.mean_rel_std_err,
            reference_seconds: reference.seconds,
        };
        if let Some(dir) = &opts.out_dir {
            let (w, h) = (opts.width, opts.height);
            let name = |what: &str| dir.join(format!("{k}-{what}"));
            write_exr(&name("reference.exr"), w, h, &reference.rgba)?;
            write_exr(&name("sh9.exr"), w, h, &sh9)?;
            write_exr(&name("sh9-lights.exr"), w, h, &lit)?;
            // All three at the reference's exposure (given, or metered on it).
            let images: [&[f32]; 3] = [&reference.rgba, &sh9, &lit];
            write_side_by_side(
                &name("reference-sh9-lights.png"),
                (w, h),
                &images,
                &scene.file.render,
            )?;
        }
        progress(&row);
        rows.push(row);
    }
    Ok(rows)
}

/// The rows as a Markdown table (percentages).
pub fn table(rows: &[LightingRow]) -> String {
    let pct = |v: f64| format!("{:.1} %", 100.0 * v);
    let mut out = String::from(
        "| environment | lights | SH9 mean | median | p90 | SH9 + lights mean | median | p90 | reference converged |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        out += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {:.0} % ({:.2} % mean error) |\n",
            r.environment,
            r.extracted,
            pct(r.sh9.mean),
            pct(r.sh9.median),
            pct(r.sh9.p90),
            pct(r.sh9_lights.mean),
            pct(r.sh9_lights.median),
            pct(r.sh9_lights.p90),
            100.0 * r.reference_converged,
            100.0 * r.reference_mean_rel_std_err,
        );
    }
    out
}
