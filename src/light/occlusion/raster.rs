//! The paper's occlusion method (§III.B, its ref. [16]) on the GPU: for every
//! vertex, the mesh is rendered black into a white cube map placed at the vertex,
//! and V(ω)·max(N·ω, 0) is projected onto the nine SH functions. Vertices are
//! batched: one atlas of face tiles per submission (a viewport per tile), then a
//! compute pass reduces each vertex's six tiles. `occlusion::raytrace` is the
//! independent CPU method it is compared with.

use super::transfer::Transfer;
use crate::error::{Error, Result};
use crate::frame_inputs::{MeshBuffers, Vertex};
use crate::gpu::{Buffer, Context, GraphicsDesc, ImageDesc, MemoryLocation, Pipeline, Sampler};
use crate::graph::upload::upload_buffer;
use crate::graph::{Access, Executor, Graph, Imported, LoadOp};
use crate::scene::mesh::Mesh;
use ash::vk;
use std::sync::Arc;

#[derive(Clone, Debug, PartialEq)]
pub struct RasterOptions {
    /// Side of one cube face in texels (6·N² directions per vertex).
    pub face_size: u32,
    /// Camera offset along the normal, mm, against self-occlusion (as the ray caster).
    pub offset_mm: f32,
    /// Side of the tile atlas; batch = (atlas / face_size)² / 6 vertices.
    pub atlas: u32,
}

impl Default for RasterOptions {
    fn default() -> Self {
        Self {
            face_size: 32,
            offset_mm: 0.1,
            atlas: 2048,
        }
    }
}

impl RasterOptions {
    /// The settings string for `occlusion::cache_key`.
    pub fn cache_settings(&self) -> String {
        format!(
            "face={} offset={} atlas={}",
            self.face_size, self.offset_mm, self.atlas
        )
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct CubePush {
    camera: [f32; 3],
    face: i32,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct ReducePush {
    first_vertex: u32,
    count: u32,
    face_size: u32,
    tiles_per_row: u32,
}

pub fn raster(
    ctx: &Arc<Context>,
    mesh: &Mesh,
    opts: &RasterOptions,
    progress: bool,
) -> Result<Transfer> {
    let all: Vec<u32> = (0..mesh.vertex_count() as u32).collect();
    raster_vertices(ctx, mesh, &all, opts, progress)
}

/// The transfer of the listed vertices only (in list order), e.g. to compare
/// methods on a sample.
pub fn raster_vertices(
    ctx: &Arc<Context>,
    mesh: &Mesh,
    vertices: &[u32],
    opts: &RasterOptions,
    progress: bool,
) -> Result<Transfer> {
    let face = opts.face_size.max(1);
    let tiles_per_row = opts.atlas / face;
    let batch = (tiles_per_row * tiles_per_row / 6) as usize;
    if batch == 0 {
        return Err(Error::Input(format!(
            "occlusion atlas {} is too small for {face}² faces",
            opts.atlas
        )));
    }
    if let Some(&bad) = vertices
        .iter()
        .find(|&&v| v as usize >= mesh.vertex_count())
    {
        return Err(Error::Input(format!(
            "occlusion: vertex {bad} is out of range"
        )));
    }
    let n = vertices.len();
    let buffers = Arc::new(MeshBuffers::upload(ctx, mesh)?);
    let normals: Vec<[f32; 4]> = vertices
        .iter()
        .map(|&v| mesh.normals[v as usize].extend(0.0).into())
        .collect();
    let normals = upload_buffer(
        ctx,
        "occlusion normals",
        bytemuck::cast_slice(&normals),
        Access::ShaderBufferRead,
    )?;
    let transfer = Arc::new(Buffer::new(
        ctx,
        "occlusion transfer",
        (n * 9 * 4) as u64,
        vk::BufferUsageFlags::STORAGE_BUFFER,
        MemoryLocation::GpuToCpu,
    )?);
    let cube = Pipeline::graphics(
        ctx,
        &GraphicsDesc {
            vertex: "occlusion_cube.vert",
            fragment: "occlusion_cube.frag",
            color_formats: &[vk::Format::R8_UNORM],
            depth_format: None,
            depth_write: true,
            // Positions only.
            vertex_layout: Some(Vertex::position_layout()),
            cull_mode: vk::CullModeFlags::NONE,
            specialization: &[],
            alpha_blend: false,
        },
    )?;
    let reduce = Pipeline::compute(ctx, "occlusion_reduce.comp")?;
    let sampler = Arc::new(Sampler::clamped(ctx, false)?);
    let cameras: Arc<Vec<[f32; 3]>> = Arc::new(
        vertices
            .iter()
            .map(|&v| {
                (mesh.positions[v as usize] + mesh.normals[v as usize] * opts.offset_mm).into()
            })
            .collect(),
    );
    let bar =
        progress.then(|| indicatif::ProgressBar::new(n as u64).with_message("occlusion (raster)"));
    let mut ex = Executor::new(ctx, 2)?;
    for first in (0..n).step_by(batch) {
        let count = batch.min(n - first);
        let mut g = Graph::new();
        let mut atlas = g.create_image(
            "occlusion atlas",
            ImageDesc::new(opts.atlas, opts.atlas, vk::Format::R8_UNORM),
        );
        let (pipe, mesh_buffers, cams) = (cube.clone(), buffers.clone(), cameras.clone());
        let p = g
            .simple_pass("occlusion_raster", &cube)
            .color(&mut atlas, LoadOp::Clear([1.0; 4]));
        p.record(move |cx| {
            cx.bind_vertex_buffer(&mesh_buffers.vertices);
            cx.bind_index_buffer(&mesh_buffers.indices);
            for v in 0..count {
                for f in 0..6u32 {
                    let tile = v as u32 * 6 + f;
                    cx.set_viewport(
                        (tile % tiles_per_row) * face,
                        (tile / tiles_per_row) * face,
                        face,
                        face,
                    );
                    cx.push_constants(
                        &pipe,
                        &CubePush {
                            camera: cams[first + v],
                            face: f as i32,
                        },
                    );
                    cx.draw_indexed(mesh_buffers.index_count, 1);
                }
            }
        });
        let mut out = g.import_buffer(
            "occlusion transfer",
            Imported::Buffer(transfer.clone()),
            Some(Access::HostRead),
            Some(Access::HostRead),
        );
        // One workgroup per vertex.
        g.simple_pass("occlusion_reduce", &reduce)
            .sample(&atlas, &sampler)
            .buffer(&normals)
            .write_buffer(&mut out)
            .constants(&ReducePush {
                first_vertex: first as u32,
                count: count as u32,
                face_size: face,
                tiles_per_row,
            })
            .dispatch_groups([count as u32, 1, 1]);
        ex.run(g)?;
        if let Some(b) = &bar {
            b.inc(count as u64);
        }
    }
    ex.finish()?;
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let bytes = transfer
        .mapped()
        .ok_or_else(|| Error::Graph("transfer buffer is not host-visible".into()))?;
    let values: &[f32] = bytemuck::cast_slice(bytes);
    Ok(Transfer {
        coeffs: values
            .chunks_exact(9)
            .map(|c| std::array::from_fn(|i| c[i]))
            .collect(),
    })
}
