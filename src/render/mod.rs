//! The `render` command's library side: load the scene, upload it, build the
//! frame graph, run it for a number of frames, read the image back, and report
//! per-pass timings.

mod frame;
pub mod output;
mod progress;
pub mod ruler;
pub mod session;
mod view;

pub use view::View;

use crate::error::{Error, Result};
use crate::gpu::{Context, ContextOptions, DeviceInfo};
use crate::graph::upload::Readback;
use crate::graph::{Executor, Graph};
use crate::light::reference::{render_view, ReferenceImage, Settings as ReferenceSettings};
use crate::post::tonemap::encode8;
use crate::profile::{MemoryUse, RunReport, RunSetup};
use crate::scene::file::{Chain, Kernel, Occlusion, SceneFile};
use crate::scene::Scene;
use crate::skin::SkinSettings;
use frame::Frame;
use progress::Progress;
use std::path::PathBuf;
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// The scene, with any command-line overrides already applied.
    pub scene: SceneFile,
    /// Frames to render; with more than one, the first is warm-up and excluded
    /// from the median (lavapipe compiles shaders on first use).
    pub frames: u32,
    /// Also read back the linear HDR image (for EXR output).
    pub hdr: bool,
    pub view: View,
    pub context: ContextOptions,
    /// Where `scene` was read from, for the report (`None`: the default scene).
    pub scene_path: Option<PathBuf>,
    /// Show a progress bar on stderr (the caller checks it is a terminal).
    pub progress: bool,
    /// Time the rulers (render::ruler) in every frame.
    pub ruler: bool,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            scene: SceneFile::default(),
            frames: 1,
            hdr: false,
            view: View::Final,
            context: ContextOptions::from_env(),
            scene_path: None,
            progress: false,
            ruler: false,
        }
    }
}

/// What the report says was rendered.
fn setup(
    scene: &Scene,
    opts: &RenderOptions,
    irradiance_resolution: u32,
    extracted_lights: usize,
) -> RunSetup {
    let f = &scene.file;
    let path = |p: &Option<PathBuf>, none: &str| {
        p.as_ref()
            .map_or_else(|| none.to_string(), |p| p.display().to_string())
    };
    RunSetup {
        scene: path(&opts.scene_path, "default"),
        mesh: path(&f.mesh, "builtin"),
        environment: f.environment.source.to_string(),
        environment_rotation_deg: f.environment.rotation_deg,
        irradiance_resolution,
        kernel: match f.skin.kernel {
            Kernel::Deon7 => "deon7",
            Kernel::Accurate => "accurate",
        }
        .into(),
        chain: match f.skin.chain {
            Chain::Full => "full",
            Chain::Adaptive => "adaptive",
        }
        .into(),
        view: opts.view.name().into(),
        render_width: f.render.width,
        render_height: f.render.height,
        occlusion: match f.skin.occlusion {
            Occlusion::Raster => "raster",
            Occlusion::Raytrace => "raytrace",
            Occlusion::Off => "off",
        }
        .into(),
        shadow_resolution: f.render.shadow_resolution,
        lights: f.lights.len(),
        environment_lights: f.environment.lights.to_string(),
        extracted_lights,
    }
}

pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
    /// `--view reference`: how the CPU reference converged (its pixels are in
    /// `rgba8` and `hdr`; `rgba` here is empty).
    pub reference: Option<ReferenceImage>,
    /// sRGB-encoded RGBA8, row-major, top row first.
    pub rgba8: Vec<u8>,
    /// Linear RGBA radiance × 2^exposure, when asked for.
    pub hdr: Option<Vec<f32>>,
    pub report: RunReport,
    /// The compiled plan of the last frame, as `--dump-graph` prints it.
    pub plan: String,
}

/// Checks a requested target size against the device before allocating anything.
pub fn check_target(info: &DeviceInfo, width: u32, height: u32) -> Result<()> {
    let max = info.max_image_dimension_2d;
    if width == 0 || height == 0 || width > max || height > max {
        return Err(Error::Input(format!(
            "target {width}x{height} is outside what {} allows (1..={max} pixels per side)",
            info.name
        )));
    }
    Ok(())
}

pub fn render(opts: &RenderOptions) -> Result<RenderOutput> {
    let scene = Scene::load(opts.scene.clone())?;
    let ctx = Context::new(&opts.context)?;
    render_scene(&ctx, &scene, opts)
}

pub fn render_scene(
    ctx: &Arc<Context>,
    scene: &Scene,
    opts: &RenderOptions,
) -> Result<RenderOutput> {
    if opts.frames == 0 {
        return Err(Error::Input(
            "frames: 0 frames render nothing; give 1 or more".into(),
        ));
    }
    let screen = (scene.file.render.width, scene.file.render.height);
    check_target(&ctx.info, screen.0, screen.1)?;
    let skin = SkinSettings::resolve(&scene.file.skin, &scene.file.render)?;
    check_target(&ctx.info, skin.resolution, skin.resolution)?;
    if opts.view == View::Reference {
        return reference(ctx, scene, opts, skin.resolution);
    }
    let resolution = skin.resolution;
    let frame = Frame::new(ctx, scene, skin, opts.ruler)?;
    let run_setup = setup(scene, opts, resolution, frame.extracted_lights);
    // The view's image and its size (UV views: as stored, e.g. a coarse adaptive level).
    let (w, h) = {
        let (image, _) = frame.graph(&mut Graph::new(), opts.view, screen, true);
        (image.desc.width, image.desc.height)
    };
    let readback = |name: &str, bytes_per_texel: u64| {
        Readback::new(ctx, name, w as u64 * h as u64 * bytes_per_texel)
    };
    let uv = opts.view.uv_space();
    let ldr_readback = if uv {
        None
    } else {
        Some(readback("readback ldr", 4)?)
    };
    let hdr_readback = if opts.hdr || uv {
        Some(readback("readback hdr", 8)?)
    } else {
        None
    };

    let mut executor = Executor::new(ctx, 2)?;
    let mut reports = Vec::new();
    let mut plan = String::new();
    let progress = Progress::new(opts.frames, opts.progress);
    for i in 0..opts.frames {
        let mut g = Graph::new();
        let (hdr, ldr) = frame.graph(&mut g, opts.view, screen, i == 0);
        if let (Some(ldr), Some(r)) = (&ldr, &ldr_readback) {
            r.image_pass(&mut g, ldr);
        }
        if let Some(r) = &hdr_readback {
            r.image_pass(&mut g, &hdr);
        }
        let compiled = executor.compile(g)?;
        plan = compiled.plan.to_string();
        reports.extend(executor.submit(compiled)?);
        progress.update(reports.len(), reports.last().and_then(|r| r.gpu_frame_ns));
    }
    reports.extend(executor.finish()?);
    drop(progress);
    let exposure = frame.exposure_for(opts.view);
    // Screen views: linear radiance × 2^exposure, alpha (coverage) as is. UV
    // views: the values as stored.
    let hdr = match &hdr_readback {
        Some(b) => {
            let scale = if uv { 1.0 } else { exposure.exp2() };
            Some(
                b.bytes()?
                    .chunks_exact(2)
                    .enumerate()
                    .map(|(i, c)| {
                        let v = half::f16::from_le_bytes([c[0], c[1]]).to_f32();
                        if i % 4 == 3 {
                            v
                        } else {
                            v * scale
                        }
                    })
                    .collect::<Vec<f32>>(),
            )
        }
        None => None,
    };
    let rgba8 = match (&ldr_readback, &hdr) {
        (Some(b), _) => b.bytes()?.to_vec(),
        (None, Some(values)) => encode8(values, exposure, scene.file.render.gamma),
        (None, None) => Vec::new(),
    };
    let (allocated_bytes, reserved_bytes) = ctx.allocator_bytes();
    let memory = MemoryUse {
        transient_pool_bytes: executor.pool_bytes(),
        allocated_bytes,
        reserved_bytes,
    };
    let report = RunReport::new(&ctx.info, run_setup, w, h, reports, memory);
    Ok(RenderOutput {
        width: w,
        height: h,
        reference: None,
        rgba8,
        hdr,
        report,
        plan,
    })
}

/// `--view reference`: the CPU reference of the direct view
/// (light::reference::render_view), exposed and encoded like the GPU's image;
/// its report has no passes.
fn reference(
    ctx: &Arc<Context>,
    scene: &Scene,
    opts: &RenderOptions,
    resolution: u32,
) -> Result<RenderOutput> {
    let (w, h) = (scene.file.render.width, scene.file.render.height);
    let mut image = render_view(scene, w, h, &ReferenceSettings::default())?;
    let exposure = scene.exposure();
    let rgba8 = encode8(&image.rgba, exposure, scene.file.render.gamma);
    let scale = exposure.exp2();
    let hdr = opts.hdr.then(|| {
        image
            .rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0] * scale, p[1] * scale, p[2] * scale, p[3]])
            .collect()
    });
    image.rgba = Vec::new();
    let setup = setup(scene, opts, resolution, 0);
    Ok(RenderOutput {
        width: w,
        height: h,
        reference: Some(image),
        rgba8,
        hdr,
        report: RunReport::new(&ctx.info, setup, w, h, Vec::new(), MemoryUse::default()),
        plan: String::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_beyond_the_device_limit_are_input_errors() {
        let info = DeviceInfo {
            name: "small GPU".into(),
            device_type: "discrete GPU".into(),
            driver_name: String::new(),
            driver_info: String::new(),
            api_version: "1.3.0".into(),
            vendor_id: 0,
            device_id: 0,
            timestamps: true,
            timestamp_period_ns: 1.0,
            timestamp_valid_bits: 64,
            max_image_dimension_2d: 8192,
            memory_heaps: Vec::new(),
            validation: false,
        };
        assert!(check_target(&info, 8192, 8192).is_ok());
        let e = check_target(&info, 8193, 100).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(
            e.to_string()
                .contains("8193x100 is outside what small GPU allows"),
            "{e}"
        );
        assert!(check_target(&info, 0, 100).is_err());
    }
}
