//! The `render` command's library side: load the scene, upload it, build the
//! frame graph, run it for a number of frames, read the image back, and report
//! per-pass timings.

pub mod forward;
pub mod resources;

use crate::error::{Error, Result};
use crate::gpu::{Buffer, Context, ContextOptions, DeviceInfo, ImageDesc, MemoryLocation};
use crate::graph::upload::readback_pass;
use crate::graph::upload::upload_buffer;
use crate::graph::ImageHandle;
use crate::graph::{Access, Executor, Graph};
use crate::light::prefilter::{self, PrefilterPass};
use crate::light::sh_pass::{ShBuffers, ShPasses};
use crate::light::shadow::{ShadowPass, ShadowView};
use crate::post::tonemap::{Tonemap, LDR_FORMAT};
use crate::profile::RunReport;
use crate::scene::file::{Occlusion, SceneFile};
use crate::scene::{LightSource, Scene};
use crate::skin::blur::BlurChain;
use crate::skin::irradiance::IrradiancePass;
use crate::skin::shade::{ShadeImages, ShadeMode, ShadePass, ShadeSettings};
use crate::skin::stretch::StretchPass;
use crate::skin::{mean_stretch, SkinSettings};
use ash::vk;
use forward::{ForwardInputs, ForwardPipelines, FrameUniforms, HDR_FORMAT, MAX_LIGHTS};
use resources::{upload_env, upload_rgba8, MeshBuffers, Samplers};
use std::sync::Arc;

/// What `render` writes: the final image or one intermediate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// The final image: texture-space diffusion (+ specular when it lands).
    Final,
    /// The diffuse (subsurface) term alone.
    Diffuse,
    /// The Kelemen/Szirmay-Kalos specular term alone (the paper's Fig. 1).
    Specular,
    /// Direct diffuse shading in screen space, no scattering (for comparison).
    Direct,
    /// The per-vertex transfer's DC term relative to open sky (1 = unoccluded).
    Occlusion,
    /// UV-space irradiance (coverage-premultiplied, as stored).
    Irradiance,
    /// UV-space stretch map (texels per mm in R and G; alpha = coverage).
    Stretch,
    /// UV-space blur level 1..=6 (as stored).
    Blur(u8),
    /// The KS-prefiltered environment: its roughness levels stacked top to bottom
    /// (light::prefilter).
    Prefiltered,
}

impl View {
    pub fn parse(s: &str) -> Result<View> {
        Ok(match s {
            "final" => View::Final,
            "diffuse" => View::Diffuse,
            "specular" => View::Specular,
            "direct" => View::Direct,
            "occlusion" => View::Occlusion,
            "irradiance" => View::Irradiance,
            "stretch" => View::Stretch,
            "prefiltered" => View::Prefiltered,
            _ => match s.strip_prefix("blur").and_then(|k| k.parse::<u8>().ok()) {
                Some(k @ 1..=6) => View::Blur(k),
                _ => {
                    return Err(Error::Input(format!(
                    "unknown view {s:?}: final, diffuse, specular, direct, occlusion, irradiance, stretch, blur1..blur6, prefiltered"
                )))
                }
            },
        })
    }

    /// Whether the view is an intermediate texture rather than a screen image:
    /// read back as stored, without tone mapping.
    pub fn uv_space(self) -> bool {
        matches!(
            self,
            View::Irradiance | View::Stretch | View::Blur(_) | View::Prefiltered
        )
    }

    /// The size of the image the view reads back.
    fn size(self, screen: (u32, u32), irradiance_resolution: u32) -> (u32, u32) {
        match self {
            View::Prefiltered => (prefilter::WIDTH, prefilter::HEIGHT * prefilter::LEVELS),
            v if v.uv_space() => (irradiance_resolution, irradiance_resolution),
            _ => screen,
        }
    }
}

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
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            scene: SceneFile::default(),
            frames: 1,
            hdr: false,
            view: View::Final,
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

/// The shadow projection of each light the frame uses (`None`: unshadowed).
fn shadow_views(scene: &Scene) -> Vec<Option<ShadowView>> {
    let (lo, hi) = scene.mesh.bounds().unwrap_or_default();
    let (centre, radius) = (0.5 * (lo + hi), 0.5 * lo.distance(hi));
    let res = scene.file.render.shadow_resolution;
    if scene.lights.len() > MAX_LIGHTS {
        log::warn!(
            "only the first {MAX_LIGHTS} of {} lights are used",
            scene.lights.len()
        );
    }
    scene
        .lights
        .iter()
        .take(MAX_LIGHTS)
        .map(|l| {
            let view = l
                .shadow
                .then(|| ShadowView::fit(l.source, centre, radius, res))
                .flatten();
            if l.shadow && view.is_none() {
                log::warn!(
                    "{:?} is inside the mesh's bounding sphere (radius {radius:.0} mm): \
                     one shadow map cannot hold every direction; it casts no shadow",
                    l.source
                );
            }
            view
        })
        .collect()
}

/// The frame's uniforms: camera, environment rotation and intensity, lights and
/// their shadow projections (`views`, from [`shadow_views`]), exposure.
fn frame_uniforms(scene: &Scene, aspect: f32, views: &[Option<ShadowView>]) -> FrameUniforms {
    let vp = scene.camera.view_projection(aspect);
    let env = &scene.file.environment;
    let mut u = FrameUniforms {
        view_proj: vp.to_cols_array_2d(),
        inv_view_proj: vp.inverse().to_cols_array_2d(),
        camera_pos: scene.camera.position.extend(1.0).into(),
        light_vec: [[0.0; 4]; MAX_LIGHTS],
        light_color: [[0.0; 4]; MAX_LIGHTS],
        light_shadow: [[[0.0; 4]; 4]; MAX_LIGHTS],
        env: [
            env.rotation_deg.to_radians(),
            env.intensity,
            0.0,
            if scene.file.skin.occlusion == Occlusion::Off {
                0.0
            } else {
                1.0
            },
        ],
        params: [scene.exposure(), 0.0, 0.0, 0.0],
    };
    let tiles = views.iter().flatten().count();
    let mut tile = 0;
    for (i, (l, view)) in scene.lights.iter().zip(views).enumerate() {
        u.light_vec[i] = match l.source {
            LightSource::Directional(d) => d.extend(0.0),
            LightSource::Point(p) => p.extend(1.0),
        }
        .into();
        u.light_color[i] = l.irradiance.extend(0.0).into();
        if let Some(v) = view {
            u.light_color[i][3] = v.texel_mm;
            u.light_shadow[i] = v.atlas_matrix(tile, tiles).to_cols_array_2d();
            tile += 1;
        }
        u.env[2] = (i + 1) as f32;
    }
    u
}

/// GPU state shared by every frame of a render: uploaded scene and pipelines.
struct Frame {
    inputs: Arc<ForwardInputs>,
    forward: ForwardPipelines,
    stretch: StretchPass,
    irradiance: IrradiancePass,
    blur: BlurChain,
    shade: ShadePass,
    shadow: ShadowPass,
    /// The shadowed lights' projections, in atlas tile order.
    shadow_views: Vec<ShadowView>,
    shadow_resolution: u32,
    prefilter: PrefilterPass,
    tonemap: Tonemap,
    sh: ShPasses,
    sh_buffers: ShBuffers,
    skin: SkinSettings,
    constant_stretch: Option<f32>,
    exposure: f32,
}

impl Frame {
    fn new(ctx: &Arc<Context>, scene: &Scene) -> Result<Self> {
        let (w, h) = (scene.file.render.width, scene.file.render.height);
        let samplers = Arc::new(Samplers::new(ctx)?);
        let views = shadow_views(scene);
        let shadow_res = scene.file.render.shadow_resolution;
        let tiles = views.iter().flatten().count() as u32;
        check_target(&ctx.info, shadow_res * tiles.max(1), shadow_res).map_err(|e| {
            Error::Input(format!(
                "shadow atlas of {tiles} light(s) at render.shadow_resolution = {shadow_res}: {e}"
            ))
        })?;
        let uniforms = frame_uniforms(scene, w as f32 / h as f32, &views);
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
            transfer: upload_buffer(
                ctx,
                "transfer",
                bytemuck::cast_slice(
                    &crate::light::occlusion::transfer_for(
                        ctx,
                        &scene.mesh,
                        scene.file.skin.occlusion,
                    )?
                    .coeffs,
                ),
                Access::ShaderBufferRead,
            )?,
            specular: upload_rgba8(ctx, "specular map", &scene.specular)?,
            roughness: upload_rgba8(ctx, "roughness map", &scene.roughness)?,
            regions: upload_rgba8(ctx, "region map", &scene.regions)?,
            roughness_map: scene.file.textures.roughness.is_some(),
            tables: crate::skin::tables::SpecularTables::new(
                ctx,
                &scene.file.skin.regions,
                samplers.linear.clone(),
                samplers.nearest.clone(),
            )?,
            env: upload_env(ctx, &scene.env)?,
            env_sampler: if ctx.supports_linear_filter(vk::Format::R32G32B32A32_SFLOAT) {
                samplers.linear.clone()
            } else {
                samplers.nearest.clone()
            },
            samplers: samplers.clone(),
        });
        let skin =
            SkinSettings::from_scene(&scene.file.skin, scene.file.render.irradiance_resolution);
        skin.profile
            .validate()
            .map_err(|e| Error::Input(format!("skin profile: {e}")))?;
        let constant_stretch =
            (!skin.stretch_correction).then(|| mean_stretch(&scene.mesh, skin.resolution));
        Ok(Self {
            forward: ForwardPipelines::new(ctx)?,
            stretch: StretchPass::new(ctx)?,
            irradiance: IrradiancePass::new(ctx)?,
            blur: BlurChain::new(ctx, &skin.kernel, samplers.linear.clone())?,
            shade: ShadePass::new(ctx)?,
            shadow: ShadowPass::new(ctx)?,
            shadow_views: views.into_iter().flatten().collect(),
            shadow_resolution: scene.file.render.shadow_resolution,
            prefilter: PrefilterPass::new(ctx, inputs.env_sampler.clone())?,
            tonemap: Tonemap::new(ctx, samplers.nearest.clone())?,
            sh: ShPasses::new(ctx, samplers.nearest.clone())?,
            sh_buffers: ShBuffers::new(
                ctx,
                &inputs.env,
                scene.file.environment.rotation_deg,
                scene.file.environment.intensity,
            )?,
            inputs,
            skin,
            constant_stretch,
            exposure: scene.exposure(),
        })
    }

    /// The occlusion view shows a ratio in [0, 1]: no exposure.
    fn exposure_for(&self, view: View) -> f32 {
        if view == View::Occlusion {
            0.0
        } else {
            self.exposure
        }
    }

    /// Builds the frame graph; returns the image to read back (and its size)
    /// for `view`, and for screen views the tone-mapped 8-bit image.
    /// `first`: the render's first frame (it also prefilters the environment).
    fn graph(
        &self,
        g: &mut Graph,
        view: View,
        (w, h): (u32, u32),
        first: bool,
    ) -> (ImageHandle, Option<ImageHandle>) {
        let mut hdr = g.create_image("hdr", ImageDesc::new(w, h, HDR_FORMAT));
        let sh = self.sh.passes(
            g,
            &self.inputs.env,
            &self.sh_buffers,
            Access::FragmentBufferRead,
        );
        if view == View::Prefiltered {
            return (self.prefilter.pass(g, &self.inputs.env, first), None);
        }
        let shadows = self.shadow.pass(
            g,
            &self.inputs.mesh,
            &self.shadow_views,
            self.shadow_resolution,
        );
        if let View::Direct | View::Occlusion = view {
            let (pipeline, name) = match view {
                View::Direct => (&self.forward.direct, "direct"),
                _ => (&self.forward.occlusion, "occlusion"),
            };
            forward::background(g, &self.forward, &self.inputs, &mut hdr);
            forward::direct(g, pipeline, name, &self.inputs, &sh, &shadows, &mut hdr);
        } else {
            let res = self.skin.resolution;
            let mesh = &self.inputs.mesh;
            let stretch = self.stretch.pass(g, mesh, res, self.constant_stretch);
            let irradiance =
                self.irradiance
                    .pass(g, &self.inputs, &sh, &shadows, res, self.skin.mix);
            if view == View::Stretch {
                return (stretch, None);
            }
            if view == View::Irradiance {
                return (irradiance, None);
            }
            let levels = self
                .blur
                .chain(g, &irradiance, &stretch, &self.skin.profile);
            if let View::Blur(k) = view {
                let mut irr = levels.irradiance;
                return (irr.swap_remove(k as usize - 1), None);
            }
            let specular_env = self.prefilter.pass(g, &self.inputs.env, first);
            forward::background(g, &self.forward, &self.inputs, &mut hdr);
            let weights: Vec<_> = self
                .skin
                .profile
                .gaussians
                .iter()
                .map(|g| g.weights)
                .collect();
            let weights: [glam::Vec3; 6] = weights.try_into().unwrap_or([glam::Vec3::ZERO; 6]);
            let mode = match view {
                View::Diffuse => ShadeMode::Diffuse,
                View::Specular => ShadeMode::Specular,
                _ => ShadeMode::Full,
            };
            let settings = ShadeSettings {
                weights,
                mix: self.skin.mix,
                mode,
            };
            self.shade.pass(
                g,
                &self.inputs,
                ShadeImages {
                    levels: &levels.irradiance,
                    shadows: &shadows,
                    specular_env: &specular_env,
                },
                settings,
                &mut hdr,
            );
        }
        let mut ldr = g.create_image("ldr", ImageDesc::new(w, h, LDR_FORMAT));
        self.tonemap
            .pass(g, &hdr, &mut ldr, self.exposure_for(view));
        (hdr, Some(ldr))
    }
}

pub fn render_scene(
    ctx: &Arc<Context>,
    scene: &Scene,
    opts: &RenderOptions,
) -> Result<RenderOutput> {
    let screen = (scene.file.render.width, scene.file.render.height);
    check_target(&ctx.info, screen.0, screen.1)?;
    let res = scene.file.render.irradiance_resolution;
    check_target(&ctx.info, res, res)?;
    if scene.file.skin.profile.len() != 6 {
        return Err(Error::Input(format!(
            "skin.profile has {} Gaussians; the blur chain and final shading use six",
            scene.file.skin.profile.len()
        )));
    }
    let frame = Frame::new(ctx, scene)?;
    let (w, h) = opts.view.size(screen, res);
    let readback = |name: &str, bytes_per_texel: u64| -> Result<Arc<Buffer>> {
        Ok(Arc::new(Buffer::new(
            ctx,
            name,
            w as u64 * h as u64 * bytes_per_texel,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?))
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
    for i in 0..opts.frames.max(1) {
        let mut g = Graph::new();
        let (hdr, ldr) = frame.graph(&mut g, opts.view, screen, i == 0);
        if let (Some(ldr), Some(buf)) = (&ldr, &ldr_readback) {
            readback_pass(&mut g, ldr, buf);
        }
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
    let exposure = frame.exposure_for(opts.view);
    // Screen views: linear radiance × 2^exposure. UV views: the values as stored.
    let hdr = match &hdr_readback {
        Some(b) => {
            let scale = if uv { 1.0 } else { exposure.exp2() };
            Some(
                mapped(b)?
                    .chunks_exact(2)
                    .map(|c| half::f16::from_le_bytes([c[0], c[1]]).to_f32() * scale)
                    .collect::<Vec<f32>>(),
            )
        }
        None => None,
    };
    let rgba8 = match (&ldr_readback, &hdr) {
        (Some(b), _) => mapped(b)?,
        (None, Some(values)) => crate::output::encode_srgb8(values, exposure),
        (None, None) => Vec::new(),
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
