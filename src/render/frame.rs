//! One frame of the `render` command: the GPU state shared by every frame of a
//! render (uploaded scene, pipelines) and the frame graph, pass by pass, for the
//! final image or a debug view.

use super::ruler::Ruler;
use super::view::Shown;
use super::View;
use crate::error::{Error, Result};
use crate::frame::{
    upload_env, upload_rgba8, FrameInputs, FrameUniforms, MeshBuffers, Samplers, ShaderVariant,
    HDR_FORMAT, MAX_LIGHTS,
};
use crate::gpu::{Context, ImageDesc};
use crate::graph::upload::upload_buffer;
use crate::graph::{Access, BufferHandle, Graph, ImageHandle};
use crate::light::direct::{DirectPass, DirectView};
use crate::light::extract::{extract, ExtractedLight};
use crate::light::prefilter::PrefilterPass;
use crate::light::sh_pass::{ShBuffers, ShPasses};
use crate::light::shadow::{atlas_grid, lobe_widening, ShadowPass, ShadowView};
use crate::light::skybox::SkyboxPass;
use crate::light::visibility::VisibilityPass;
use crate::post::debug::{DebugPass, DebugView, DepthRange};
use crate::post::glow::Glow;
use crate::post::meter::Meter;
use crate::post::tonemap::{Tonemap, LDR_FORMAT};
use crate::post::{Display, Exposure, PostSettings};
use crate::scene::file::{Occlusion, ToneCurve};
use crate::scene::texture::Texture;
use crate::scene::{Light, LightSource, Scene};
use crate::skin::blur::BlurChain;
use crate::skin::chain::{self, Level};
use crate::skin::irradiance::IrradiancePass;
use crate::skin::shade::{ShadeImages, ShadeMode, ShadePass, ShadeSettings};
use crate::skin::specular;
use crate::skin::stretch::StretchMaps;
use crate::skin::tables::SpecularTables;
use crate::skin::{mean_stretch, SkinSettings};
use ash::vk;
use std::sync::Arc;

/// The lights the frame uses, at most [`MAX_LIGHTS`]: the scene's, then the
/// environment's bright sources (`extracted`, in the map's frame) as shadowed
/// directional lights of their power, turned and scaled like the environment.
fn frame_lights(scene: &Scene, extracted: &[ExtractedLight]) -> Vec<Light> {
    let env = &scene.file.environment;
    let all: Vec<Light> = scene
        .lights
        .iter()
        .copied()
        .chain(extracted.iter().map(|x| Light {
            source: LightSource::Directional(x.world_direction(env.rotation_deg)),
            // A uniform cap of radius α delivers (1 + cos α)/2 of its ∫L dω to a
            // surface facing it.
            irradiance: x.power * env.intensity * 0.5 * (1.0 + x.angular_radius_rad.cos()),
            shadow: true,
            angular_radius: x.angular_radius_rad,
        }))
        .collect();
    if all.len() > MAX_LIGHTS {
        log::warn!(
            "only the first {MAX_LIGHTS} of {} lights ({} from the environment) are used",
            all.len(),
            extracted.len()
        );
    }
    all.into_iter().take(MAX_LIGHTS).collect()
}

/// Where the depth view's 1 and 0 lie: the mesh's nearest and farthest vertex
/// along the camera's axis.
fn depth_range(scene: &Scene) -> DepthRange {
    let camera = &scene.camera;
    DepthRange::of(
        camera.position,
        (camera.target - camera.position).normalize_or_zero(),
        &scene.mesh.positions,
    )
}

/// The shadow projection of each light (`None`: unshadowed).
fn shadow_views(scene: &Scene, lights: &[Light]) -> Vec<Option<ShadowView>> {
    let (lo, hi) = scene.mesh.bounds().unwrap_or_default();
    let (centre, radius) = (0.5 * (lo + hi), 0.5 * lo.distance(hi));
    let res = scene.file.render.shadow_resolution;
    lights
        .iter()
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
/// their shadow projections (`views`, from [`shadow_views`]).
fn frame_uniforms(
    scene: &Scene,
    lights: &[Light],
    aspect: f32,
    views: &[Option<ShadowView>],
) -> FrameUniforms {
    let vp = scene.camera.view_projection(aspect);
    let env = &scene.file.environment;
    let tiles = views.iter().flatten().count();
    let mut u = FrameUniforms {
        view_proj: vp.to_cols_array_2d(),
        inv_view_proj: vp.inverse().to_cols_array_2d(),
        camera_pos: scene.camera.position.extend(1.0).into(),
        light_vec: [[0.0; 4]; MAX_LIGHTS],
        light_color: [[0.0; 4]; MAX_LIGHTS],
        light_shadow: [[[0.0; 4]; 4]; MAX_LIGHTS],
        light_params: [[0.0; 4]; MAX_LIGHTS],
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
        params: [
            0.0,
            0.5 / specular::map_mean(
                &scene.mesh.positions,
                &scene.mesh.uvs,
                &scene.mesh.indices,
                (
                    scene.specular.width,
                    scene.specular.height,
                    &scene.specular.rgba8,
                ),
            ),
            atlas_grid(tiles).0 as f32,
            atlas_grid(tiles).1 as f32,
        ],
    };
    let mut tile = 0;
    for (i, (l, view)) in lights.iter().zip(views).enumerate() {
        u.light_vec[i] = match l.source {
            LightSource::Directional(d) => d.extend(0.0),
            LightSource::Point(p) => p.extend(1.0),
        }
        .into();
        u.light_color[i] = l.irradiance.extend(0.0).into();
        u.light_params[i][0] = l.angular_radius.tan();
        u.light_params[i][2] = lobe_widening(l.angular_radius);
        if let Some(v) = view {
            u.light_color[i][3] = v.texel_mm;
            u.light_shadow[i] = v.atlas_matrix(tile, tiles).to_cols_array_2d();
            u.light_params[i][1] = v.depth_range_mm;
            tile += 1;
        }
        u.env[2] = (i + 1) as f32;
    }
    u
}

/// GPU state shared by every frame of a render: uploaded scene and pipelines.
pub(super) struct Frame {
    inputs: FrameInputs,
    tables: SpecularTables,
    skybox: SkyboxPass,
    direct: DirectPass,
    stretch: StretchMaps,
    irradiance: IrradiancePass,
    blur: BlurChain,
    shade: ShadePass,
    shadow: ShadowPass,
    visibility: VisibilityPass,
    /// The frame's lights (the scene's, then the extracted sources) and each
    /// one's shadow projection: the uniforms are made from them.
    lights: Vec<Light>,
    views: Vec<Option<ShadowView>>,
    prefilter: PrefilterPass,
    debug: DebugPass,
    /// Where the depth view's 1 and 0 lie.
    depth_range: DepthRange,
    meter: Meter,
    glow: Glow,
    tonemap: Tonemap,
    sh: ShPasses,
    sh_buffers: ShBuffers,
    skin: SkinSettings,
    /// The blur levels' resolutions (skin::chain).
    levels: Vec<Level>,
    /// Timed beside the chain, over the irradiance (render --ruler).
    ruler: Option<Ruler>,
    /// render.skybox: draw the environment behind the head.
    skybox_on: bool,
    pub(super) post: PostSettings,
    /// Bright sources taken out of the environment as lights (in the map's frame).
    pub(super) extracted: Vec<ExtractedLight>,
}

impl Frame {
    /// `albedo`: the scene's, or the test texture (`--view test-texture`).
    pub(super) fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        albedo: &Texture,
        skin: SkinSettings,
        ruler: bool,
    ) -> Result<Self> {
        let (w, h) = (scene.file.render.width, scene.file.render.height);
        let samplers = Arc::new(Samplers::new(ctx)?);
        // The environment's bright sources become lights; the rest lights the
        // skin through SH9 and the prefilter, while the skybox shows it whole.
        let extraction = extract(&scene.env, scene.file.environment.lights);
        for (i, l) in extraction.lights.iter().enumerate() {
            log::info!(
                "environment light {i}: {:.1}% of the map's energy, {:.2}° across",
                100.0 * l.share,
                2.0 * l.angular_radius_rad.to_degrees()
            );
        }
        let lights = frame_lights(scene, &extraction.lights);
        let views = shadow_views(scene, &lights);
        let shadow_res = scene.file.render.shadow_resolution;
        let tiles = views.iter().flatten().count();
        let (cols, rows) = atlas_grid(tiles);
        super::check_target(&ctx.info, shadow_res * cols, shadow_res * rows).map_err(|e| {
            Error::Input(format!(
                "shadow atlas of {tiles} light(s) at render.shadow_resolution = {shadow_res}: {e}"
            ))
        })?;
        let uniforms = frame_uniforms(scene, &lights, w as f32 / h as f32, &views);
        let env = upload_env(ctx, &scene.env)?;
        // Bit i set where light i has `has`.
        let bits = |has: &dyn Fn(usize) -> bool| {
            (0..lights.len())
                .filter(|&i| has(i))
                .fold(0, |b, i| b | 1 << i)
        };
        let inputs = FrameInputs {
            uniforms: upload_buffer(
                ctx,
                "frame uniforms",
                bytemuck::bytes_of(&uniforms),
                Access::UniformRead,
            )?,
            mesh: Arc::new(MeshBuffers::upload(ctx, &scene.mesh)?),
            albedo: upload_rgba8(ctx, "albedo", albedo)?,
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
            variant: ShaderVariant {
                lights: lights.len() as u32,
                occlusion: scene.file.skin.occlusion != Occlusion::Off,
                roughness_map: scene.file.textures.roughness.is_some(),
                shadowed: bits(&|i| views[i].is_some()),
                // Soft shadows where the map can take them: directional (linear depth).
                soft: bits(&|i| {
                    views[i].is_some()
                        && lights[i].angular_radius > 0.0
                        && matches!(lights[i].source, LightSource::Directional(_))
                }),
            },
            lighting_env: if extraction.lights.is_empty() {
                env.clone()
            } else {
                upload_env(ctx, &extraction.residual)?
            },
            env,
            env_sampler: if ctx.supports_linear_filter(vk::Format::R32G32B32A32_SFLOAT) {
                samplers.linear.clone()
            } else {
                samplers.nearest.clone()
            },
            samplers: samplers.clone(),
        };
        let tables = SpecularTables::new(
            ctx,
            &skin.regions,
            &scene.regions,
            samplers.linear.clone(),
            samplers.nearest.clone(),
        )?;
        let res = skin.resolution;
        let texels_per_mm = mean_stretch(&scene.mesh, res);
        let constant_stretch = (!skin.stretch_correction).then_some(texels_per_mm);
        let levels = chain::plan(&skin.profile, skin.chain, res, texels_per_mm);
        log::info!(
            "{:?} chain at {res}² ({texels_per_mm:.2} texels/mm): levels {:?}",
            skin.chain,
            levels
        );
        let depth_range = depth_range(scene);
        Ok(Self {
            tables,
            skybox: SkyboxPass::new(ctx)?,
            direct: DirectPass::new(ctx, &inputs.variant)?,
            stretch: StretchMaps::new(ctx, res, &skin.profile, constant_stretch)?,
            irradiance: IrradiancePass::new(ctx, &inputs.variant)?,
            blur: BlurChain::new(ctx, &skin.kernel, samplers.linear.clone())?,
            shade: ShadePass::new(ctx, &inputs.variant)?,
            shadow: ShadowPass::new(ctx, &views, shadow_res)?,
            visibility: VisibilityPass::new(ctx, &inputs.variant, res)?,
            views,
            lights,
            prefilter: PrefilterPass::new(ctx, inputs.env_sampler.clone())?,
            debug: DebugPass::new(ctx, &scene.regions)?,
            depth_range,
            meter: Meter::new(ctx, samplers.nearest.clone())?,
            glow: Glow::new(ctx, samplers.nearest.clone(), samplers.linear.clone())?,
            tonemap: Tonemap::new(ctx, samplers.nearest.clone())?,
            sh: ShPasses::new(ctx, samplers.nearest.clone())?,
            sh_buffers: ShBuffers::new(
                ctx,
                &inputs.lighting_env,
                scene.file.environment.rotation_deg,
                scene.file.environment.intensity,
            )?,
            inputs,
            skin,
            levels,
            ruler: if ruler {
                Some(Ruler::new(ctx, samplers.nearest.clone())?)
            } else {
                None
            },
            skybox_on: scene.file.render.skybox,
            post: PostSettings::resolve(&scene.file.render),
            extracted: extraction.lights,
        })
    }

    /// Moves the camera to `scene.camera` at the aspect of `scene.file.render`'s
    /// size: the frame's uniforms and the depth view's range are made again.
    pub(super) fn set_camera(&mut self, ctx: &Arc<Context>, scene: &Scene) -> Result<()> {
        self.depth_range = depth_range(scene);
        let (w, h) = (scene.file.render.width, scene.file.render.height);
        let uniforms = frame_uniforms(scene, &self.lights, w as f32 / h as f32, &self.views);
        self.inputs.uniforms = upload_buffer(
            ctx,
            "frame uniforms",
            bytemuck::bytes_of(&uniforms),
            Access::UniformRead,
        )?;
        Ok(())
    }

    /// Turns the environment to `scene.file.environment.rotation_deg`: the SH
    /// transform, the extracted sources' directions, their shadow projections
    /// and the uniforms are made again. What `kept` holds of them (the SH, the
    /// shadows) is to be computed again.
    pub(super) fn set_rotation(
        &mut self,
        ctx: &Arc<Context>,
        scene: &Scene,
        kept: &mut Kept,
    ) -> Result<()> {
        let env = &scene.file.environment;
        self.sh_buffers = ShBuffers::new(
            ctx,
            &self.inputs.lighting_env,
            env.rotation_deg,
            env.intensity,
        )?;
        self.lights = frame_lights(scene, &self.extracted);
        self.views = shadow_views(scene, &self.lights);
        self.shadow.set_views(&self.views);
        (kept.sh, kept.shadows) = (false, false);
        self.set_camera(ctx, scene)
    }

    /// The post-processing settings (exposure, tone curve, glow, background)
    /// replaced: the graph reads them when it is built.
    pub(super) fn set_post(&mut self, post: PostSettings) {
        self.post = post;
    }

    /// A UV-space view's image (stored values) encoded for display as the view
    /// is shown (`render::view::Shown`).
    pub(super) fn encode(&self, g: &mut Graph, image: ImageHandle, view: View) -> ImageHandle {
        let images = self.post(g, view, image);
        images.ldr.expect("post makes the 8-bit image")
    }

    /// The exposure and display of `view` (render::view::Shown).
    pub(super) fn display(&self, view: View) -> (Exposure, Display) {
        let display = self.post.display;
        match view.shown() {
            Shown::Exposed => (self.post.exposure, display),
            Shown::Fraction => (
                Exposure::Given(0.0),
                Display {
                    curve: ToneCurve::Linear,
                    ..display
                },
            ),
            Shown::Data => (Exposure::Given(0.0), Display::data(display.background)),
        }
    }

    /// Builds the frame graph for `view` at `(w, h)` (UV-space views: their
    /// image as stored). What `kept` says is not yet computed, and the view
    /// needs, the frame computes, and marks it computed.
    pub(super) fn graph(
        &self,
        g: &mut Graph,
        view: View,
        (w, h): (u32, u32),
        kept: &mut Kept,
    ) -> FrameImages {
        let mut hdr = g.create_image("hdr", ImageDesc::new(w, h, HDR_FORMAT));
        let sh = self.sh.passes(
            g,
            &self.inputs.lighting_env,
            &self.sh_buffers,
            Access::UniformRead,
            !std::mem::replace(&mut kept.sh, true),
        );
        let mut prefiltered = |g: &mut Graph| {
            let first = !std::mem::replace(&mut kept.prefiltered, true);
            self.prefilter.pass(g, &self.inputs.lighting_env, first)
        };
        if view == View::Prefiltered {
            return FrameImages::uv(prefiltered(g));
        }
        let draw = !std::mem::replace(&mut kept.shadows, true);
        let shadows = self.shadow.pass(g, &self.inputs.mesh, draw);
        let soft = self.visibility.pass(g, &self.inputs, &shadows, draw);
        let debug = match view {
            View::Depth => Some(DebugView::Depth),
            View::Normals => Some(DebugView::Normals),
            View::Albedo => Some(DebugView::Albedo),
            View::Regions => Some(DebugView::Regions),
            _ => None,
        };
        if let Some(debug) = debug {
            self.skybox.pass(g, &self.inputs, &mut hdr, false);
            self.debug
                .pass(g, debug, &self.inputs, self.depth_range, &mut hdr);
        } else if let View::Direct | View::Occlusion = view {
            let direct = match view {
                View::Direct => DirectView::Shading,
                _ => DirectView::Occlusion,
            };
            self.skybox.pass(g, &self.inputs, &mut hdr, self.skybox_on);
            self.direct
                .pass(g, direct, &self.inputs, &sh, &shadows, &soft, &mut hdr);
        } else {
            let res = self.skin.resolution;
            let mesh = &self.inputs.mesh;
            let first = !std::mem::replace(&mut kept.stretch, true);
            let mut stretch = self.stretch.pass(g, mesh, &self.blur, first);
            let irradiance = self.irradiance.pass(
                g,
                &self.inputs,
                &self.tables,
                &sh,
                (&shadows, &soft),
                res,
                self.skin.mix,
            );
            if let View::Stretch(k) = view {
                return FrameImages::uv(stretch.swap_remove(k as usize));
            }
            if view == View::Irradiance {
                return FrameImages::uv(irradiance);
            }
            if let Some(r) = &self.ruler {
                r.passes(g, &irradiance);
            }
            let mut blurred = self.blur.chain(g, &irradiance, &stretch, &self.levels);
            if let View::Blur(k) = view {
                // Level k is the last blur at or before it, or the irradiance.
                let made = self.levels[..k as usize]
                    .iter()
                    .filter(|l| l.sigma_mm.is_some())
                    .count();
                return FrameImages::uv(match made {
                    0 => irradiance,
                    n => blurred.swap_remove(n - 1),
                });
            }
            let specular_env = prefiltered(g);
            self.skybox.pass(g, &self.inputs, &mut hdr, self.skybox_on);
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
                blur_amount: self.skin.blur_amount,
                mode,
            };
            self.shade.pass(
                g,
                &self.inputs,
                &self.tables,
                ShadeImages {
                    irradiance: &irradiance,
                    levels: &BlurChain::select(&irradiance, &blurred, &self.levels),
                    shadows: &shadows,
                    soft_visibility: &soft,
                    specular_env: &specular_env,
                },
                settings,
                &mut hdr,
            );
        }
        self.post(g, view, hdr)
    }

    /// Metering, glow and tone mapping of a screen view's `hdr`.
    fn post(&self, g: &mut Graph, view: View, hdr: ImageHandle) -> FrameImages {
        let (exposure, display) = self.display(view);
        let exposed = view.shown() == Shown::Exposed;
        // Metered before the glow: the exposure is the skin's.
        let metered = (exposure == Exposure::Metered).then(|| self.meter.pass(g, &hdr));
        let hdr = match self.post.glow {
            Some(intensity) if exposed => self.glow.pass(g, &hdr, intensity),
            _ => hdr,
        };
        let (w, h) = (hdr.desc.width, hdr.desc.height);
        let mut ldr = g.create_image("ldr", ImageDesc::new(w, h, LDR_FORMAT));
        let unwritten;
        let result = match &metered {
            Some(m) => m,
            None => {
                unwritten = self.meter.result(g);
                &unwritten
            }
        };
        self.tonemap
            .pass(g, &hdr, result, &mut ldr, exposure, &display);
        FrameImages {
            image: hdr,
            ldr: Some(ldr),
            metered,
        }
    }
}

/// What a render computes once and keeps between its frames (the scene, the
/// lights and the mesh do not change within it): each is computed by the first
/// frame whose view needs it.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Kept {
    /// The environment's SH coefficients (light::sh_pass).
    sh: bool,
    /// The KS-prefiltered environment (light::prefilter).
    prefiltered: bool,
    /// The shadow atlas and the soft lights' visibility (light::shadow, light::visibility).
    shadows: bool,
    /// The stretch maps (skin::stretch).
    stretch: bool,
}

/// The images a frame graph ends with.
pub(super) struct FrameImages {
    /// A screen view's HDR image as tone-mapped (after the glow), or a UV-space
    /// view's image as stored.
    pub image: ImageHandle,
    /// A screen view's 8-bit image.
    pub ldr: Option<ImageHandle>,
    /// The meter's result (post::meter), when the view was metered.
    pub metered: Option<BufferHandle>,
}

impl FrameImages {
    fn uv(image: ImageHandle) -> Self {
        Self {
            image,
            ldr: None,
            metered: None,
        }
    }
}
