//! The mesh in screen space with direct diffuse shading and no scattering
//! (`--view direct`), or its occlusion (`--view occlusion`): Σ L_i·T_i per vertex
//! plus the shadowed lights, for comparison with texture-space diffusion.

use crate::error::Result;
use crate::frame_inputs::{FrameInputs, ShaderVariant, Vertex, DEPTH_FORMAT, HDR_FORMAT};
use crate::gpu::{GraphicsDesc, ImageDesc, Pipeline, Pipelines};
use crate::graph::{BufferHandle, Graph, ImageHandle, LoadOp};
use ash::vk;
use std::sync::Arc;

/// Which quantity the pass shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DirectView {
    /// Direct diffuse shading.
    Shading,
    /// The transfer's DC term relative to open sky (1 = unoccluded).
    Occlusion,
}

impl DirectView {
    pub const ALL: [DirectView; 2] = [DirectView::Shading, DirectView::Occlusion];

    /// The view's name (`render --view`), also its pass's.
    pub fn name(self) -> &'static str {
        match self {
            DirectView::Shading => "direct",
            DirectView::Occlusion => "occlusion",
        }
    }
}

pub struct DirectPass {
    shading: Arc<Pipeline>,
    occlusion: Arc<Pipeline>,
}

impl DirectPass {
    pub fn new(pipelines: &Pipelines, variant: &ShaderVariant) -> Result<Self> {
        let lit = |fragment| {
            pipelines.graphics(&GraphicsDesc {
                vertex: "mesh_lit.vert",
                fragment,
                color_formats: &[HDR_FORMAT],
                depth_format: Some(DEPTH_FORMAT),
                depth_write: true,
                vertex_layout: Some(Vertex::layout()),
                // Scanned meshes are not reliably closed or consistently wound.
                cull_mode: vk::CullModeFlags::NONE,
                specialization: &variant.specialization(),
                alpha_blend: false,
            })
        };
        Ok(Self {
            shading: lit("forward.frag")?,
            occlusion: lit("occlusion.frag")?,
        })
    }

    /// Draws the mesh over `hdr`; `sh`: the environment's coefficients
    /// (light::sh_pass); `shadows`: the lights' shadow atlas (light::shadow);
    /// `soft`: the soft lights' visibility (light::visibility).
    #[allow(clippy::too_many_arguments)]
    pub fn pass(
        &self,
        g: &mut Graph,
        view: DirectView,
        inputs: &FrameInputs,
        sh: &BufferHandle,
        shadows: &ImageHandle,
        soft: &[ImageHandle],
        hdr: &mut ImageHandle,
    ) {
        let (pipeline, name) = match view {
            DirectView::Shading => (&self.shading, view.name()),
            DirectView::Occlusion => (&self.occlusion, view.name()),
        };
        let (w, h) = (hdr.desc.width, hdr.desc.height);
        let mut depth = g.create_image("depth", ImageDesc::new(w, h, DEPTH_FORMAT));
        let s = &inputs.samplers;
        let mut pass = g
            .simple_pass(name, pipeline)
            .uniform(&inputs.uniforms)
            .texture(&inputs.albedo, &s.linear)
            .texture(&inputs.normal, &s.linear)
            .read_uniform(sh)
            .buffer(&inputs.transfer)
            .sample(shadows, &s.shadow);
        for v in soft {
            pass = pass.sample(v, &s.linear);
        }
        let pass = pass
            .color(hdr, LoadOp::Load)
            .depth(&mut depth, LoadOp::Clear([1.0; 4]));
        inputs.mesh.draw(pass);
    }
}
