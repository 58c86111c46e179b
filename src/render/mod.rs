//! The `render` command's library side: upload the scene, build the frame
//! graph, run it for a number of frames, read the image and the exposure back,
//! and report per-pass timings; the debug sheet and the occlusion comparison.

mod frame_graph;
pub mod output;
pub mod progress;
pub mod ruler;
pub mod session;
pub mod sheet;
mod view;

pub use view::{Screen, Shown, View};

use crate::error::{Error, Result};
use crate::gpu::{Context, DeviceInfo};
use crate::graph::upload::Readback;
use crate::graph::{Executor, Graph, Kept};
use crate::light::reference::{render_view_with, ReferenceImage, Settings as ReferenceSettings};
use crate::post::meter::{self, Metered};
use crate::post::tonemap::encode8;
use crate::post::{Exposure, PostSettings};
use crate::scene::checker;
use crate::scene::file::{Chain, Gamma, Kernel, Occlusion, UvOrigin};
use crate::scene::texture::flip_rows;
use crate::scene::Scene;
use crate::skin::SkinSettings;
use crate::timing::{CameraSetup, MemoryUse, PipelineTime, RunReport, RunSetup};
use frame_graph::Frame;
use progress::Progress;
use sheet::Sheet;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Frames to render; with more than one, the first is warm-up and excluded
    /// from the median (lavapipe compiles shaders on first use).
    pub frames: u32,
    /// Also read back the linear HDR image (for EXR output).
    pub hdr: bool,
    pub view: View,
    /// Where the scene was read from, for the report (`None`: the default scene).
    pub scene_path: Option<PathBuf>,
    /// Show a progress bar on stderr (the caller checks it is a terminal).
    pub progress: bool,
    /// Time the rulers (render::ruler) in every frame.
    pub ruler: bool,
    /// Count every pass's work (pipeline statistics) in every frame
    /// (graph::Executor::set_counters).
    pub counters: bool,
    /// Independent repetitions, each with a fresh upload, pipelines and warm-up;
    /// the image is the last run's.
    pub runs: u32,
    /// Warm-up frames per run, outside the statistics (`None`: 1 when there
    /// are more frames than one, else 0).
    pub warmup: Option<u32>,
    /// Pre-roll: after a run's first frame, frames rendered and not reported
    /// until this many milliseconds have passed, so that a GPU's clocks are up
    /// before the frames that count (`None`: [`PREROLL_GPU_MS`] on GPUs, 0 on
    /// CPU devices). Only when some frame is measured.
    pub warmup_ms: Option<u32>,
    /// After the runs, one more with every shader that has the variant
    /// skipping its work (gpu::Context::set_skip_work): each such pass's
    /// time there over its time, and the bound-by verdict from it
    /// (RunReport::with_work_skipped). Its image is not kept.
    pub variants: bool,
}

/// The default pre-roll on GPUs. An NVIDIA H200 left idle between a sweep's
/// points measured the next point at 345–750 MHz instead of 1980: its raster
/// passes up to 5.6× slower (docs/records/2026-11-26-h200.md).
pub const PREROLL_GPU_MS: u32 = 1000;

impl RenderOptions {
    /// Warm-up frames per run; an error when no measured frame would be left.
    pub fn warmup_frames(&self) -> Result<u32> {
        match self.warmup {
            None => Ok(u32::from(self.frames > 1)),
            Some(w) if w < self.frames => Ok(w),
            Some(w) => Err(Error::Input(format!(
                "--warmup {w} leaves none of --frames {} measured: give more frames than warm-up",
                self.frames
            ))),
        }
    }

    /// The pre-roll on this device (see `warmup_ms`).
    pub fn preroll(&self, device: &crate::gpu::DeviceInfo) -> std::time::Duration {
        let ms = match (self.frames, self.warmup_ms) {
            (0..=1, _) => 0,
            (_, Some(ms)) => ms,
            _ if device.is_cpu() => 0,
            _ => PREROLL_GPU_MS,
        };
        std::time::Duration::from_millis(ms.into())
    }
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            frames: 1,
            hdr: false,
            view: View::FINAL,
            scene_path: None,
            progress: false,
            ruler: false,
            counters: false,
            runs: 1,
            warmup: None,
            warmup_ms: None,
            variants: false,
        }
    }
}

/// What the report says was rendered: `view` with `exposure` EV (metered or
/// given).
fn setup(
    scene: &Scene,
    (opts, device): (&RenderOptions, &DeviceInfo),
    view: &View,
    extracted_lights: usize,
    (exposure_ev, exposure_metered): (f32, bool),
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
        irradiance_resolution: f.render.irradiance_resolution,
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
        view: view.name().into(),
        render_width: f.render.width,
        render_height: f.render.height,
        occlusion: match f.skin.occlusion {
            Occlusion::Raster => "raster",
            Occlusion::Raytrace => "raytrace",
            Occlusion::Off => "off",
        }
        .into(),
        shadow_resolution: f.render.shadow_resolution,
        shadow_focus: f.render.shadow_focus,
        irradiance_shading: match f.render.irradiance_shading.compute(device.is_cpu()) {
            true => "compute".into(),
            false => String::new(),
        },
        lights: f.lights.len(),
        environment_lights: f.environment.lights.to_string(),
        extracted_lights,
        exposure_ev,
        exposure_metered,
        tone_curve: format!("{:?}", f.render.tone_curve).to_lowercase(),
        glow_intensity: if f.render.glow {
            f.render.glow_intensity
        } else {
            0.0
        },
        blur_width: f.skin.blur_width,
        blur_amount: f.skin.blur_amount,
        transmission: f.skin.transmission,
        test_texture: f.textures.test_texture || *view == View::Screen(Screen::TestTexture),
        gamma: match f.render.gamma {
            Gamma::Srgb => "srgb".into(),
            Gamma::Power(g) => g.to_string(),
        },
        skybox: f.render.skybox,
        background: f.render.background,
        uv_origin: match f.textures.uv_origin {
            UvOrigin::TopLeft => "top-left",
            UvOrigin::BottomLeft => "bottom-left",
        }
        .into(),
        mm_per_unit: f.mm_per_unit,
        camera: CameraSetup {
            position_mm: scene.camera.position.into(),
            target_mm: scene.camera.target.into(),
            up: scene.camera.up.into(),
            fov_y_deg: scene.camera.fov_y_deg,
            near_mm: scene.camera.near_mm,
            far_mm: scene.camera.far_mm,
        },
    }
}

pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
    pub view: View,
    /// `--view reference`: how the CPU reference converged (its pixels are in
    /// `rgba8` and `hdr`; `rgba` here is empty).
    pub reference: Option<ReferenceImage>,
    /// sRGB-encoded RGBA8, row-major, top row first.
    pub rgba8: Vec<u8>,
    /// Linear RGBA, when asked for: screen views the radiance the tone map
    /// read (after the glow; alpha = coverage), UV-space views as stored.
    pub hdr: Option<Vec<f32>>,
    /// The exposure `rgba8` was made with, EV: given, metered (the GPU's, read
    /// back; a UV-space view's on the CPU), or 0 for fractions and data
    /// (View::shown). EXR output is `hdr` × 2^exposure for screen views.
    pub exposure: f32,
    /// What the meter found, when the exposure was metered.
    pub metered: Option<Metered>,
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

/// Renders `opts.view` of `scene`.
pub fn render_scene(
    ctx: &Arc<Context>,
    scene: &Scene,
    opts: &RenderOptions,
) -> Result<RenderOutput> {
    for (n, what) in [(opts.frames, "frames"), (opts.runs, "runs")] {
        if n == 0 {
            return Err(Error::Input(format!(
                "{what}: 0 {what} render nothing; give 1 or more"
            )));
        }
    }
    let warmup = opts.warmup_frames()?;
    if opts.counters && !ctx.info.pipeline_statistics {
        return Err(Error::Input(format!(
            "--counters: {} offers no pipeline statistics queries (the \
             pipelineStatisticsQuery feature); render without --counters",
            ctx.info.name
        )));
    }
    let skin = settings(ctx, scene)?;
    if opts.view == View::Screen(Screen::Reference) {
        return reference(ctx, scene, opts);
    }
    let test_texture;
    let checker = opts.view == View::Screen(Screen::TestTexture);
    let albedo = if checker && !scene.file.textures.test_texture {
        test_texture = checker::albedo(scene.file.textures.uv_origin);
        &test_texture
    } else {
        &scene.albedo
    };
    let mut frames = Vec::new();
    let mut last = None;
    for run_index in 0..opts.runs {
        let frame = Frame::new(ctx, scene, albedo, skin.clone(), opts.ruler)?;
        let out = run(ctx, scene, &frame, &opts.view, opts)?;
        frames.extend(out.report.per_frame.iter().cloned().map(|mut f| {
            f.run = run_index;
            f
        }));
        last = Some(out);
    }
    let mut out = last.expect("at least one run");
    let r = &out.report;
    let (preroll_ms, pipelines) = (r.preroll_ms, r.pipelines.clone());
    out.report = RunReport::new(
        &ctx.info,
        r.setup.clone(),
        (r.width, r.height),
        frames,
        warmup as usize,
        r.memory,
    );
    if opts.variants {
        ctx.set_skip_work(true);
        let skipped = Frame::new(ctx, scene, albedo, skin.clone(), opts.ruler)
            .and_then(|frame| run(ctx, scene, &frame, &opts.view, opts));
        ctx.set_skip_work(false);
        out.report = out.report.with_work_skipped(&skipped?.report);
    }
    out.report.preroll_ms = preroll_ms;
    out.report.pipelines = pipelines;
    Ok(out)
}

/// The skin settings of `scene`, its sizes checked against the device.
fn settings(ctx: &Arc<Context>, scene: &Scene) -> Result<SkinSettings> {
    check_target(&ctx.info, scene.file.render.width, scene.file.render.height)?;
    let skin = SkinSettings::resolve(&scene.file.skin, &scene.file.render)?;
    check_target(&ctx.info, skin.resolution, skin.resolution)?;
    Ok(skin)
}

/// The views of the debug sheet (the paper's Fig. 3 and debug mode), in rows
/// of [`sheet::COLUMNS`]: the six stretch levels, the six blur levels, then
/// depth, occlusion and specular.
pub fn sheet_views() -> Vec<View> {
    let stretch = (0..6).map(crate::skin::stretch::level_name);
    let blur = (1..=6).map(crate::skin::blur::BlurChain::level_name);
    let screens = [
        Screen::Debug(crate::post::debug::DebugView::Depth),
        Screen::Direct(crate::light::direct::DirectView::Occlusion),
        Screen::Skin(crate::skin::shade::ShadeMode::Specular),
        Screen::Skin(crate::skin::shade::ShadeMode::Transmission),
    ];
    stretch
        .chain(blur)
        .map(View::Image)
        .chain(screens.map(View::Screen))
        .collect()
}

/// Every view of `scene` (`render --view list`): the screen views, then the
/// frame graph's images that can be read back as stored.
pub fn views(ctx: &Arc<Context>, scene: &Scene) -> Result<Vec<String>> {
    let frame = Frame::new(ctx, scene, &scene.albedo, settings(ctx, scene)?, false)?;
    frame.views((scene.file.render.width, scene.file.render.height))
}

/// Whether `view` is shown upside down from how it is stored: UV-space views are
/// shown in the orientation of the scene's maps, and maps with their UV origin
/// at the bottom left were flipped on load (scene::texture::flip_rows).
fn flipped(scene: &Scene, view: &View) -> bool {
    view.uv_space() && scene.file.textures.uv_origin == UvOrigin::BottomLeft
}

/// Images of the frame graph by name (RGBA16F, UV-space), one frame each on one
/// upload of the scene, as stored: rows in the order of v, not flipped for
/// display. Each is (width, height, linear RGBA).
pub fn stored_images(
    ctx: &Arc<Context>,
    scene: &Scene,
    names: &[String],
) -> Result<Vec<(u32, u32, Vec<f32>)>> {
    let frame = Frame::new(ctx, scene, &scene.albedo, settings(ctx, scene)?, false)?;
    names
        .iter()
        .map(|name| {
            let view = View::Image(name.clone());
            let out = run(
                ctx,
                scene,
                &frame,
                &view,
                &single(&RenderOptions::default()),
            )?;
            let mut values = out.hdr.unwrap_or_default();
            if flipped(scene, &view) {
                flip_rows(&mut values, out.width as usize * 4);
            }
            Ok((out.width, out.height, values))
        })
        .collect()
}

/// One frame of each view, without progress bar or HDR image.
fn single(opts: &RenderOptions) -> RenderOptions {
    RenderOptions {
        frames: 1,
        hdr: false,
        progress: false,
        ..opts.clone()
    }
}

/// The debug sheet: every view of [`sheet_views`] rendered (one frame each, on
/// one upload of the scene) and labelled with its name.
pub fn debug_sheet(ctx: &Arc<Context>, scene: &Scene, opts: &RenderOptions) -> Result<Sheet> {
    let frame = Frame::new(ctx, scene, &scene.albedo, settings(ctx, scene)?, false)?;
    let tiles = sheet_views()
        .iter()
        .map(|view| {
            let out = run(ctx, scene, &frame, view, &single(opts))?;
            Ok((view.name().to_string(), out))
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(sheet::compose(&tiles, sheet::COLUMNS, sheet::TILE))
}

/// `opts.view` with occlusion on (the scene's method, or `raytrace` where the
/// scene has it off) and off, side by side (the paper's Figs. 6–8), at one
/// exposure: the one metered (or given) with occlusion on.
pub fn compare_occlusion(ctx: &Arc<Context>, scene: &Scene, opts: &RenderOptions) -> Result<Sheet> {
    let mut on = scene.clone();
    if on.file.skin.occlusion == Occlusion::Off {
        on.file.skin.occlusion = Occlusion::Raytrace;
    }
    let with = render_scene(ctx, &on, &single(opts))?;
    let mut off = on.clone();
    off.file.skin.occlusion = Occlusion::Off;
    off.file.render.exposure = Some(with.exposure);
    let without = render_scene(ctx, &off, &single(opts))?;
    let method = format!("{:?}", on.file.skin.occlusion).to_lowercase();
    let size = (with.width, with.height);
    let tiles = [
        (format!("{}, occlusion {method}", opts.view.name()), with),
        (format!("{}, occlusion off", opts.view.name()), without),
    ];
    Ok(sheet::compose(&tiles, 2, size))
}

/// Renders `view` with `frame`, `opts.frames` times; reads back the image(s)
/// and the exposure.
fn run(
    ctx: &Arc<Context>,
    scene: &Scene,
    frame: &Frame,
    view: &View,
    opts: &RenderOptions,
) -> Result<RenderOutput> {
    let screen = (scene.file.render.width, scene.file.render.height);
    // The view's image and its size (UV views: as stored, e.g. a coarse adaptive level).
    let (w, h) = {
        let images = frame.graph(&mut Graph::new(), view, screen)?;
        (images.image.desc.width, images.image.desc.height)
    };
    let readback = |name: &str, bytes_per_texel: u64| {
        Readback::new(ctx, name, w as u64 * h as u64 * bytes_per_texel)
    };
    let uv = view.uv_space();
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
    let exposure_readback = Readback::new(ctx, "readback exposure", meter::RESULT_BYTES)?;

    let mut executor = Executor::new(ctx, 2)?;
    executor.set_counters(opts.counters)?;
    let mut reports = Vec::new();
    let mut plan = String::new();
    let mut gpu_metered = false;
    let progress = Progress::new(opts.frames, opts.progress);
    // What the frames compute once and keep (SH, shadows, stretch maps …).
    let mut kept = Kept::default();
    // The frame's graph with its readbacks; whether the GPU meters exposure.
    let build = |kept: &Kept| -> Result<(Graph, bool)> {
        let mut g = Graph::with_kept(kept.clone());
        let images = frame.graph(&mut g, view, screen)?;
        if let (Some(ldr), Some(r)) = (&images.ldr, &ldr_readback) {
            r.image_pass(&mut g, ldr);
        }
        // After the 8-bit readback, which waits for the tone map's reads.
        if let Some(m) = &images.metered {
            exposure_readback.buffer_pass(&mut g, m);
        }
        if let Some(r) = &hdr_readback {
            r.image_pass(&mut g, &images.image);
        }
        Ok((g, images.metered.is_some()))
    };
    let preroll = opts.preroll(&ctx.info);
    // The frames of the pre-roll, rendered before the second frame and not reported.
    let mut unreported = 0..0;
    for i in 0..opts.frames {
        if i == 1 && !preroll.is_zero() {
            let (start, until) = (executor.frames_submitted(), Instant::now() + preroll);
            while Instant::now() < until {
                let compiled = executor.compile(build(&kept)?.0)?;
                reports.extend(executor.submit(compiled)?);
            }
            unreported = start..executor.frames_submitted();
        }
        let (g, metered) = build(&kept)?;
        gpu_metered |= metered;
        let compiled = executor.compile(g)?;
        kept = compiled.plan.kept.clone();
        plan = compiled.plan.to_string();
        reports.extend(executor.submit(compiled)?);
        progress.update(i as usize + 1, reports.last().and_then(|r| r.gpu_frame_ns));
    }
    reports.extend(executor.finish()?);
    reports.retain(|r| !unreported.contains(&r.frame));
    drop(progress);
    let mut hdr = match &hdr_readback {
        Some(b) => Some(
            b.bytes()?
                .chunks_exact(2)
                .map(|c| half::f16::from_le_bytes([c[0], c[1]]).to_f32())
                .collect::<Vec<f32>>(),
        ),
        None => None,
    };
    let (exposure, display) = frame.display(view.shown());
    // Metered on the pre-exposed values (as the GPU's meter is), then read as
    // the scene's light: the values ÷ P, the EV + log2 P.
    let pre_ev = match view.shown() {
        Shown::Exposed => frame.pre_ev(),
        _ => 0.0,
    };
    let metered = match (exposure, &hdr) {
        _ if gpu_metered => Some(Metered::from_bytes(exposure_readback.bytes()?)),
        // UV-space views are metered here, on the CPU.
        (Exposure::Metered, Some(values)) if uv => Some(meter::exposure(values)),
        _ => None,
    }
    .map(|m| m.pre_exposed_by(pre_ev));
    if let Some(values) = &mut hdr {
        let scale = (-pre_ev).exp2();
        for p in values.chunks_exact_mut(4) {
            p[..3].iter_mut().for_each(|c| *c *= scale);
        }
    }
    let ev = match (exposure, metered) {
        (Exposure::Given(ev), _) => ev,
        (Exposure::Metered, m) => m.map_or(0.0, |m| m.ev),
    };
    let mut rgba8 = match (&ldr_readback, &hdr) {
        (Some(b), _) => b.bytes()?.to_vec(),
        (None, Some(values)) => encode8(values, ev, &display),
        (None, None) => Vec::new(),
    };
    if flipped(scene, view) {
        flip_rows(&mut rgba8, w as usize * 4);
        if let Some(values) = &mut hdr {
            flip_rows(values, w as usize * 4);
        }
    }
    let (allocated_bytes, reserved_bytes) = ctx.allocator_bytes();
    let memory = MemoryUse {
        transient_pool_bytes: executor.pool_bytes(),
        allocated_bytes,
        reserved_bytes,
    };
    let run_setup = setup(
        scene,
        (opts, &ctx.info),
        view,
        frame.extracted_lights(),
        (ev, metered.is_some()),
    );
    let warmup = opts.warmup_frames()? as usize;
    let mut report = RunReport::new(&ctx.info, run_setup, (w, h), reports, warmup, memory);
    report.preroll_ms = preroll.as_millis() as u64;
    report.pipelines = frame
        .pipeline_times()
        .into_iter()
        .map(|(name, creation_ns)| PipelineTime { name, creation_ns })
        .collect();
    Ok(RenderOutput {
        width: w,
        height: h,
        view: view.clone(),
        reference: None,
        rgba8,
        hdr,
        exposure: ev,
        metered,
        report,
        plan,
    })
}

/// `--view reference`: the CPU reference of the direct view
/// (light::reference::render_view), exposed (given, or metered on the CPU) and
/// encoded as the GPU's image would be; its report has no passes.
fn reference(ctx: &Arc<Context>, scene: &Scene, opts: &RenderOptions) -> Result<RenderOutput> {
    let (w, h) = (scene.file.render.width, scene.file.render.height);
    let task = progress::Task::new("reference", h.into());
    let mut image = render_view_with(scene, w, h, &ReferenceSettings::default(), &|| task.add(1))?;
    drop(task);
    let post = PostSettings::resolve(&scene.file.render);
    let metered = (post.exposure == Exposure::Metered).then(|| meter::exposure(&image.rgba));
    let ev = match post.exposure {
        Exposure::Given(ev) => ev,
        Exposure::Metered => metered.map_or(0.0, |m| m.ev),
    };
    let rgba8 = encode8(&image.rgba, ev, &post.display);
    let rgba = std::mem::take(&mut image.rgba);
    let hdr = opts.hdr.then_some(rgba);
    let view = View::Screen(Screen::Reference);
    let setup = setup(scene, (opts, &ctx.info), &view, 0, (ev, metered.is_some()));
    Ok(RenderOutput {
        width: w,
        height: h,
        view,
        reference: Some(image),
        rgba8,
        hdr,
        exposure: ev,
        metered,
        report: RunReport::new(
            &ctx.info,
            setup,
            (w, h),
            Vec::new(),
            0,
            MemoryUse::default(),
        ),
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
            pipeline_statistics: true,
            calibrated_timestamps: false,
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
