//! Irradiance in texture space (GPU Gems 3 §14.5): the mesh rasterised by its
//! UVs, lit by the SH environment and the shadowed explicit lights, times albedo^mix.

use super::{uv_pipeline, UV_FORMAT};
use crate::error::Result;
use crate::gpu::{Binding, Context, ImageDesc, Pipeline};
use crate::graph::{Access, BufferHandle, Descriptor, Graph, ImageHandle, LoadOp};
use crate::render::forward::{ForwardInputs, SPECULAR_BINDINGS};
use std::sync::Arc;

pub struct IrradiancePass {
    pipeline: Arc<Pipeline>,
}

impl IrradiancePass {
    pub fn new(ctx: &Arc<Context>) -> Result<Self> {
        Ok(Self {
            pipeline: uv_pipeline(
                ctx,
                "uv_lit.vert",
                "irradiance.frag",
                &[
                    &[
                        Binding::UniformBuffer,
                        Binding::SampledImage,
                        Binding::SampledImage,
                        Binding::StorageBuffer,
                        Binding::StorageBuffer,
                    ][..],
                    &SPECULAR_BINDINGS,
                    &[Binding::SampledImage],
                ]
                .concat(),
                8,
            )?,
        })
    }

    /// `sh`: the environment's coefficients (light::sh_pass); `shadows`: the
    /// lights' shadow atlas (light::shadow).
    pub fn pass(
        &self,
        g: &mut Graph,
        inputs: &Arc<ForwardInputs>,
        sh: &BufferHandle,
        shadows: &ImageHandle,
        resolution: u32,
        mix: f32,
    ) -> ImageHandle {
        let mut out = g.create_image(
            "irradiance",
            ImageDesc::new(resolution, resolution, UV_FORMAT),
        );
        let mut p = g.add_pass("irradiance");
        let coeffs = p.read_buffer(sh, Access::FragmentBufferRead);
        let atlas = p.read(shadows, Access::FragmentSampled);
        p.color_attachment(&mut out, LoadOp::Clear([0.0; 4]));
        let (pipe, inp) = (self.pipeline.clone(), inputs.clone());
        p.record(move |cx| {
            cx.bind(&pipe);
            let mut d = vec![
                Descriptor::StaticUniform(&inp.uniforms),
                Descriptor::StaticSampled(&inp.albedo, &inp.samplers.linear),
                Descriptor::StaticSampled(&inp.normal, &inp.samplers.linear),
                Descriptor::Storage(coeffs),
                Descriptor::StaticStorage(&inp.transfer),
            ];
            d.extend(inp.specular_descriptors());
            d.push(Descriptor::Sampled(atlas, &inp.samplers.shadow));
            cx.push_descriptors(&pipe, &d);
            cx.push_constants(&pipe, &[mix.to_bits(), u32::from(inp.roughness_map)]);
            inp.mesh.draw(cx);
        });
        out
    }
}
