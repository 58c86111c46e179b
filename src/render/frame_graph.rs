//! One frame of the `render` command: the GPU state shared by every frame of a
//! render (uploaded scene, passes and their pipelines, resolved settings) and
//! the assembly of the frame graph. A view is an output the graph is asked
//! for; the graph runs only the passes it depends on (graph::cull), and what
//! a render computes once is kept by key (graph::Kept).

use super::ruler;
use super::view::{Screen, Shown, View};
use crate::error::{Error, Result};
use crate::frame_inputs::{
    upload_env, upload_rgba8, FrameInputs, FrameUniforms, MeshBuffers, Samplers, ShaderVariant,
    HDR_FORMAT, MAX_LIGHTS,
};
use crate::gpu::{Context, ImageDesc, Pipelines};
use crate::graph::upload::upload_buffer;
use crate::graph::{Access, BufferHandle, Graph, ImageHandle};
use crate::light::direct::{DirectPass, DirectView};
use crate::light::extract::extract;
use crate::light::interreflection;
use crate::light::lighting::Lighting;
use crate::light::occlusion::RgbTransfer;
use crate::light::prefilter::PrefilterPass;
use crate::light::sh_pass::{ShBuffers, ShPasses};
use crate::light::shadow::{atlas_grid, lobe_widening, ShadowPass, ShadowView};
use crate::light::skybox;
use crate::light::transmission;
use crate::light::visibility::{VisibilityPass, TEXTURES};
use crate::post::debug::{DebugPass, DepthRange};
use crate::post::glow::Glow;
use crate::post::meter::Meter;
use crate::post::tonemap::{Tonemap, LDR_FORMAT};
use crate::post::{Display, Exposure, PostSettings};
use crate::scene::file::ToneCurve;
use crate::scene::texture::Texture;
use crate::scene::{LightSource, Scene};
use crate::skin::blur::BlurChain;
use crate::skin::chain::{self, Level};
use crate::skin::fold::{FoldPass, FoldTerm};
use crate::skin::irradiance::IrradiancePass;
use crate::skin::shade::{ShadeImages, ShadeMode, ShadePass, ShadeSettings};
use crate::skin::specular::{self, Lobe};
use crate::skin::stretch::StretchMaps;
use crate::skin::tables::SpecularTables;
use crate::skin::translucent::TranslucentPass;
use crate::skin::{mean_stretch, SkinSettings};
use ash::vk;
use glam::Vec3;
use std::sync::Arc;

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

/// The frame's uniforms: camera at `aspect`, the environment's rotation and
/// intensity, the lights and their shadow projections; `specular_scale`: 0.5
/// over the specular map's mean; `lobe`: the specular lobe
/// (skin::SkinSettings::lobe), whose parameter the shaders read.
fn frame_uniforms(
    scene: &Scene,
    lighting: &Lighting,
    aspect: f32,
    specular_scale: f32,
    lobe: Lobe,
) -> FrameUniforms {
    let vp = scene.camera.view_projection(aspect);
    let tiles = lighting.tiles().len();
    let mut u = FrameUniforms {
        view_proj: vp.to_cols_array_2d(),
        inv_view_proj: vp.inverse().to_cols_array_2d(),
        camera_pos: scene.camera.position.extend(1.0).into(),
        light_vec: [[0.0; 4]; MAX_LIGHTS],
        light_color: [[0.0; 4]; MAX_LIGHTS],
        light_shadow: [[[0.0; 4]; 4]; MAX_LIGHTS],
        light_params: [[0.0; 4]; MAX_LIGHTS],
        light_focus: [[[0.0; 4]; 4]; MAX_LIGHTS],
        light_focus_tile: [[0.0; 4]; MAX_LIGHTS],
        env: [
            lighting.rotation_deg.to_radians(),
            lighting.env_factor(),
            0.0,
            if lighting.occlusion { 1.0 } else { 0.0 },
        ],
        params: [
            lobe.parameter(),
            specular_scale,
            atlas_grid(tiles).0 as f32,
            atlas_grid(tiles).1 as f32,
        ],
    };
    let (cols, rows) = atlas_grid(tiles);
    let mut tile = 0;
    for (i, (l, maps)) in lighting.lights.iter().zip(&lighting.maps).enumerate() {
        u.light_vec[i] = match l.source {
            LightSource::Directional(d) => d.extend(0.0),
            LightSource::Point(p) => p.extend(1.0),
        }
        .into();
        u.light_color[i] = l.irradiance.extend(0.0).into();
        u.light_params[i][0] = l.angular_radius.tan();
        u.light_params[i][2] = lobe_widening(l.angular_radius);
        if let Some(m) = maps {
            u.light_color[i][3] = m.whole.texel_mm;
            u.light_shadow[i] = m.whole.atlas_matrix(tile, tiles).to_cols_array_2d();
            u.light_params[i][1] = m.whole.depth_range_mm;
            u.light_params[i][3] = m.whole.near_mm.unwrap_or(0.0);
            if let Some(f) = m.focus {
                let t = tile as u32 + 1;
                u.light_focus[i] = f.view.atlas_matrix(t as usize, tiles).to_cols_array_2d();
                let corner = [
                    (t % cols) as f32 / cols as f32,
                    (t / cols) as f32 / rows as f32,
                ];
                u.light_focus_tile[i] = [f.view.texel_mm, f.nearest, corner[0], corner[1]];
            }
            tile += lighting.tiles_per_light();
        }
        u.env[2] = (i + 1) as f32;
    }
    u
}

/// Each shadowed light's texel size, mm (a point light's at its near plane),
/// in its focus map and in its whole-mesh map.
fn log_shadow_maps(lighting: &Lighting) {
    for (i, m) in lighting.maps.iter().enumerate() {
        let Some(m) = m else { continue };
        let texel = |v: &ShadowView| v.texel_mm * v.near_mm.unwrap_or(1.0);
        match m.focus {
            Some(f) => log::info!(
                "light {i}: shadow map {:.3} mm a texel where the camera looks \
                 ({:.1}× finer), {:.3} mm elsewhere",
                texel(&f.view),
                1.0 / f.half,
                texel(&m.whole)
            ),
            None => log::info!("light {i}: shadow map {:.3} mm a texel", texel(&m.whole)),
        }
    }
}

/// The scene uploaded for the frame's passes, lit by `lighting`.
fn frame_inputs(
    ctx: &Arc<Context>,
    scene: &Scene,
    albedo: &Texture,
    lighting: &Lighting,
    residual: Option<&crate::scene::env::EnvMap>,
    uniforms: &FrameUniforms,
    skin: &SkinSettings,
) -> Result<FrameInputs> {
    let samplers = Arc::new(Samplers::new(ctx)?);
    let env = upload_env(ctx, &scene.env, scene.pre_exposure.map)?;
    let (lights, views) = (&lighting.lights, &lighting.maps);
    // Bit i set where light i has `has`.
    let bits = |has: &dyn Fn(usize) -> bool| {
        (0..lights.len())
            .filter(|&i| has(i))
            .fold(0, |b, i| b | 1 << i)
    };
    let occlusion = scene.file.skin.occlusion;
    let transfer = crate::light::occlusion::transfer_for(ctx, &scene.mesh, occlusion)?;
    let n = scene.mesh.vertex_count();
    let lobe = crate::light::occlusion::lobe_visibility_for(&scene.mesh, occlusion);
    // Per vertex: the transfer, then the lobe visibility (common/transfer.glsl).
    let per_vertex: Vec<[[f32; 9]; 2]> = transfer
        .coeffs
        .iter()
        .zip(&lobe.coeffs)
        .map(|(t, s)| [*t, *s])
        .collect();
    let bounce = if scene.file.skin.interreflection {
        interreflection::bounce_for(&scene.mesh, albedo, &transfer, occlusion)
    } else {
        RgbTransfer::none(n)
    };
    let through = transmission::transmitted_for(
        &scene.mesh,
        &transfer,
        occlusion,
        &skin.falloff(),
        skin.transmission,
    );
    // Per vertex: the interreflected transfer, then the transmitted one.
    let rgb: Vec<[[[f32; 9]; 3]; 2]> = bounce
        .coeffs
        .iter()
        .zip(&through.coeffs)
        .map(|(b, t)| [*b, *t])
        .collect();
    Ok(FrameInputs {
        uniforms: upload_buffer(
            ctx,
            "frame uniforms",
            bytemuck::bytes_of(uniforms),
            Access::UniformRead,
        )?,
        mesh: Arc::new(MeshBuffers::upload(ctx, &scene.mesh)?),
        albedo: upload_rgba8(ctx, "albedo", albedo)?,
        normal: upload_rgba8(ctx, "normal map", &scene.normal)?,
        transfer: upload_buffer(
            ctx,
            "transfer and lobe visibility",
            bytemuck::cast_slice(&per_vertex),
            Access::ShaderBufferRead,
        )?,
        rgb_transfer: upload_buffer(
            ctx,
            "interreflected and transmitted transfer",
            bytemuck::cast_slice(&rgb),
            Access::ShaderBufferRead,
        )?,
        specular: upload_rgba8(ctx, "specular map", &scene.specular)?,
        roughness: upload_rgba8(ctx, "roughness map", &scene.roughness)?,
        variant: ShaderVariant {
            lights: lights.len() as u32,
            occlusion: lighting.occlusion,
            roughness_map: scene.file.textures.roughness.is_some(),
            dielectric_lobe: matches!(skin.lobe, Lobe::Dielectric { .. }),
            shadowed: bits(&|i| views[i].is_some()),
            // Soft shadows where the map can take them: directional (linear depth).
            soft: bits(&|i| {
                views[i].is_some()
                    && lights[i].angular_radius > 0.0
                    && matches!(lights[i].source, LightSource::Directional(_))
            }),
        },
        lighting_env: match residual {
            Some(r) => upload_env(ctx, r, scene.pre_exposure.map)?,
            None => env.clone(),
        },
        env,
        env_sampler: if ctx.supports_linear_filter(vk::Format::R32G32B32A32_SFLOAT) {
            samplers.linear.clone()
        } else {
            samplers.nearest.clone()
        },
        samplers,
    })
}

/// The frame's passes that own more than their pipelines (images, buffers,
/// the lights' projections); the rest are free functions.
struct Passes {
    direct: DirectPass,
    stretch: StretchMaps,
    irradiance: IrradiancePass,
    translucent: TranslucentPass,
    blur: BlurChain,
    /// `skin.fold_correction`: the chain's levels corrected where the skin folds.
    fold: Option<FoldPass>,
    shade: ShadePass,
    shadow: ShadowPass,
    visibility: VisibilityPass,
    hard_visibility: VisibilityPass,
    prefilter: PrefilterPass,
    debug: DebugPass,
    meter: Meter,
    glow: Glow,
    tonemap: Tonemap,
    sh: ShPasses,
}

impl Passes {
    fn new(
        p: &Pipelines,
        scene: &Scene,
        inputs: &FrameInputs,
        lighting: &Lighting,
        skin: &SkinSettings,
        levels: &[Level],
    ) -> Result<Self> {
        let (variant, s) = (&inputs.variant, &inputs.samplers);
        let res = skin.resolution;
        let constant_stretch = (!skin.stretch_correction).then(|| mean_stretch(&scene.mesh, res));
        // Light through thin skin: the final pass reads what `translucent` draws.
        let transmits = skin.transmission > 0.0;
        Ok(Self {
            direct: DirectPass::new(p, variant)?,
            stretch: StretchMaps::new(
                p,
                res,
                &skin.profile,
                constant_stretch,
                skin.shear_correction,
            )?,
            irradiance: IrradiancePass::new(p, variant, res, scene.file.render.irradiance_shading)?,
            blur: BlurChain::new(p, &skin.kernel, s.linear.clone(), skin.shear_correction)?,
            fold: match skin.fold_correction {
                true => {
                    let cache = crate::cache::default_cache_dir();
                    let term = FoldTerm::load_or_compute(&scene.mesh, levels, res, &cache);
                    Some(FoldPass::new(p, &term, s.nearest.clone())?)
                }
                false => None,
            },
            shade: ShadePass::new(
                p,
                variant,
                transmits,
                skin.blur_amount < 1.0,
                chain::unblurred_levels(levels),
            )?,
            translucent: TranslucentPass::new(
                p,
                variant,
                res,
                transmits,
                skin.medium.as_ref().map(|m| &m.tables),
            )?,
            shadow: ShadowPass::new(p, &lighting.tiles(), lighting.shadow_resolution)?,
            visibility: VisibilityPass::new(p, variant, res, false)?,
            hard_visibility: VisibilityPass::new(p, variant, res, true)?,
            prefilter: PrefilterPass::new(p, inputs.env_sampler.clone(), skin.lobe.schlick_f0())?,
            debug: DebugPass::new(p, &scene.regions)?,
            meter: Meter::new(p, s.nearest.clone())?,
            glow: Glow::new(p, s.nearest.clone(), s.linear.clone())?,
            tonemap: Tonemap::new(p, s.nearest.clone())?,
            sh: ShPasses::new(p, s.nearest.clone())?,
        })
    }
}

/// GPU state shared by every frame of a render: uploaded scene, passes and
/// the settings resolved once.
pub(super) struct Frame {
    inputs: FrameInputs,
    tables: SpecularTables,
    /// The render's pipelines, each built once (gpu::Pipelines).
    pipelines: Pipelines,
    passes: Passes,
    lighting: Lighting,
    sh_buffers: ShBuffers,
    skin: SkinSettings,
    /// The six Gaussians' RGB weights (the paper's Fig. 2).
    weights: [Vec3; 6],
    /// The blur levels' resolutions (skin::chain).
    levels: Vec<Level>,
    /// 0.5 over the specular map's mean (frame uniforms).
    specular_scale: f32,
    /// Time the rulers beside the chain, over the irradiance (render --ruler).
    ruler: bool,
    /// Where the depth view's 1 and 0 lie.
    depth_range: DepthRange,
    pub(super) post: PostSettings,
}

/// The lighting images every shading pass reads.
struct LightImages {
    sh: BufferHandle,
    shadows: ImageHandle,
    soft: [ImageHandle; TEXTURES],
    /// The other shadowed lights' visibility at the irradiance resolution,
    /// for the irradiance pass.
    hard: [ImageHandle; TEXTURES],
    /// The key the lights' kept images are drawn for (Lighting::shadow_key).
    key: u64,
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
        let residual = (!extraction.lights.is_empty()).then_some(&extraction.residual);
        // The focus maps hold the light that scatters into the view: four σ
        // of the profile's widest Gaussian beyond it.
        let widest = skin
            .profile
            .gaussians
            .last()
            .map_or(0.0, |g| g.variance_mm2);
        let margin_mm = 4.0 * widest.sqrt();
        let lighting = Lighting::resolve(scene, extraction.lights.clone(), margin_mm);
        log_shadow_maps(&lighting);
        let tiles = lighting.tiles().len();
        let (cols, rows) = atlas_grid(tiles);
        let res = lighting.shadow_resolution;
        super::check_target(&ctx.info, res * cols, res * rows).map_err(|e| {
            Error::Input(format!(
                "shadow atlas of {tiles} tile(s) ({} per shadowed light) at \
                 render.shadow_resolution = {res}: {e}",
                lighting.tiles_per_light()
            ))
        })?;
        let m = &scene.mesh;
        let specular_map = (scene.specular.width, scene.specular.height);
        // 1/(2s̄) of the specular map's rule; 0 turns the map off (a medium's
        // boundary has one ρs).
        let specular_scale = if !skin.specular_map_applies() {
            0.0
        } else {
            0.5 / specular::map_mean(
                &m.positions,
                &m.uvs,
                &m.indices,
                (specular_map.0, specular_map.1, &scene.specular.rgba8),
            )
        };
        let uniforms = frame_uniforms(
            scene,
            &lighting,
            w as f32 / h as f32,
            specular_scale,
            skin.lobe,
        );
        let inputs = frame_inputs(ctx, scene, albedo, &lighting, residual, &uniforms, &skin)?;
        let s = &inputs.samplers;
        let tables = SpecularTables::new(
            ctx,
            &skin.regions,
            skin.lobe,
            &scene.regions,
            s.linear.clone(),
            s.nearest.clone(),
        )?;
        let texels_per_mm = mean_stretch(&scene.mesh, skin.resolution);
        let levels = chain::plan(&skin.profile, skin.chain, skin.resolution, texels_per_mm);
        log::info!(
            "{:?} chain at {}² ({texels_per_mm:.2} texels/mm): levels {levels:?}",
            skin.chain,
            skin.resolution
        );
        let weights: Vec<Vec3> = skin.profile.gaussians.iter().map(|g| g.weights).collect();
        let (rotation, factor) = (lighting.rotation_deg, lighting.env_factor());
        let pipelines = Pipelines::new(ctx);
        Ok(Self {
            tables,
            passes: Passes::new(&pipelines, scene, &inputs, &lighting, &skin, &levels)?,
            pipelines,
            ruler,
            sh_buffers: ShBuffers::new(ctx, &inputs.lighting_env, rotation, factor)?,
            inputs,
            lighting,
            weights: weights.try_into().unwrap_or([Vec3::ZERO; 6]),
            skin,
            levels,
            specular_scale,
            depth_range: depth_range(scene),
            post: PostSettings::resolve(&scene.file.render),
        })
    }

    /// Bright sources taken out of the environment as lights.
    /// Each cached pipeline's creation time, slowest first (gpu::Pipelines).
    pub(super) fn pipeline_times(&self) -> Vec<(String, f64)> {
        self.pipelines.creation_times()
    }

    pub(super) fn extracted_lights(&self) -> usize {
        self.lighting.extracted.len()
    }

    /// Moves the camera to `scene.camera` at the aspect of `scene.file.render`'s
    /// size: the frame's uniforms and the depth view's range are made again,
    /// and the shadow focus maps where the camera left them (kept by key, they
    /// are drawn again by the next frame that needs them).
    pub(super) fn set_camera(&mut self, ctx: &Arc<Context>, scene: &Scene) -> Result<()> {
        self.depth_range = depth_range(scene);
        if self.lighting.set_camera(scene) {
            self.passes.shadow.set_tiles(&self.lighting.tiles());
        }
        let (w, h) = (scene.file.render.width, scene.file.render.height);
        let aspect = w as f32 / h as f32;
        let uniforms = frame_uniforms(
            scene,
            &self.lighting,
            aspect,
            self.specular_scale,
            self.skin.lobe,
        );
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
    /// and the uniforms are made again; the SH and shadows, kept by key, are
    /// computed again by the next frame that needs them.
    pub(super) fn set_rotation(&mut self, ctx: &Arc<Context>, scene: &Scene) -> Result<()> {
        let env = &scene.file.environment;
        self.lighting.turn(env.rotation_deg);
        self.sh_buffers
            .set_transform(ctx, env.rotation_deg, self.lighting.env_factor())?;
        self.passes.shadow.set_tiles(&self.lighting.tiles());
        self.set_camera(ctx, scene)
    }

    /// The post-processing settings (exposure, tone curve, glow, background)
    /// replaced: the graph reads them when it is built.
    pub(super) fn set_post(&mut self, post: PostSettings) {
        self.post = post;
    }

    /// A UV-space view's image (stored values) encoded for display as the view
    /// is shown.
    pub(super) fn encode(&self, g: &mut Graph, image: ImageHandle, view: &View) -> ImageHandle {
        let images = self.post(g, view.shown(), image);
        images.ldr.expect("post makes the 8-bit image")
    }

    /// log2 P: the EV the frame's HDR targets are exposed by already
    /// (scene::range); their values are the light × 2^this.
    pub(super) fn pre_ev(&self) -> f32 {
        self.lighting.pre_exposure.ev()
    }

    /// The exposure and display of a view shown as `shown`.
    pub(super) fn display(&self, shown: Shown) -> (Exposure, Display) {
        let display = self.post.display;
        match shown {
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

    /// Builds the frame graph for `view` at `size` (screen views; an image
    /// view is the image as stored) and requests its images.
    pub(super) fn graph(
        &self,
        g: &mut Graph,
        view: &View,
        size: (u32, u32),
    ) -> Result<FrameImages> {
        let light = self.lighting_images(g);
        match view {
            View::Screen(screen) => {
                let hdr = self.screen(g, *screen, &light, size)?;
                Ok(self.post(g, screen.shown(), hdr))
            }
            View::Image(name) => {
                self.screen(g, Screen::Skin(ShadeMode::Full), &light, size)?;
                let image = g
                    .find_image(name)
                    .filter(|i| i.desc.format == HDR_FORMAT)
                    .ok_or_else(|| {
                        Error::Input(format!(
                            "--view {name}: no such view; `dermis render --view list` lists them"
                        ))
                    })?;
                g.output(&image);
                Ok(FrameImages::uv(image))
            }
        }
    }

    /// The names of every view of the frame: the screen views, then the
    /// frame graph's images that can be read back as stored.
    pub(super) fn views(&self, size: (u32, u32)) -> Result<Vec<String>> {
        let mut g = Graph::new();
        let light = self.lighting_images(&mut g);
        self.screen(&mut g, Screen::Skin(ShadeMode::Full), &light, size)?;
        let images = g
            .image_names()
            .into_iter()
            .filter(|n| g.find_image(n).is_some_and(|i| i.desc.format == HDR_FORMAT));
        let screens = Screen::all().map(|s| s.name().to_string());
        Ok(screens.chain(images).collect())
    }

    /// The SH coefficients, the shadow atlas and the lights' visibility in
    /// texture space, each kept by the key of its inputs.
    fn lighting_images(&self, g: &mut Graph) -> LightImages {
        let p = &self.passes;
        let sh = p.sh.passes(g, &self.inputs.lighting_env, &self.sh_buffers);
        let key = self.lighting.shadow_key();
        let shadows = p.shadow.pass(g, &self.inputs.mesh, key);
        let soft = p.visibility.pass(g, &self.inputs, &shadows, key);
        let hard = p.hard_visibility.pass(g, &self.inputs, &shadows, key);
        LightImages {
            sh,
            shadows,
            soft,
            hard,
            key,
        }
    }

    /// The screen image (HDR) of `screen` at `(w, h)`.
    fn screen(
        &self,
        g: &mut Graph,
        screen: Screen,
        light: &LightImages,
        (w, h): (u32, u32),
    ) -> Result<ImageHandle> {
        let mut hdr = g.create_image("hdr", ImageDesc::new(w, h, HDR_FORMAT));
        let (p, inputs) = (&self.passes, &self.inputs);
        match screen {
            Screen::Skin(mode) => self.skin(g, mode, light, &mut hdr)?,
            // The frame was made with the checker as its albedo.
            Screen::TestTexture => self.skin(g, ShadeMode::Full, light, &mut hdr)?,
            Screen::Direct(view) => {
                // The sky belongs behind the shaded image, not behind a fraction.
                let sky = self.post.skybox && view == DirectView::Shading;
                skybox::pass(g, &self.pipelines, inputs, &mut hdr, sky, None)?;
                let (sh, shadows, soft) = (&light.sh, &light.shadows, &light.soft);
                p.direct.pass(g, view, inputs, sh, shadows, soft, &mut hdr);
            }
            Screen::Debug(view) => {
                skybox::pass(g, &self.pipelines, inputs, &mut hdr, false, None)?;
                p.debug.pass(g, view, inputs, self.depth_range, &mut hdr);
            }
            Screen::Reference => {
                return Err(Error::Input(
                    "the reference view is rendered on the CPU, not by the frame graph".into(),
                ))
            }
        }
        Ok(hdr)
    }

    /// Texture-space diffusion and the skin pass in `mode`, into `hdr`.
    fn skin(
        &self,
        g: &mut Graph,
        mode: ShadeMode,
        light: &LightImages,
        hdr: &mut ImageHandle,
    ) -> Result<()> {
        let (p, inputs) = (&self.passes, &self.inputs);
        let stretch = p.stretch.pass(g, &inputs.mesh, &p.blur);
        let irradiance = p.irradiance.pass(
            g,
            inputs,
            &self.tables,
            &light.sh,
            (&light.shadows, &light.soft, &light.hard),
            self.skin.mix,
        );
        if self.ruler {
            ruler::passes(g, &self.pipelines, &inputs.samplers.nearest, &irradiance)?;
        }
        let blurred = p
            .blur
            .chain(g, &irradiance, &stretch, &self.levels, p.fold.as_ref());
        let specular_env = p.prefilter.pass(g, &inputs.lighting_env);
        // Per Gaussian its RGB weight and variance (mm²): the transmittance.
        let profile = std::array::from_fn(|i| {
            let variance = self
                .skin
                .profile
                .gaussians
                .get(i)
                .map_or(0.0, |g| g.variance_mm2);
            self.weights[i].extend(variance).into()
        });
        let translucent = p.translucent.pass(
            g,
            inputs,
            &self.tables,
            (&light.shadows, light.key),
            &profile,
        );
        let size = (hdr.desc.width, hdr.desc.height);
        let mut depth = p.shade.depth(g, inputs, size);
        // A term's view shows the term alone: metered on a dim term (the light
        // through thin skin, the specular) the sky would be blown out.
        let sky = self.post.skybox && mode == ShadeMode::Full;
        skybox::pass(g, &self.pipelines, inputs, hdr, sky, Some(&mut depth))?;
        let settings = ShadeSettings {
            weights: self.weights,
            transmission: self.skin.transmission,
            mix: self.skin.mix,
            blur_amount: self.skin.blur_amount,
            mode,
        };
        let images = ShadeImages {
            sh: &light.sh,
            irradiance: &irradiance,
            levels: &BlurChain::select(&irradiance, &blurred, &self.levels),
            shadows: &light.shadows,
            soft_visibility: &light.soft,
            specular_env: &specular_env,
            translucent: &translucent,
        };
        p.shade
            .pass(g, inputs, &self.tables, images, settings, hdr, &mut depth);
        Ok(())
    }

    /// Metering, glow and tone mapping of a screen image `hdr` shown as `shown`.
    fn post(&self, g: &mut Graph, shown: Shown, hdr: ImageHandle) -> FrameImages {
        let (exposure, display) = self.display(shown);
        let p = &self.passes;
        // Metered before the glow: the exposure is the skin's.
        let metered = (exposure == Exposure::Metered).then(|| p.meter.pass(g, &hdr));
        let hdr = match self.post.glow {
            Some(intensity) if shown == Shown::Exposed => p.glow.pass(g, &hdr, intensity),
            _ => hdr,
        };
        // A given exposure applies to the light before its pre-exposure.
        let exposure = match exposure {
            Exposure::Given(ev) if shown == Shown::Exposed => Exposure::Given(ev - self.pre_ev()),
            e => e,
        };
        let (w, h) = (hdr.desc.width, hdr.desc.height);
        let mut ldr = g.create_image("ldr", ImageDesc::new(w, h, LDR_FORMAT));
        let unwritten;
        let result = match &metered {
            Some(m) => m,
            None => {
                unwritten = p.meter.result(g);
                &unwritten
            }
        };
        p.tonemap
            .pass(g, &hdr, result, &mut ldr, exposure, &display);
        g.output(&ldr);
        FrameImages {
            image: hdr,
            ldr: Some(ldr),
            metered,
        }
    }
}

/// The images a frame graph ends with.
pub(super) struct FrameImages {
    /// A screen view's HDR image as tone-mapped (after the glow), or an image
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
