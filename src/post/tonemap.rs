//! Exposure (EV stops) and the sRGB transfer function into an 8-bit target.

use crate::error::Result;
use crate::gpu::{Context, GraphicsDesc, Pipeline, Sampler};
use crate::graph::{Graph, ImageHandle, LoadOp};
use ash::vk;
use std::sync::Arc;

pub const LDR_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;

pub struct Tonemap {
    pipeline: Arc<Pipeline>,
    sampler: Arc<Sampler>,
}

impl Tonemap {
    pub fn new(ctx: &Arc<Context>, sampler: Arc<Sampler>) -> Result<Self> {
        let pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                vertex: "fullscreen.vert",
                fragment: "tonemap.frag",
                color_formats: &[LDR_FORMAT],
                depth_format: None,
                vertex_layout: None,
                cull_mode: vk::CullModeFlags::NONE,
            },
        )?;
        Ok(Self { pipeline, sampler })
    }

    /// `hdr` × 2^exposure, sRGB-encoded, into `ldr`.
    pub fn pass(&self, g: &mut Graph, hdr: &ImageHandle, ldr: &mut ImageHandle, exposure: f32) {
        g.simple_pass("tonemap", &self.pipeline)
            .sample(hdr, &self.sampler)
            .color(ldr, LoadOp::DontCare)
            .constants(&exposure)
            .draw(3);
    }
}
