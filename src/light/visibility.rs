//! The soft lights' visibility in texture space, once per render (the mesh and
//! the lights do not move within one; kept by key, graph::Kept): for each light
//! with an angular size (the environment's extracted sources), percentage-closer
//! soft shadows from its tile of the shadow atlas at every texel of the mesh's
//! UV layout (shaders-glsl/light_visibility.frag). The shading passes (irradiance,
//! final skin, direct view) read it back with one bilinear fetch per three lights,
//! so the soft shadows' taps are paid at half the irradiance resolution, at most
//! [`MAX_RESOLUTION`]², whatever the screen. The other shadowed lights' 3×3 PCF
//! is drawn the same way at the irradiance resolution (`hard_visibility`), for
//! the irradiance pass alone, which reads it texel for texel: the same values,
//! in 8-bit steps, once per lighting instead of every frame.

use crate::error::Result;
use crate::frame_inputs::{FrameInputs, ShaderVariant, Vertex};
use crate::gpu::{GraphicsDesc, Image, ImageDesc, Pipeline, Pipelines};
use crate::graph::{Access, Graph, ImageHandle, LoadOp};
use ash::vk;
use std::sync::Arc;

/// Largest side of the visibility textures. The diffusion blurs the irradiance
/// they shadow; 1024² is ~0.6 mm per texel on the scan, the shadow atlas's
/// 2048² tiles ~0.25 mm. Half the irradiance resolution costs no measurable
/// accuracy against the reference (docs/design/lighting.md) and a quarter of the time.
pub const MAX_RESOLUTION: u32 = 1024;
/// Three lights per texture (RGB), coverage in alpha, 8 bits each.
pub const FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
/// Textures the shaders bind (common/lights.glsl SOFT_VISIBILITY): nine lights,
/// more than frame_inputs::MAX_LIGHTS.
pub const TEXTURES: usize = 3;

pub struct VisibilityPass {
    pipeline: Arc<Pipeline>,
    /// The soft lights' (light_visibility.frag) or, `hard`, the other shadowed
    /// lights'.
    hard: bool,
    /// Some light of the kind has a shadow map.
    any: bool,
    /// Drawn by the render's first frame that needs them and kept, as the
    /// shadow atlas they come from.
    textures: Vec<Arc<Image>>,
}

impl VisibilityPass {
    /// The soft lights' pass and its textures at min(`resolution`/2,
    /// [`MAX_RESOLUTION`])² for an irradiance texture of `resolution`²; or
    /// (`hard`) the other shadowed lights' at `resolution`², which only the
    /// irradiance pass reads, texel for texel (the shading passes in screen
    /// space filter those lights per pixel). 1×1 when no light is of the kind,
    /// so the shading passes always have them to bind.
    pub fn new(
        pipelines: &Pipelines,
        variant: &ShaderVariant,
        resolution: u32,
        hard: bool,
    ) -> Result<Self> {
        let ctx = pipelines.ctx();
        let mut specialization = variant.specialization().to_vec();
        specialization.push(u32::from(hard));
        let pipeline = pipelines.graphics(&GraphicsDesc {
            vertex: "uv.vert",
            fragment: "light_visibility.frag",
            color_formats: &[FORMAT; TEXTURES],
            depth_format: None,
            depth_write: true,
            vertex_layout: Some(Vertex::layout()),
            // UV charts may be mirrored: both windings are surface.
            cull_mode: vk::CullModeFlags::NONE,
            specialization: &specialization,
            alpha_blend: false,
        })?;
        let lights = if hard {
            variant.shadowed & !variant.soft
        } else {
            variant.soft
        };
        // One pass draws all three: they share its render area.
        let side = match (lights != 0, hard) {
            (false, _) => 1,
            (true, true) => resolution,
            (true, false) => (resolution / 2).clamp(1, MAX_RESOLUTION),
        };
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED;
        let textures = (0..TEXTURES)
            .map(|k| {
                let desc = ImageDesc::new(side, side, FORMAT);
                Image::new(ctx, &name(hard, k), desc, usage).map(Arc::new)
            })
            .collect::<Result<_>>()?;
        Ok(Self {
            pipeline,
            hard,
            any: lights != 0,
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
        let names: [String; TEXTURES] = std::array::from_fn(|k| name(self.hard, k));
        let images = std::array::from_fn(|k| (names[k].as_str(), &self.textures[k]));
        let (mut out, draw) = g.import_kept_images(images, Access::ShaderSampled, key);
        if !draw {
            return out;
        }
        let s = &inputs.samplers;
        let pass_name = if self.hard {
            "hard_visibility"
        } else {
            "light_visibility"
        };
        let mut pass = g
            .simple_pass(pass_name, &self.pipeline)
            .tag(super::TAG)
            .uniform(&inputs.uniforms)
            .sample(atlas, &s.shadow)
            .sample(atlas, &s.nearest);
        for image in &mut out {
            pass = pass.color(image, LoadOp::Clear([0.0; 4]));
        }
        if self.any {
            inputs.mesh.draw(pass);
        } else {
            pass.record(|_| {});
        }
        out
    }
}

fn name(hard: bool, k: usize) -> String {
    let kind = if hard { "hard" } else { "soft" };
    format!("{kind} visibility {k}")
}
