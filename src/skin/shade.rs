//! Final skin shading in screen space (GPU Gems 3 §14.5; the paper's Fig. 2):
//! Σ w_i · blur_i with the profile's RGB weights, × albedo^(1−mix), / π, plus the
//! KS specular of the lights and the environment.

use crate::error::Result;
use crate::gpu::{Binding, Context, GraphicsDesc, Pipeline};
use crate::graph::{Access, Descriptor, Graph, ImageHandle, LoadOp};
use crate::render::forward::{ForwardInputs, DEPTH_FORMAT, HDR_FORMAT, SPECULAR_BINDINGS};
use crate::render::resources::{Vertex, VERTEX_ATTRIBUTES};
use ash::vk;
use std::sync::Arc;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadePush {
    weights: [[f32; 4]; 6],
    mix_pre: f32,
    mode: u32,
    roughness_map: u32,
}

/// The profile weights, albedo split and output of the final pass.
#[derive(Clone, Copy, Debug)]
pub struct ShadeSettings {
    /// RGB weight of each Gaussian (the paper's Fig. 2).
    pub weights: [glam::Vec3; 6],
    /// Pre-scatter share of the albedo.
    pub mix: f32,
    pub mode: ShadeMode,
}

/// The frame's images the final pass reads.
pub struct ShadeImages<'a> {
    /// The six blur levels.
    pub levels: &'a [ImageHandle],
    /// The lights' shadow atlas (light::shadow).
    pub shadows: &'a ImageHandle,
    /// The KS-prefiltered environment (light::prefilter).
    pub specular_env: &'a ImageHandle,
}

/// What the final pass writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadeMode {
    /// Subsurface diffuse plus specular.
    Full = 0,
    Diffuse = 1,
    Specular = 2,
}

pub struct ShadePass {
    pipeline: Arc<Pipeline>,
}

impl ShadePass {
    pub fn new(ctx: &Arc<Context>) -> Result<Self> {
        // The order of skin.frag: frame, albedo, normal, shadow atlas, transfer,
        // specular environment, six blur levels, the specular bindings.
        let mut bindings = vec![
            Binding::UniformBuffer,
            Binding::SampledImage,
            Binding::SampledImage,
            Binding::SampledImage,
            Binding::StorageBuffer,
            Binding::SampledImage,
        ];
        bindings.extend([Binding::SampledImage; 6]);
        bindings.extend(SPECULAR_BINDINGS);
        let pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                vertex: "mesh_lit.vert",
                fragment: "skin.frag",
                bindings: &bindings,
                push_constant_bytes: std::mem::size_of::<ShadePush>() as u32,
                color_formats: &[HDR_FORMAT],
                depth_format: Some(DEPTH_FORMAT),
                vertex_layout: Some((std::mem::size_of::<Vertex>() as u32, &VERTEX_ATTRIBUTES)),
                cull_mode: vk::CullModeFlags::NONE,
            },
        )?;
        Ok(Self { pipeline })
    }

    /// Draws the mesh over `hdr` (which holds the background).
    pub fn pass(
        &self,
        g: &mut Graph,
        inputs: &Arc<ForwardInputs>,
        images: ShadeImages,
        settings: ShadeSettings,
        hdr: &mut ImageHandle,
    ) {
        let (w, h) = (hdr.desc.width, hdr.desc.height);
        let mut depth = g.create_image("depth", crate::gpu::ImageDesc::new(w, h, DEPTH_FORMAT));
        let mut p = g.add_pass("skin");
        let refs: Vec<_> = images
            .levels
            .iter()
            .map(|l| p.read(l, Access::FragmentSampled))
            .collect();
        let atlas = p.read(images.shadows, Access::FragmentSampled);
        let env = p.read(images.specular_env, Access::FragmentSampled);
        p.color_attachment(hdr, LoadOp::Load);
        p.depth_attachment(&mut depth, LoadOp::Clear([1.0; 4]));
        let (pipe, inp) = (self.pipeline.clone(), inputs.clone());
        let push = ShadePush {
            weights: settings.weights.map(|w| w.extend(0.0).into()),
            mix_pre: settings.mix,
            mode: settings.mode as u32,
            roughness_map: u32::from(inputs.roughness_map),
        };
        p.record(move |cx| {
            cx.bind(&pipe);
            let sampler = &inp.samplers.linear;
            let mut d = vec![
                Descriptor::StaticUniform(&inp.uniforms),
                Descriptor::StaticSampled(&inp.albedo, sampler),
                Descriptor::StaticSampled(&inp.normal, sampler),
                Descriptor::Sampled(atlas, &inp.samplers.shadow),
                Descriptor::StaticStorage(&inp.transfer),
                Descriptor::Sampled(env, sampler),
            ];
            d.extend(refs.iter().map(|&r| Descriptor::Sampled(r, sampler)));
            d.extend(inp.specular_descriptors());
            cx.push_descriptors(&pipe, &d);
            cx.push_constants(&pipe, &push);
            inp.mesh.draw(cx);
        });
    }
}
