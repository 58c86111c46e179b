//! The soft lights' visibility in texture space, once per render (the mesh and
//! the lights do not move within one; kept by key, graph::Kept): for each light
//! with an angular size (the environment's extracted sources), percentage-closer
//! soft shadows from its tile of the shadow atlas at every texel of the mesh's
//! UV layout (shaders-glsl/light_visibility.frag). The shading passes (irradiance,
//! final skin, direct view) read it back with one bilinear fetch per three lights,
//! so the soft shadows' taps are paid at half the irradiance resolution, at most
//! [`MAX_RESOLUTION`]², whatever the screen.

use crate::error::Result;
use crate::frame::{FrameInputs, ShaderVariant, Vertex};
use crate::gpu::{GraphicsDesc, Image, ImageDesc, Pipeline, Pipelines};
use crate::graph::{Access, Graph, ImageHandle, LoadOp};
use ash::vk;
use std::sync::Arc;

/// Largest side of the visibility textures. The diffusion blurs the irradiance
/// they shadow; 1024² is ~0.6 mm per texel on the scan, the shadow atlas's
/// 2048² tiles ~0.25 mm. Half the irradiance resolution costs no measurable
/// accuracy against the reference (docs/lighting.md) and a quarter of the time.
pub const MAX_RESOLUTION: u32 = 1024;
/// Three lights per texture (RGB), coverage in alpha, 8 bits each.
pub const FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
/// Textures the shaders bind (common/lights.glsl SOFT_VISIBILITY): nine lights,
/// more than frame::MAX_LIGHTS.
pub const TEXTURES: usize = 3;

pub struct VisibilityPass {
    pipeline: Arc<Pipeline>,
    /// Any light has an angular size and a shadow map.
    soft: bool,
    /// Drawn by the render's first frame that needs them and kept, as the
    /// shadow atlas they come from.
    textures: Vec<Arc<Image>>,
}

impl VisibilityPass {
    /// The pass and its textures at min(`resolution`/2, [`MAX_RESOLUTION`])² for
    /// an irradiance texture of `resolution`²; 1×1 when no light is soft, so the
    /// shading passes always have them to bind.
    pub fn new(pipelines: &Pipelines, variant: &ShaderVariant, resolution: u32) -> Result<Self> {
        let ctx = pipelines.ctx();
        let pipeline = pipelines.graphics(&GraphicsDesc {
            vertex: "uv.vert",
            fragment: "light_visibility.frag",
            color_formats: &[FORMAT; TEXTURES],
            depth_format: None,
            depth_write: true,
            vertex_layout: Some(Vertex::layout()),
            // UV charts may be mirrored: both windings are surface.
            cull_mode: vk::CullModeFlags::NONE,
            specialization: &variant.specialization(),
            alpha_blend: false,
        })?;
        let soft = variant.soft != 0;
        let side = if soft {
            (resolution / 2).clamp(1, MAX_RESOLUTION)
        } else {
            1
        };
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
        let textures = (0..TEXTURES)
            .map(|k| {
                let desc = ImageDesc::new(side, side, FORMAT);
                Image::new(ctx, &name(k), desc, usage).map(Arc::new)
            })
            .collect::<Result<_>>()?;
        Ok(Self {
            pipeline,
            soft,
            textures,
        })
    }

    /// The visibility textures as graph images, from the lights' shadow `atlas`
    /// (light::shadow), kept for `key` (the atlas's): drawn (pass
    /// `light_visibility`) by the first frame that needs them.
    pub fn pass(
        &self,
        g: &mut Graph,
        inputs: &FrameInputs,
        atlas: &ImageHandle,
        key: u64,
    ) -> [ImageHandle; TEXTURES] {
        let names: [String; TEXTURES] = std::array::from_fn(name);
        let images = std::array::from_fn(|k| (names[k].as_str(), &self.textures[k]));
        let (mut out, draw) = g.import_kept_images(images, Access::ShaderSampled, key);
        if !draw {
            return out;
        }
        let s = &inputs.samplers;
        let mut pass = g
            .simple_pass("light_visibility", &self.pipeline)
            .tag(super::TAG)
            .uniform(&inputs.uniforms)
            .sample(atlas, &s.shadow)
            .sample(atlas, &s.nearest);
        for image in &mut out {
            pass = pass.color(image, LoadOp::Clear([0.0; 4]));
        }
        if self.soft {
            inputs.mesh.draw(pass);
        } else {
            pass.record(|_| {});
        }
        out
    }
}

fn name(k: usize) -> String {
    format!("soft visibility {k}")
}
