//! The scene on the GPU: vertex and index buffers, textures (with GPU mips), the
//! environment map, the per-frame uniforms and samplers.

use crate::error::Result;
use crate::gpu::{Buffer, Context, Image, ImageDesc, Sampler};
use crate::graph::upload::{full_mip_count, upload_buffer, upload_texture};
use crate::graph::Access;
use crate::scene::env::EnvMap;
use crate::scene::mesh::Mesh;
use crate::scene::texture::{Encoding, Texture};
use ash::vk;
use std::sync::Arc;

/// Interleaved vertex: position (mm), normal, uv, tangent (w = bitangent sign).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
    pub tangent: [f32; 4],
}

/// The vertex layout the mesh pipelines declare: (format, offset) per location.
pub const VERTEX_ATTRIBUTES: [(vk::Format, u32); 4] = [
    (vk::Format::R32G32B32_SFLOAT, 0),
    (vk::Format::R32G32B32_SFLOAT, 12),
    (vk::Format::R32G32_SFLOAT, 24),
    (vk::Format::R32G32B32A32_SFLOAT, 32),
];

pub struct MeshBuffers {
    pub vertices: Arc<Buffer>,
    pub indices: Arc<Buffer>,
    pub index_count: u32,
}

impl MeshBuffers {
    pub fn upload(ctx: &Arc<Context>, mesh: &Mesh) -> Result<Self> {
        mesh.validate()
            .map_err(|m| crate::Error::Input(format!("mesh {:?}: {m}", mesh.name)))?;
        let vertices: Vec<Vertex> = (0..mesh.vertex_count())
            .map(|i| Vertex {
                position: mesh.positions[i].into(),
                normal: mesh.normals[i].into(),
                uv: mesh.uvs[i].into(),
                tangent: mesh.tangents[i].into(),
            })
            .collect();
        Ok(Self {
            vertices: upload_buffer(
                ctx,
                "vertices",
                bytemuck::cast_slice(&vertices),
                Access::VertexBuffer,
            )?,
            indices: upload_buffer(
                ctx,
                "indices",
                bytemuck::cast_slice(&mesh.indices),
                Access::IndexBuffer,
            )?,
            index_count: mesh.indices.len() as u32,
        })
    }
}

impl MeshBuffers {
    /// Binds the buffers and draws every triangle (for any pass that draws the mesh).
    pub fn draw(&self, cx: &crate::graph::PassCx) {
        cx.bind_vertex_buffer(&self.vertices);
        cx.bind_index_buffer(&self.indices);
        cx.draw_indexed(self.index_count, 1);
    }
}

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
pub fn upload_env(ctx: &Arc<Context>, env: &EnvMap) -> Result<Arc<Image>> {
    let texels: Vec<f32> = env
        .texels
        .iter()
        .flat_map(|c| [c.x, c.y, c.z, 1.0])
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

pub struct Samplers {
    pub linear: Arc<Sampler>,
    pub nearest: Arc<Sampler>,
    /// Depth comparison for the shadow atlas, bilinear where the device filters D32.
    pub shadow: Arc<Sampler>,
}

impl Samplers {
    pub fn new(ctx: &Arc<Context>) -> Result<Self> {
        let linear_depth = ctx.supports_linear_filter(crate::light::shadow::SHADOW_FORMAT);
        Ok(Self {
            linear: Arc::new(Sampler::clamped(ctx, true)?),
            nearest: Arc::new(Sampler::clamped(ctx, false)?),
            shadow: Arc::new(Sampler::shadow(ctx, linear_depth)?),
        })
    }
}
