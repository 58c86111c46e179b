//! Exposure (EV stops) and the output transfer function (`render.gamma`: the sRGB
//! curve of IEC 61966-2-1 or a pure power) into an 8-bit target. The CPU
//! [`encode8`] is the same function for images read back as floats.

use crate::error::Result;
use crate::gpu::{Context, GraphicsDesc, Pipeline, Sampler};
use crate::graph::{Graph, ImageHandle, LoadOp};
use crate::scene::file::Gamma;
use ash::vk;
use std::sync::Arc;

pub const LDR_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;

/// Push constants of tonemap.frag.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TonemapPush {
    exposure: f32,
    /// 0: the sRGB curve; else encoded = linear^(1/gamma).
    gamma: f32,
}

fn gamma_param(gamma: Gamma) -> f32 {
    match gamma {
        Gamma::Srgb => 0.0,
        Gamma::Power(g) => g,
    }
}

/// One channel, linear (after exposure) to encoded in [0, 1].
pub fn encode(c: f32, gamma: Gamma) -> f32 {
    let c = c.clamp(0.0, 1.0);
    match gamma {
        // IEC 61966-2-1.
        Gamma::Srgb if c <= 0.003_130_8 => 12.92 * c,
        Gamma::Srgb => 1.055 * c.powf(1.0 / 2.4) - 0.055,
        Gamma::Power(g) => c.powf(1.0 / g),
    }
}

/// Linear RGBA → 8-bit after × 2^exposure and the transfer function; alpha 255.
pub fn encode8(rgba: &[f32], exposure: f32, gamma: Gamma) -> Vec<u8> {
    let scale = exposure.exp2();
    let q = |c: f32| (encode(c * scale, gamma) * 255.0).round() as u8;
    rgba.chunks_exact(4)
        .flat_map(|p| [q(p[0]), q(p[1]), q(p[2]), 255])
        .collect()
}

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
                depth_write: true,
                vertex_layout: None,
                cull_mode: vk::CullModeFlags::NONE,
                specialization: &[],
                alpha_blend: false,
            },
        )?;
        Ok(Self { pipeline, sampler })
    }

    /// `hdr` × 2^exposure, encoded with `gamma`, into `ldr`.
    pub fn pass(
        &self,
        g: &mut Graph,
        hdr: &ImageHandle,
        ldr: &mut ImageHandle,
        exposure: f32,
        gamma: Gamma,
    ) {
        g.simple_pass("tonemap", &self.pipeline)
            .sample(hdr, &self.sampler)
            .color(ldr, LoadOp::DontCare)
            .constants(&TonemapPush {
                exposure,
                gamma: gamma_param(gamma),
            })
            .draw(3);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encodings_match_their_definitions() {
        // IEC 61966-2-1 reference points: 0.5 → 0.7354, 0.0031308 on the knee.
        assert!((encode(0.5, Gamma::Srgb) - 0.735_36).abs() < 1e-4);
        assert!((encode(0.003_130_8, Gamma::Srgb) - 0.040_45).abs() < 1e-4);
        assert_eq!(encode(0.25, Gamma::Power(2.0)), 0.5);
        assert_eq!(encode(0.25, Gamma::Power(1.0)), 0.25);
        assert!((encode(7.0, Gamma::Srgb) - 1.0).abs() < 1e-6);
        // Exposure +1 EV doubles before encoding.
        assert_eq!(
            encode8(&[0.125, 0.0, 1.0, 1.0], 1.0, Gamma::Power(1.0)),
            [64, 0, 255, 255]
        );
    }
}
