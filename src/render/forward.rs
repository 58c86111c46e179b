//! Screen-space scene passes: the environment behind the head, and the mesh with
//! direct diffuse shading (`--view direct`) or its occlusion (`--view occlusion`).

use super::resources::{MeshBuffers, Samplers, Vertex, VERTEX_ATTRIBUTES};
use crate::error::Result;
use crate::gpu::{Binding, Buffer, Context, GraphicsDesc, Image, Pipeline};
use crate::graph::{Access, BufferHandle, Descriptor, Graph, ImageHandle, LoadOp};
use ash::vk;
use std::sync::Arc;

/// Formats of the screen-space targets.
pub const HDR_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// Per-frame uniforms (std140, mirrors shaders-glsl/common/frame.glsl).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniforms {
    pub view_proj: [[f32; 4]; 4],
    pub inv_view_proj: [[f32; 4]; 4],
    pub camera_pos: [f32; 4],
    /// w = 0: direction towards the light; w = 1: position, mm.
    pub light_vec: [[f32; 4]; 4],
    /// rgb: irradiance facing the light (point: at 1000 mm); w: shadow texel
    /// size, mm (per mm of distance for a point light), 0 = unshadowed.
    pub light_color: [[f32; 4]; 4],
    /// World to (atlas u, v, depth), light::shadow::ShadowView::atlas_matrix.
    pub light_shadow: [[[f32; 4]; 4]; 4],
    /// x: environment rotation (radians about +Y), y: intensity, z: light count,
    /// w: occlusion on.
    pub env: [f32; 4],
    /// x: exposure (EV).
    pub params: [f32; 4],
}

pub const MAX_LIGHTS: usize = 4;

pub struct ForwardPipelines {
    background: Arc<Pipeline>,
    /// Direct diffuse shading (`--view direct`).
    pub direct: Arc<Pipeline>,
    /// The transfer's DC term (`--view occlusion`).
    pub occlusion: Arc<Pipeline>,
}

impl ForwardPipelines {
    pub fn new(ctx: &Arc<Context>) -> Result<Self> {
        let background = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                vertex: "fullscreen.vert",
                fragment: "background.frag",
                bindings: &[Binding::UniformBuffer, Binding::SampledImage],
                push_constant_bytes: 8,
                color_formats: &[HDR_FORMAT],
                depth_format: None,
                vertex_layout: None,
                cull_mode: vk::CullModeFlags::NONE,
            },
        )?;
        let lit = |fragment| {
            Pipeline::graphics(
                ctx,
                &GraphicsDesc {
                    vertex: "mesh_lit.vert",
                    fragment,
                    bindings: &[
                        Binding::UniformBuffer,
                        Binding::SampledImage,
                        Binding::SampledImage,
                        Binding::StorageBuffer,
                        Binding::StorageBuffer,
                        Binding::SampledImage,
                    ],
                    push_constant_bytes: 0,
                    color_formats: &[HDR_FORMAT],
                    depth_format: Some(DEPTH_FORMAT),
                    vertex_layout: Some((std::mem::size_of::<Vertex>() as u32, &VERTEX_ATTRIBUTES)),
                    // Scanned meshes are not reliably closed or consistently wound.
                    cull_mode: vk::CullModeFlags::NONE,
                },
            )
        };
        Ok(Self {
            background,
            direct: lit("forward.frag")?,
            occlusion: lit("occlusion.frag")?,
        })
    }
}

/// Static inputs of the forward passes.
pub struct ForwardInputs {
    pub uniforms: Arc<Buffer>,
    pub mesh: Arc<MeshBuffers>,
    pub albedo: Arc<Image>,
    pub normal: Arc<Image>,
    /// Per-vertex SH transfer, 9 floats per vertex (light::occlusion).
    pub transfer: Arc<Buffer>,
    /// Specular intensity, roughness and face-region maps (read by the specular term).
    pub specular: Arc<Image>,
    pub roughness: Arc<Image>,
    pub regions: Arc<Image>,
    /// Whether the scene gave a roughness map (else the regions' m is used).
    pub roughness_map: bool,
    pub tables: crate::skin::tables::SpecularTables,
    pub env: Arc<Image>,
    /// Linear where the device filters RGBA32F, else nearest.
    pub env_sampler: Arc<crate::gpu::Sampler>,
    pub samplers: Arc<Samplers>,
}

impl ForwardInputs {
    /// The six specular bindings of common/ks_specular.glsl, in order.
    pub fn specular_descriptors(&self) -> [Descriptor<'_>; 6] {
        let t = &self.tables;
        let s = &self.samplers;
        [
            Descriptor::StaticSampled(&t.beckmann, &t.sampler),
            Descriptor::StaticSampled(&t.albedo, &t.sampler),
            Descriptor::StaticSampled(&self.regions, &s.nearest),
            Descriptor::StaticSampled(&self.specular, &s.linear),
            Descriptor::StaticSampled(&self.roughness, &s.linear),
            Descriptor::StaticStorage(&t.regions),
        ]
    }
}

/// The specular bindings' kinds, matching [`ForwardInputs::specular_descriptors`].
pub const SPECULAR_BINDINGS: [Binding; 6] = [
    Binding::SampledImage,
    Binding::SampledImage,
    Binding::SampledImage,
    Binding::SampledImage,
    Binding::SampledImage,
    Binding::StorageBuffer,
];

/// The environment seen through the camera, clearing `hdr`.
pub fn background(
    g: &mut Graph,
    p: &ForwardPipelines,
    inputs: &Arc<ForwardInputs>,
    hdr: &mut ImageHandle,
) {
    let (w, h) = (hdr.desc.width, hdr.desc.height);
    let mut pass = g.add_pass("background");
    pass.color_attachment(hdr, LoadOp::Clear([0.0; 4]));
    let (pipe, inp) = (p.background.clone(), inputs.clone());
    pass.record(move |cx| {
        cx.bind(&pipe);
        cx.push_descriptors(
            &pipe,
            &[
                Descriptor::StaticUniform(&inp.uniforms),
                Descriptor::StaticSampled(&inp.env, &inp.env_sampler),
            ],
        );
        cx.push_constants(&pipe, &[w as f32, h as f32]);
        cx.draw(3, 1);
    });
}

/// The mesh drawn in screen space over `hdr` with `pipeline` (`direct` or
/// `occlusion` of [`ForwardPipelines`]); `sh`: the environment's coefficients;
/// `shadows`: the lights' shadow atlas (light::shadow).
pub fn direct(
    g: &mut Graph,
    pipeline: &Arc<Pipeline>,
    name: &str,
    inputs: &Arc<ForwardInputs>,
    sh: &BufferHandle,
    shadows: &ImageHandle,
    hdr: &mut ImageHandle,
) {
    let (w, h) = (hdr.desc.width, hdr.desc.height);
    let mut depth = g.create_image("depth", crate::gpu::ImageDesc::new(w, h, DEPTH_FORMAT));
    let mut pass = g.add_pass(name);
    let coeffs = pass.read_buffer(sh, Access::FragmentBufferRead);
    let atlas = pass.read(shadows, Access::FragmentSampled);
    pass.color_attachment(hdr, LoadOp::Load);
    pass.depth_attachment(&mut depth, LoadOp::Clear([1.0; 4]));
    let (pipe, inp) = (pipeline.clone(), inputs.clone());
    pass.record(move |cx| {
        cx.bind(&pipe);
        cx.push_descriptors(
            &pipe,
            &[
                Descriptor::StaticUniform(&inp.uniforms),
                Descriptor::StaticSampled(&inp.albedo, &inp.samplers.linear),
                Descriptor::StaticSampled(&inp.normal, &inp.samplers.linear),
                Descriptor::Storage(coeffs),
                Descriptor::StaticStorage(&inp.transfer),
                Descriptor::Sampled(atlas, &inp.samplers.shadow),
            ],
        );
        inp.mesh.draw(cx);
    });
}
