//! Irradiance in texture space (GPU Gems 3 §14.5): the mesh's UV layout lit by
//! the SH environment and the shadowed explicit lights, times albedo^mix. What
//! no light changes is drawn once per render over a raster of the mesh by its
//! UVs and kept (the mesh, its maps and the skin settings are fixed for a
//! render; docs/records/2026-11-26-per-render-terms.md):
//! - `surface`: the normal-mapped shading normal, albedo^mix, the specular's
//!   (ρs, m) and the share of the environment's light it lets in, 1 − ρs·Ā(m);
//! - `texel_map`, for the compute formulation below: per texel the covering
//!   triangle's three vertices and its weights on them (texel_map.vert).
//!
//! Each frame lights every covered texel, one of two ways
//! (`render.irradiance_shading`; docs/records/2026-11-27-compute-irradiance.md):
//! the mesh rasterised by its UVs (`uv_lit.vert`,
//! `irradiance.frag`), or `irradiance_vertices`, which evaluates what is
//! interpolated (the position and the environment's irradiance through the
//! transfer) at every vertex, then a compute pass over the texel map that
//! interpolates it at each texel (`irradiance.comp`): the same values, without
//! rasterising the layout every frame. A CPU rasteriser interpolates cheaper
//! than it fetches, and GPUs measured here rasterise slower than they compute.

use super::tables::SpecularTables;
use super::{uv_pipeline, UV_FORMAT};
use crate::error::Result;
use crate::frame_inputs::{FrameInputs, Samplers, ShaderVariant};
use crate::gpu::{GraphicsDesc, Image, ImageDesc, Pipeline, Pipelines};
use crate::graph::{Access, BufferHandle, Graph, ImageHandle, LoadOp, SimplePass};
use crate::scene::file::IrradianceShading;
use ash::vk;
use std::sync::Arc;

/// The surface textures (surface.frag): (octahedral n, ρs, m) and (albedo^mix,
/// 1 − ρs·Ā(m)).
const SURFACE: [&str; 2] = ["surface_normal", "surface_albedo"];
/// Their format: 16-bit fixed point over [0, 1], finer there than the half
/// floats of UV_FORMAT (the irradiance moved by up to 0.2 % with those).
const SURFACE_FORMAT: vk::Format = vk::Format::R16G16B16A16_UNORM;
/// The texel map (texel_map.frag): three vertex indices plus one (0: the
/// gutter) and two 16-bit weights.
const TEXEL_MAP_FORMAT: vk::Format = vk::Format::R32G32B32A32_UINT;
/// Vertices per row of the per-frame vertex values, two texels each
/// (common/vertices.glsl reads the row length from the image's width).
const VERTICES_PER_ROW: u32 = 1024;

pub struct IrradiancePass {
    /// The per-frame pass: a raster of the mesh by its UVs, or with
    /// `texel_map` a compute pass over it.
    pipeline: Arc<Pipeline>,
    surface_pipeline: Arc<Pipeline>,
    /// [`SURFACE`] at the irradiance resolution.
    surface: [Arc<Image>; 2],
    texel_map: Option<TexelMap>,
}

/// The compute formulation's kept texel map and its passes.
struct TexelMap {
    image: Arc<Image>,
    pipeline: Arc<Pipeline>,
    vertices_pipeline: Arc<Pipeline>,
}

impl IrradiancePass {
    /// The pass for an irradiance texture of `resolution`², shaded as
    /// `shading` resolves on this device.
    pub fn new(
        pipelines: &Pipelines,
        variant: &ShaderVariant,
        resolution: u32,
        shading: IrradianceShading,
    ) -> Result<Self> {
        let ctx = pipelines.ctx();
        let specialization = variant.specialization();
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
            | vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::TRANSFER_SRC;
        let image = |name, format| {
            let desc = ImageDesc::new(resolution, resolution, format);
            Image::new(ctx, name, desc, usage).map(Arc::new)
        };
        let compute = shading.compute(ctx.info.is_cpu());
        let texel_map = compute
            .then(|| -> Result<TexelMap> {
                Ok(TexelMap {
                    image: image("texel_map", TEXEL_MAP_FORMAT)?,
                    // The full-screen state: no vertex input, no depth, no
                    // culling (UV charts may be mirrored: both windings are
                    // surface); the vertices are the mesh's corners.
                    pipeline: pipelines.graphics(&GraphicsDesc {
                        vertex: "texel_map.vert",
                        ..GraphicsDesc::fullscreen("texel_map.frag", &[TEXEL_MAP_FORMAT])
                    })?,
                    vertices_pipeline: pipelines
                        .compute("irradiance_vertices.comp", &specialization)?,
                })
            })
            .transpose()?;
        Ok(Self {
            pipeline: if compute {
                pipelines.compute("irradiance.comp", &specialization)?
            } else {
                uv_pipeline(
                    pipelines,
                    ("uv_lit.vert", "irradiance.frag"),
                    &[UV_FORMAT],
                    &specialization,
                )?
            },
            surface_pipeline: uv_pipeline(
                pipelines,
                ("uv.vert", "surface.frag"),
                &[SURFACE_FORMAT; 2],
                &specialization,
            )?,
            surface: [
                image(SURFACE[0], SURFACE_FORMAT)?,
                image(SURFACE[1], SURFACE_FORMAT)?,
            ],
            texel_map,
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
        let ([mut normal, mut albedo], draw) =
            g.import_kept_images(images, Access::ShaderSampled, 0);
        if draw {
            let pass = g
                .simple_pass("surface", &self.surface_pipeline)
                .uniform(&inputs.uniforms)
                .texture(&inputs.albedo, &s.linear)
                .texture(&inputs.normal, &s.linear);
            let pass = tables
                .bind(pass, inputs)
                .color(&mut normal, LoadOp::Clear([0.0; 4]))
                .color(&mut albedo, LoadOp::Clear([0.0; 4]))
                .constants(&mix);
            inputs.mesh.draw(pass);
        }
        let map = self.texel_map.as_ref().map(|m| m.inputs(g, inputs, sh));
        let side = self.surface[0].desc.width;
        let mut out = g.create_image("irradiance", ImageDesc::new(side, side, UV_FORMAT));
        let pass = g
            .simple_pass("irradiance", &self.pipeline)
            .uniform(&inputs.uniforms)
            .sample(&normal, &s.nearest)
            .sample(&albedo, &s.nearest)
            .read_uniform(sh);
        let lit = (shadows, soft, hard);
        let Some((texel_map, values)) = map else {
            let pass = pass.buffer(&inputs.transfer);
            let pass = lights(tables.bind(pass, inputs), lit, s, |p| {
                p.buffer(&inputs.rgb_transfer)
            });
            inputs
                .mesh
                .draw(pass.color(&mut out, LoadOp::Clear([0.0; 4])));
            return out;
        };
        let pass = pass.sample(&texel_map, &s.nearest);
        let pass = lights(tables.bind(pass, inputs), lit, s, |p| {
            p.sample(&values, &s.nearest)
        });
        pass.store(&mut out).dispatch([side, side, 1]);
        out
    }
}

/// The shadow atlas and the lights' stored visibility, bindings 10 to 17 of
/// both formulations, with binding 14 (the raster's per-vertex RGB transfer,
/// the compute pass's vertex values) bound by `at_14`.
fn lights<'g>(
    pass: SimplePass<'g>,
    (shadows, soft, hard): (&ImageHandle, &[ImageHandle], &[ImageHandle]),
    samplers: &Samplers,
    at_14: impl FnOnce(SimplePass<'g>) -> SimplePass<'g>,
) -> SimplePass<'g> {
    let mut pass = pass.sample(shadows, &samplers.shadow);
    for v in soft {
        pass = pass.sample(v, &samplers.linear);
    }
    let mut pass = at_14(pass);
    for v in hard {
        pass = pass.sample(v, &samplers.nearest);
    }
    pass
}

impl TexelMap {
    /// The kept texel map (drawn by the render's first frame: pass
    /// `texel_map`) and this frame's vertex values (`irradiance_vertices`).
    fn inputs(
        &self,
        g: &mut Graph,
        inputs: &FrameInputs,
        sh: &BufferHandle,
    ) -> (ImageHandle, ImageHandle) {
        let ([mut map], draw) =
            g.import_kept_images([("texel_map", &self.image)], Access::ShaderSampled, 0);
        let mesh = &inputs.mesh;
        if draw {
            g.simple_pass("texel_map", &self.pipeline)
                .buffer(&mesh.indices)
                .buffer(&mesh.vertices)
                .color(&mut map, LoadOp::Clear([0.0; 4]))
                .draw(mesh.index_count);
        }
        let rows = mesh.vertex_count.div_ceil(VERTICES_PER_ROW);
        let desc = ImageDesc::new(2 * VERTICES_PER_ROW, rows, vk::Format::R32G32B32A32_SFLOAT);
        let mut values = g.create_image("irradiance_vertices", desc);
        g.simple_pass("irradiance_vertices", &self.vertices_pipeline)
            .uniform(&inputs.uniforms)
            .buffer(&mesh.vertices)
            .store(&mut values)
            .read_uniform(sh)
            .buffer(&inputs.transfer)
            .buffer(&inputs.rgb_transfer)
            .dispatch([mesh.vertex_count, 1, 1]);
        (map, values)
    }
}
