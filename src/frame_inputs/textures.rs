//! Textures and the environment map on the GPU, with GPU-generated mips.

use crate::error::Result;
use crate::gpu::{Context, Image, ImageDesc};
use crate::graph::upload::{full_mip_count, upload_texture};
use crate::scene::env::EnvMap;
use crate::scene::texture::{Encoding, Texture};
use ash::vk;
use std::sync::Arc;

/// An RGBA8 texture with a full GPU-generated mip chain; sRGB maps get an
/// `_SRGB` format so shaders sample linear values.
pub fn upload_rgba8(ctx: &Arc<Context>, name: &str, t: &Texture) -> Result<Arc<Image>> {
    let format = match t.encoding {
        Encoding::Srgb => vk::Format::R8G8B8A8_SRGB,
        Encoding::Linear => vk::Format::R8G8B8A8_UNORM,
    };
    let desc = ImageDesc {
        mip_levels: full_mip_count(t.width, t.height),
        ..ImageDesc::new(t.width, t.height, format)
    };
    upload_texture(ctx, name, desc, &t.rgba8)
}

/// The environment as RGBA32F: the sky's sun disk (~1e6 kcd/m²) does not fit
/// in half floats (max 65504). With a full mip chain where the device filters
/// RGBA32F (the specular prefilter reads coarse levels), else one level.
/// Texels × `scale` (the scene's map pre-exposure, scene::range).
pub fn upload_env(ctx: &Arc<Context>, env: &EnvMap, scale: f32) -> Result<Arc<Image>> {
    let texels: Vec<f32> = env
        .texels
        .iter()
        .flat_map(|c| [c.x * scale, c.y * scale, c.z * scale, 1.0])
        .collect();
    let format = vk::Format::R32G32B32A32_SFLOAT;
    let desc = ImageDesc {
        mip_levels: if ctx.supports_linear_filter(format) {
            full_mip_count(env.width, env.height)
        } else {
            1
        },
        ..ImageDesc::new(env.width, env.height, format)
    };
    upload_texture(ctx, "environment", desc, bytemuck::cast_slice(&texels))
}
