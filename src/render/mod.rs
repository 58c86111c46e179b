//! The `render` command's library side: load the scene, upload it, build the
//! frame graph, run it for a number of frames, read the image back, and report
//! per-pass timings.

pub mod forward;
pub mod resources;

use crate::error::{Error, Result};
use crate::gpu::{Buffer, Context, ContextOptions, DeviceInfo, ImageDesc, MemoryLocation};
use crate::graph::upload::upload_buffer;
use crate::graph::{Access, Executor, Graph};
use crate::light::sh;
use crate::post::tonemap::{Tonemap, LDR_FORMAT};
use crate::profile::RunReport;
use crate::scene::file::SceneFile;
use crate::scene::Scene;
use crate::testscene::readback_pass;
use ash::vk;
use forward::{ForwardInputs, ForwardPipelines, FrameUniforms, HDR_FORMAT, MAX_LIGHTS};
use resources::{upload_env, upload_rgba8, MeshBuffers, Samplers};
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
    pub context: ContextOptions,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            scene: SceneFile::default(),
            frames: 1,
            hdr: false,
            context: ContextOptions::from_env(),
        }
    }
}

pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
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

/// The frame's uniforms: camera, SH lighting (rotated and scaled), lights, exposure.
pub fn frame_uniforms(scene: &Scene, aspect: f32) -> FrameUniforms {
    let vp = scene.camera.view_projection(aspect);
    let env = &scene.file.environment;
    let coeffs = sh::rotate_y(&sh::project(&scene.env), env.rotation_deg);
    let mut u = FrameUniforms {
        view_proj: vp.to_cols_array_2d(),
        inv_view_proj: vp.inverse().to_cols_array_2d(),
        camera_pos: scene.camera.position.extend(1.0).into(),
        sh: coeffs.map(|c| (c * env.intensity).extend(0.0).into()),
        light_dir: [[0.0; 4]; MAX_LIGHTS],
        light_color: [[0.0; 4]; MAX_LIGHTS],
        env: [env.rotation_deg.to_radians(), env.intensity, 0.0, 0.0],
        params: [scene.exposure(), 0.0, 0.0, 0.0],
    };
    if scene.lights.len() > MAX_LIGHTS {
        log::warn!(
            "only the first {MAX_LIGHTS} of {} lights are used",
            scene.lights.len()
        );
    }
    for (i, l) in scene.lights.iter().take(MAX_LIGHTS).enumerate() {
        u.light_dir[i] = l.direction.extend(0.0).into();
        u.light_color[i] = l.irradiance.extend(0.0).into();
        u.env[2] = (i + 1) as f32;
    }
    u
}

pub fn render_scene(
    ctx: &Arc<Context>,
    scene: &Scene,
    opts: &RenderOptions,
) -> Result<RenderOutput> {
    let (w, h) = (scene.file.render.width, scene.file.render.height);
    check_target(&ctx.info, w, h)?;
    let samplers = Arc::new(Samplers::new(ctx)?);
    let uniforms = frame_uniforms(scene, w as f32 / h as f32);
    let inputs = Arc::new(ForwardInputs {
        uniforms: upload_buffer(
            ctx,
            "frame uniforms",
            bytemuck::bytes_of(&uniforms),
            Access::UniformRead,
        )?,
        mesh: Arc::new(MeshBuffers::upload(ctx, &scene.mesh)?),
        albedo: upload_rgba8(ctx, "albedo", &scene.albedo)?,
        normal: upload_rgba8(ctx, "normal map", &scene.normal)?,
        env: upload_env(ctx, &scene.env)?,
        env_sampler: if ctx.supports_linear_filter(vk::Format::R32G32B32A32_SFLOAT) {
            samplers.linear.clone()
        } else {
            samplers.nearest.clone()
        },
        samplers: samplers.clone(),
    });
    let forward = ForwardPipelines::new(ctx)?;
    let tonemap = Tonemap::new(ctx, samplers.nearest.clone())?;
    let readback = |bytes_per_texel: u64| -> Result<Arc<Buffer>> {
        Ok(Arc::new(Buffer::new(
            ctx,
            "readback",
            w as u64 * h as u64 * bytes_per_texel,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?))
    };
    let ldr_readback = readback(4)?;
    let hdr_readback = if opts.hdr { Some(readback(8)?) } else { None };
    let exposure = scene.exposure();
    log::info!("exposure {exposure:.2} EV");

    let mut executor = Executor::new(ctx, 2)?;
    let mut reports = Vec::new();
    let mut plan = String::new();
    for _ in 0..opts.frames.max(1) {
        let mut g = Graph::new();
        let mut hdr = g.create_image("hdr", ImageDesc::new(w, h, HDR_FORMAT));
        forward::passes(&mut g, &forward, &inputs, &mut hdr);
        let mut ldr = g.create_image("ldr", ImageDesc::new(w, h, LDR_FORMAT));
        tonemap.pass(&mut g, &hdr, &mut ldr, exposure);
        readback_pass(&mut g, &ldr, &ldr_readback);
        if let Some(buf) = &hdr_readback {
            readback_pass(&mut g, &hdr, buf);
        }
        let compiled = executor.compile(g)?;
        plan = compiled.plan.to_string();
        reports.extend(executor.submit(compiled)?);
    }
    reports.extend(executor.finish()?);
    let mapped = |b: &Buffer| {
        b.mapped()
            .map(<[u8]>::to_vec)
            .ok_or_else(|| Error::Graph("readback buffer is not host-visible".into()))
    };
    let rgba8 = mapped(&ldr_readback)?;
    let hdr = match &hdr_readback {
        Some(b) => {
            let scale = exposure.exp2();
            Some(
                mapped(b)?
                    .chunks_exact(2)
                    .map(|c| half::f16::from_le_bytes([c[0], c[1]]).to_f32() * scale)
                    .collect(),
            )
        }
        None => None,
    };
    let report = RunReport::new(&ctx.info, w, h, reports, executor.pool_bytes());
    Ok(RenderOutput {
        width: w,
        height: h,
        rgba8,
        hdr,
        report,
        plan,
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
