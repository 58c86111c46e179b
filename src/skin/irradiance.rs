//! Irradiance in texture space (GPU Gems 3 §14.5): the mesh rasterised by its
//! UVs, lit by the SH environment and the shadowed explicit lights, times
//! albedo^mix. What no light changes — the normal-mapped shading normal,
//! albedo^mix, the specular's (ρs, m) and the share of the environment's light
//! it lets in, 1 − ρs·Ā(m) — is drawn once per render over the
//! same raster (`surface`, kept: the mesh, its maps and the skin settings are
//! fixed for a render) and read back texel for texel by every frame
//! (`irradiance`), instead of five map and table fetches per texel (issue 24;
//! docs/performance.md).

use super::tables::SpecularTables;
use super::{uv_pipeline, UV_FORMAT};
use crate::error::Result;
use crate::frame::{FrameInputs, ShaderVariant};
use crate::gpu::{Image, ImageDesc, Pipeline, Pipelines};
use crate::graph::{Access, BufferHandle, Graph, ImageHandle, LoadOp};
use ash::vk;
use std::sync::Arc;

/// The surface textures (surface.frag): (octahedral n, ρs, m) and (albedo^mix,
/// 1 − ρs·Ā(m)).
const SURFACE: [&str; 2] = ["surface_normal", "surface_albedo"];
/// Their format: 16-bit fixed point over [0, 1], finer there than the half
/// floats of UV_FORMAT (the irradiance moved by up to 0.2 % with those).
const SURFACE_FORMAT: vk::Format = vk::Format::R16G16B16A16_UNORM;

pub struct IrradiancePass {
    pipeline: Arc<Pipeline>,
    surface_pipeline: Arc<Pipeline>,
    /// [`SURFACE`] at the irradiance resolution.
    surface: [Arc<Image>; 2],
}

impl IrradiancePass {
    /// The pass for an irradiance texture of `resolution`².
    pub fn new(pipelines: &Pipelines, variant: &ShaderVariant, resolution: u32) -> Result<Self> {
        let ctx = pipelines.ctx();
        let specialization = variant.specialization();
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
            | vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::TRANSFER_SRC;
        let desc = ImageDesc::new(resolution, resolution, SURFACE_FORMAT);
        let image = |name| Image::new(ctx, name, desc, usage).map(Arc::new);
        Ok(Self {
            pipeline: uv_pipeline(
                pipelines,
                ("uv_lit.vert", "irradiance.frag"),
                &[UV_FORMAT],
                &specialization,
            )?,
            surface_pipeline: uv_pipeline(
                pipelines,
                ("uv.vert", "surface.frag"),
                &[SURFACE_FORMAT; 2],
                &specialization,
            )?,
            surface: [image(SURFACE[0])?, image(SURFACE[1])?],
        })
    }

    /// `sh`: the environment's coefficients (light::sh_pass); `shadows`: the
    /// lights' shadow atlas (light::shadow), `soft` and `hard` the soft and the
    /// other shadowed lights' visibility (light::visibility); `tables`: the
    /// specular term's, for energy conservation on entry and the region
    /// parameters.
    #[allow(clippy::too_many_arguments)]
    pub fn pass(
        &self,
        g: &mut Graph,
        inputs: &FrameInputs,
        tables: &SpecularTables,
        sh: &BufferHandle,
        (shadows, soft, hard): (&ImageHandle, &[ImageHandle], &[ImageHandle]),
        mix: f32,
    ) -> ImageHandle {
        let s = &inputs.samplers;
        let [normal, albedo] = &self.surface;
        let images = [(SURFACE[0], normal), (SURFACE[1], albedo)];
        let (mut surface, draw) = g.import_kept_images(images, Access::ShaderSampled, 0);
        if draw {
            let pass = g
                .simple_pass("surface", &self.surface_pipeline)
                .uniform(&inputs.uniforms)
                .texture(&inputs.albedo, &s.linear)
                .texture(&inputs.normal, &s.linear);
            let [normal, albedo] = &mut surface;
            let pass = tables
                .bind(pass, inputs)
                .color(normal, LoadOp::Clear([0.0; 4]))
                .color(albedo, LoadOp::Clear([0.0; 4]))
                .constants(&mix);
            inputs.mesh.draw(pass);
        }
        let side = self.surface[0].desc.width;
        let mut out = g.create_image("irradiance", ImageDesc::new(side, side, UV_FORMAT));
        let pass = g
            .simple_pass("irradiance", &self.pipeline)
            .uniform(&inputs.uniforms)
            .sample(&surface[0], &s.nearest)
            .sample(&surface[1], &s.nearest)
            .read_uniform(sh)
            .buffer(&inputs.transfer);
        let mut pass = tables.bind(pass, inputs).sample(shadows, &s.shadow);
        for v in soft {
            pass = pass.sample(v, &s.linear);
        }
        let mut pass = pass.buffer(&inputs.rgb_transfer);
        for v in hard {
            pass = pass.sample(v, &s.nearest);
        }
        let pass = pass.color(&mut out, LoadOp::Clear([0.0; 4]));
        inputs.mesh.draw(pass);
        out
    }
}
