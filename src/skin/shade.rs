//! Final skin shading in screen space (GPU Gems 3 §14.5; the paper's Fig. 2):
//! Σ w_i · blur_i with the profile's RGB weights, × albedo^(1−mix), / π, plus the
//! KS specular of the lights and the environment, and the light of shadowed
//! lights transmitted through thin skin (docs/records/2026-11-26-transmission.md, "Transmission").

use super::tables::SpecularTables;
use crate::error::Result;
use crate::frame_inputs::{FrameInputs, ShaderVariant, Vertex, DEPTH_FORMAT, HDR_FORMAT};
use crate::gpu::{GraphicsDesc, ImageDesc, Pipeline, Pipelines};
use crate::graph::{BufferHandle, Graph, ImageHandle, LoadOp};
use ash::vk;
use std::sync::Arc;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ShadePush {
    /// rgb: the Gaussian's weights (w: std430's padding of a vec3 array).
    weights: [[f32; 4]; 6],
    mix_pre: f32,
    mode: u32,
    blur_amount: f32,
    transmission: f32,
    /// rgb: the summed weights of the levels evaluated per pixel.
    pixel_weight: [f32; 4],
}

/// The profile weights, albedo split and output of the final pass.
#[derive(Clone, Copy, Debug)]
pub struct ShadeSettings {
    /// RGB weight of each Gaussian (the paper's Fig. 2).
    pub weights: [glam::Vec3; 6],
    /// Scale on the transmitted light (SkinSettings::transmission). The pass's
    /// pipeline has the term only when it was built with it ([`ShadePass::new`]).
    pub transmission: f32,
    /// Pre-scatter share of the albedo.
    pub mix: f32,
    /// Share of the blurred levels in the diffuse term (SkinSettings::blur_amount).
    pub blur_amount: f32,
    pub mode: ShadeMode,
}

/// The frame's images the final pass reads.
pub struct ShadeImages<'a> {
    /// The environment's SH coefficients (light::sh_pass).
    pub sh: &'a BufferHandle,
    /// The unblurred irradiance.
    pub irradiance: &'a ImageHandle,
    /// The six blur levels (skin::blur::BlurChain::select).
    pub levels: &'a [&'a ImageHandle],
    /// The lights' shadow atlas (light::shadow).
    pub shadows: &'a ImageHandle,
    /// The soft lights' visibility textures (light::visibility).
    pub soft_visibility: &'a [ImageHandle],
    /// The KS-prefiltered environment (light::prefilter).
    pub specular_env: &'a ImageHandle,
    /// The light transmitted through thin skin, front and back
    /// (skin::translucent).
    pub translucent: &'a [ImageHandle; 2],
}

/// What the final pass writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadeMode {
    /// Subsurface diffuse plus specular.
    Full = 0,
    Diffuse = 1,
    Specular = 2,
    /// The light of shadowed lights behind the skin transmitted through it,
    /// as it adds to the final image (docs/records/2026-11-26-transmission.md, "Transmission").
    Transmission = 3,
}

impl ShadeMode {
    pub const ALL: [ShadeMode; 4] = [
        ShadeMode::Full,
        ShadeMode::Diffuse,
        ShadeMode::Specular,
        ShadeMode::Transmission,
    ];

    /// The view's name (`render --view`).
    pub fn name(self) -> &'static str {
        match self {
            ShadeMode::Full => "final",
            ShadeMode::Diffuse => "diffuse",
            ShadeMode::Specular => "specular",
            ShadeMode::Transmission => "transmission",
        }
    }
}

pub struct ShadePass {
    /// Depth only: the pre-pass (scanned heads are two-sided and not consistently
    /// wound, so back faces are not culled; without it their fragments are shaded
    /// wherever they are drawn before the faces in front: ~25 % of the pass).
    depth: Arc<Pipeline>,
    pipeline: Arc<Pipeline>,
    /// The leading levels that are the unblurred irradiance: the pass
    /// evaluates them per pixel and does not read their textures (skin.frag's
    /// PIXEL_LEVELS).
    pixel_levels: usize,
}

/// `constant_id` of skin.frag's `TRANSMISSION`, after frame.glsl's; then
/// `UNBLURRED` and `PIXEL_LEVELS`.
const TRANSMISSION_CONSTANT: usize = 6;

impl ShadePass {
    /// `transmission`: build the final pass with the transmitted term (a
    /// specialization constant: without it the shader is the one without the
    /// term, so `skin.transmission = 0` costs nothing and changes no bit).
    /// `unblurred`: with the unblurred irradiance mixed in (`skin.blur_amount`
    /// < 1; at 1 its lookup would be multiplied by 0). `pixel_levels`: how
    /// many leading levels the chain leaves unblurred
    /// (skin::chain::unblurred_levels); the pass evaluates the irradiance per
    /// pixel for them (skin.frag's PIXEL_LEVELS).
    pub fn new(
        pipelines: &Pipelines,
        variant: &ShaderVariant,
        transmission: bool,
        unblurred: bool,
        pixel_levels: usize,
    ) -> Result<Self> {
        let mut specialization = variant.specialization().to_vec();
        debug_assert_eq!(specialization.len(), TRANSMISSION_CONSTANT);
        specialization.push(u32::from(transmission));
        specialization.push(u32::from(unblurred));
        specialization.push(pixel_levels as u32);
        // The pre-pass transforms the position only; both vertex shaders
        // compute gl_Position alike and `precise`, so the shading pass's depth
        // equals the pre-pass's exactly.
        let mesh = |(vertex, fragment), vertex_layout, color_formats, depth_write| {
            pipelines.graphics(&GraphicsDesc {
                vertex,
                fragment,
                color_formats,
                depth_format: Some(DEPTH_FORMAT),
                depth_write,
                vertex_layout: Some(vertex_layout),
                cull_mode: vk::CullModeFlags::NONE,
                specialization: &specialization,
                alpha_blend: false,
            })
        };
        Ok(Self {
            depth: mesh(
                ("skin_depth.vert", "depth_only.frag"),
                Vertex::position_layout(),
                &[],
                true,
            )?,
            pipeline: mesh(
                ("skin.vert", "skin.frag"),
                Vertex::layout(),
                &[HDR_FORMAT],
                false,
            )?,
            pixel_levels,
        })
    }

    /// The depth pre-pass (`skin_depth`) at `(w, h)`: the mesh's depth, which
    /// the background and the final pass test against.
    pub fn depth(&self, g: &mut Graph, inputs: &FrameInputs, (w, h): (u32, u32)) -> ImageHandle {
        let mut depth = g.create_image("depth", ImageDesc::new(w, h, DEPTH_FORMAT));
        let pre = g
            .simple_pass("skin_depth", &self.depth)
            .uniform(&inputs.uniforms)
            .depth(&mut depth, LoadOp::Clear([1.0; 4]));
        inputs.mesh.draw(pre);
        depth
    }

    /// Draws the mesh over `hdr` (which holds the background) where `depth`
    /// ([`ShadePass::depth`]) holds it.
    #[allow(clippy::too_many_arguments)]
    pub fn pass(
        &self,
        g: &mut Graph,
        inputs: &FrameInputs,
        tables: &SpecularTables,
        images: ShadeImages,
        settings: ShadeSettings,
        hdr: &mut ImageHandle,
        depth: &mut ImageHandle,
    ) {
        let s = &inputs.samplers;
        // The order of skin.frag: frame, albedo, normal, shadow atlas, transfer,
        // SH, RGB transfer, specular environment, irradiance, six blur levels,
        // the specular bindings, the soft lights' visibility, the translucent
        // textures.
        let mut pass = g
            .simple_pass("skin", &self.pipeline)
            .uniform(&inputs.uniforms)
            .texture(&inputs.albedo, &s.linear)
            .texture(&inputs.normal, &s.linear)
            .sample(images.shadows, &s.shadow)
            .buffer(&inputs.transfer)
            .read_uniform(images.sh)
            .buffer(&inputs.rgb_transfer)
            .sample(images.specular_env, &s.linear)
            .sample(images.irradiance, &s.linear);
        for level in images.levels {
            pass = pass.sample(level, &s.linear);
        }
        let mut pass = tables.bind(pass, inputs);
        for v in images.soft_visibility {
            pass = pass.sample(v, &s.linear);
        }
        let pass = pass
            .sample(&images.translucent[0], &s.linear)
            .sample(&images.translucent[1], &s.linear)
            .color(hdr, LoadOp::Load)
            .depth(depth, LoadOp::Load)
            .constants(&ShadePush {
                weights: settings.weights.map(|w| w.extend(0.0).into()),
                mix_pre: settings.mix,
                mode: settings.mode as u32,
                blur_amount: settings.blur_amount,
                transmission: settings.transmission,
                pixel_weight: settings.weights[..self.pixel_levels]
                    .iter()
                    .sum::<glam::Vec3>()
                    .extend(0.0)
                    .into(),
            });
        inputs.mesh.draw(pass);
    }
}
