//! The mesh on the GPU: the interleaved vertex layout every mesh pipeline
//! declares, and the vertex and index buffers.

use crate::error::{Error, Result};
use crate::gpu::{Buffer, Context};
use crate::graph::upload::upload_buffer;
use crate::graph::{Access, PassCx, SimplePass};
use crate::scene::mesh::Mesh;
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

// Shaders that read the vertex buffer as storage count 12 floats a vertex,
// the position at float 0 and the uv at float 6 (common/vertices.glsl).
const _: () = assert!(
    std::mem::size_of::<Vertex>() == 12 * 4
        && std::mem::offset_of!(Vertex, position) == 0
        && std::mem::offset_of!(Vertex, uv) == 6 * 4
);

/// The vertex layout the mesh pipelines declare: (format, offset) per location.
pub const VERTEX_ATTRIBUTES: [(vk::Format, u32); 4] = [
    (vk::Format::R32G32B32_SFLOAT, 0),
    (vk::Format::R32G32B32_SFLOAT, 12),
    (vk::Format::R32G32_SFLOAT, 24),
    (vk::Format::R32G32B32A32_SFLOAT, 32),
];

impl Vertex {
    /// Stride and attributes, as `GraphicsDesc::vertex_layout` takes them.
    pub fn layout() -> (u32, &'static [(vk::Format, u32)]) {
        (std::mem::size_of::<Vertex>() as u32, &VERTEX_ATTRIBUTES)
    }

    /// The position alone, for the depth-only passes (shadow maps, the
    /// occlusion cube maps, the skin's depth pre-pass).
    pub fn position_layout() -> (u32, &'static [(vk::Format, u32)]) {
        (
            std::mem::size_of::<Vertex>() as u32,
            &VERTEX_ATTRIBUTES[..1],
        )
    }
}

pub struct MeshBuffers {
    pub vertices: Arc<Buffer>,
    pub indices: Arc<Buffer>,
    pub index_count: u32,
    pub vertex_count: u32,
}

impl MeshBuffers {
    pub fn upload(ctx: &Arc<Context>, mesh: &Mesh) -> Result<Self> {
        mesh.validate()
            .map_err(|m| Error::Input(format!("mesh {:?}: {m}", mesh.name)))?;
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
            vertex_count: vertices.len() as u32,
        })
    }

    /// Finishes `pass` by drawing every triangle of the mesh.
    pub fn draw(&self, pass: SimplePass) {
        pass.draw_indexed(&self.vertices, &self.indices, self.index_count);
    }

    /// Draws every triangle from inside a custom pass body (several viewports).
    pub fn record_draw(&self, cx: &PassCx) {
        cx.bind_vertex_buffer(&self.vertices);
        cx.bind_index_buffer(&self.indices);
        cx.draw_indexed(self.index_count, 1);
    }
}
