//! The specular term's GPU inputs (GPU Gems 3 §14.3): the Beckmann table D(N·H, m),
//! the specular albedo table A(cos θ, m) for energy conservation, both computed by
//! dermis at start-up (skin/specular.rs), and the per-region (ρs, m) table.

use super::specular;
use crate::error::Result;
use crate::frame::FrameInputs;
use crate::gpu::{Buffer, Context, Image, ImageDesc, Sampler};
use crate::graph::upload::{upload_buffer, upload_texture};
use crate::graph::{Access, SimplePass};
use crate::scene::file::SpecularRegion;
use ash::vk;
use std::sync::Arc;

/// 256² keeps linear interpolation of D within ~0.5 % over the lobe at m = 0.3.
pub const BECKMANN_SIZE: usize = 256;
/// 64 × 64, as recommended by the ρdt accuracy tests (skin/specular.rs).
pub const ALBEDO_SIZE: usize = 64;

/// D(N·H, m) (the paper's eq. 1), endpoint-inclusive: row m = j/(n−1), column
/// N·H = i/(n−1) (see `specular::table_point`). m = 0 is a Dirac lobe: stored as 0.
pub fn beckmann_table(n: usize) -> Vec<f32> {
    (0..n * n)
        .map(|k| {
            let (c, m) = (
                specular::table_point(k % n, n),
                specular::table_point(k / n, n),
            );
            if m > 0.0 {
                specular::beckmann(c, m)
            } else {
                0.0
            }
        })
        .collect()
}

pub struct SpecularTables {
    pub beckmann: Arc<Image>,
    pub albedo: Arc<Image>,
    /// Ten vec4 (ρs, m, 0, 0), indexed by the region map.
    pub regions: Arc<Buffer>,
    /// Linear where the device filters R32F, else nearest.
    pub sampler: Arc<Sampler>,
}

impl SpecularTables {
    pub fn new(
        ctx: &Arc<Context>,
        regions: &[SpecularRegion],
        linear: Arc<Sampler>,
        nearest: Arc<Sampler>,
    ) -> Result<Self> {
        let table = |name: &str, size: usize, values: Vec<f32>| {
            let desc = ImageDesc::new(size as u32, size as u32, vk::Format::R32_SFLOAT);
            upload_texture(ctx, name, desc, bytemuck::cast_slice(&values))
        };
        let params: Vec<[f32; 4]> = (0..10)
            .map(|i| {
                regions.get(i).map_or(
                    [specular::DEFAULT_RHO_S, specular::DEFAULT_M, 0.0, 0.0],
                    |r| [r.rho_s, r.m, 0.0, 0.0],
                )
            })
            .collect();
        Ok(Self {
            beckmann: table(
                "beckmann table",
                BECKMANN_SIZE,
                beckmann_table(BECKMANN_SIZE),
            )?,
            albedo: table(
                "specular albedo table",
                ALBEDO_SIZE,
                specular::specular_albedo_lut(ALBEDO_SIZE, ALBEDO_SIZE, 256, 64),
            )?,
            regions: upload_buffer(
                ctx,
                "region parameters",
                bytemuck::cast_slice(&params),
                Access::UniformRead,
            )?,
            sampler: if ctx.supports_linear_filter(vk::Format::R32_SFLOAT) {
                linear
            } else {
                nearest
            },
        })
    }

    /// Declares the six bindings of common/ks_specular.glsl, in its order: the
    /// Beckmann and albedo tables, the region, intensity and roughness maps, the
    /// region parameters.
    pub fn bind<'g>(&self, pass: SimplePass<'g>, inputs: &FrameInputs) -> SimplePass<'g> {
        let s = &inputs.samplers;
        pass.texture(&self.beckmann, &self.sampler)
            .texture(&self.albedo, &self.sampler)
            .texture(&inputs.regions, &s.nearest)
            .texture(&inputs.specular, &s.linear)
            .texture(&inputs.roughness, &s.linear)
            .uniform(&self.regions)
    }
}
