//! Irradiance in texture space (GPU Gems 3 §14.5): the mesh rasterised by its
//! UVs, lit by the SH environment and the shadowed explicit lights, times albedo^mix.

use super::tables::SpecularTables;
use super::{uv_pipeline, UV_FORMAT};
use crate::error::Result;
use crate::frame::{FrameInputs, ShaderVariant};
use crate::gpu::{ImageDesc, Pipeline, Pipelines};
use crate::graph::{BufferHandle, Graph, ImageHandle, LoadOp};
use std::sync::Arc;

pub struct IrradiancePass {
    pipeline: Arc<Pipeline>,
}

impl IrradiancePass {
    pub fn new(pipelines: &Pipelines, variant: &ShaderVariant) -> Result<Self> {
        Ok(Self {
            pipeline: uv_pipeline(
                pipelines,
                "uv_lit.vert",
                "irradiance.frag",
                &variant.specialization(),
            )?,
        })
    }

    /// `sh`: the environment's coefficients (light::sh_pass); `shadows`: the
    /// lights' shadow atlas (light::shadow) and `soft`, the soft lights'
    /// visibility (light::visibility); `tables`: the specular term's, for energy
    /// conservation on entry.
    #[allow(clippy::too_many_arguments)]
    pub fn pass(
        &self,
        g: &mut Graph,
        inputs: &FrameInputs,
        tables: &SpecularTables,
        sh: &BufferHandle,
        (shadows, soft): (&ImageHandle, &[ImageHandle]),
        resolution: u32,
        mix: f32,
    ) -> ImageHandle {
        let mut out = g.create_image(
            "irradiance",
            ImageDesc::new(resolution, resolution, UV_FORMAT),
        );
        let s = &inputs.samplers;
        let pass = g
            .simple_pass("irradiance", &self.pipeline)
            .uniform(&inputs.uniforms)
            .texture(&inputs.albedo, &s.linear)
            .texture(&inputs.normal, &s.linear)
            .read_uniform(sh)
            .buffer(&inputs.transfer);
        let mut pass = tables.bind(pass, inputs).sample(shadows, &s.shadow);
        for v in soft {
            pass = pass.sample(v, &s.linear);
        }
        let pass = pass
            .buffer(&inputs.rgb_transfer)
            .color(&mut out, LoadOp::Clear([0.0; 4]))
            .constants(&mix);
        inputs.mesh.draw(pass);
        out
    }
}
