//! egui drawn by our own pass in the render graph: its textures uploaded when
//! egui changes them, its meshes copied each frame into host-visible buffers (a
//! ring one longer than the frames in flight, so no buffer is rewritten while a
//! frame reads it), one indexed draw per mesh with its clip rectangle as the
//! scissor and its texture pushed as the descriptor.

use crate::error::{Error, Result};
use crate::gpu::{
    Buffer, Context, GraphicsDesc, Image, ImageDesc, MemoryLocation, Pipeline, Sampler,
};
use crate::graph::upload::upload_texture;
use crate::graph::{Descriptor, Graph, ImageHandle, LoadOp};
use ash::vk;
use egui::epaint::{ClippedPrimitive, Primitive, Vertex};
use egui::{ImageData, TextureId, TexturesDelta};
use std::collections::HashMap;
use std::sync::Arc;

/// Vertex and index buffers kept: frames in flight (2) + 1.
const RING: usize = 3;

/// One draw: a mesh's indices, its texture and its scissor (pixels).
struct Draw {
    texture: Arc<Image>,
    scissor: [u32; 4],
    first_index: u32,
    count: u32,
    vertex_offset: i32,
}

/// A texture as egui last set it: the pixels (for partial updates) and the image.
struct Texture {
    size: [usize; 2],
    pixels: Vec<egui::Color32>,
    image: Arc<Image>,
}

pub struct EguiPass {
    ctx: Arc<Context>,
    pipeline: Arc<Pipeline>,
    sampler: Arc<Sampler>,
    textures: HashMap<TextureId, Texture>,
    /// (vertices, indices) per ring slot.
    ring: Vec<Option<(Buffer, Buffer)>>,
    /// Buffers of earlier frames, dropped when their slot comes round again.
    in_use: Vec<Option<(Arc<Buffer>, Arc<Buffer>)>>,
    next: usize,
}

impl EguiPass {
    /// A pass drawing into targets of `format`.
    pub fn new(ctx: &Arc<Context>, format: vk::Format) -> Result<Self> {
        let stride = std::mem::size_of::<Vertex>() as u32;
        let pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                vertex: "egui.vert",
                fragment: "egui.frag",
                color_formats: &[format],
                depth_format: None,
                depth_write: false,
                vertex_layout: Some((
                    stride,
                    &[
                        (vk::Format::R32G32_SFLOAT, 0),
                        (vk::Format::R32G32_SFLOAT, 8),
                        (vk::Format::R8G8B8A8_UNORM, 16),
                    ],
                )),
                cull_mode: vk::CullModeFlags::NONE,
                specialization: &[],
                alpha_blend: true,
            },
        )?;
        Ok(Self {
            ctx: ctx.clone(),
            pipeline,
            sampler: Arc::new(Sampler::clamped(ctx, true)?),
            textures: HashMap::new(),
            ring: (0..RING).map(|_| None).collect(),
            in_use: (0..RING).map(|_| None).collect(),
            next: 0,
        })
    }

    /// Applies egui's texture changes: whole textures and patches uploaded,
    /// freed ones dropped (a frame still using one keeps its image alive).
    pub fn update_textures(&mut self, delta: &TexturesDelta) -> Result<()> {
        for (id, d) in delta
            .set
            .iter()
            .flat_map(|(id, ds)| ds.iter().map(move |d| (id, d)))
        {
            let ImageData::Color(patch) = &d.image;
            let (size, pixels) = match (d.pos, self.textures.remove(id)) {
                (None, _) => (patch.size, patch.pixels.clone()),
                (
                    Some([x0, y0]),
                    Some(Texture {
                        size, mut pixels, ..
                    }),
                ) => {
                    for y in 0..patch.size[1] {
                        let row = &patch.pixels[y * patch.size[0]..(y + 1) * patch.size[0]];
                        let start = (y0 + y) * size[0] + x0;
                        pixels[start..start + row.len()].copy_from_slice(row);
                    }
                    (size, pixels)
                }
                (Some(_), None) => {
                    return Err(Error::Graph(format!(
                        "egui patches {id:?} before setting it"
                    )));
                }
            };
            let desc = ImageDesc::new(size[0] as u32, size[1] as u32, vk::Format::R8G8B8A8_UNORM);
            let bytes: &[u8] = bytemuck::cast_slice(&pixels);
            let image = upload_texture(&self.ctx, &format!("egui {id:?}"), desc, bytes)?;
            self.textures.insert(
                *id,
                Texture {
                    size,
                    pixels,
                    image,
                },
            );
        }
        for id in &delta.free {
            self.textures.remove(id);
        }
        Ok(())
    }

    /// Draws `primitives` (egui's tessellation at `pixels_per_point`) over `target`.
    pub fn pass(
        &mut self,
        g: &mut Graph,
        target: &mut ImageHandle,
        primitives: &[ClippedPrimitive],
        pixels_per_point: f32,
    ) -> Result<()> {
        let (width, height) = (target.desc.width, target.desc.height);
        let (mut vertices, mut indices, mut draws) = (Vec::new(), Vec::<u32>::new(), Vec::new());
        for p in primitives {
            let Primitive::Mesh(mesh) = &p.primitive else {
                continue; // paint callbacks: none are registered
            };
            let Some(texture) = self.textures.get(&mesh.texture_id) else {
                continue;
            };
            let clip = p.clip_rect * pixels_per_point;
            let x0 = (clip.min.x.round().max(0.0) as u32).min(width);
            let y0 = (clip.min.y.round().max(0.0) as u32).min(height);
            let x1 = (clip.max.x.round().max(0.0) as u32).min(width);
            let y1 = (clip.max.y.round().max(0.0) as u32).min(height);
            if x1 <= x0 || y1 <= y0 || mesh.indices.is_empty() {
                continue;
            }
            draws.push(Draw {
                texture: texture.image.clone(),
                scissor: [x0, y0, x1 - x0, y1 - y0],
                first_index: indices.len() as u32,
                count: mesh.indices.len() as u32,
                vertex_offset: vertices.len() as i32,
            });
            vertices.extend_from_slice(&mesh.vertices);
            indices.extend_from_slice(&mesh.indices);
        }
        let Some(first) = draws.first().map(|d| d.texture.clone()) else {
            return Ok(());
        };
        let (vb, ib) = self.buffers(
            bytemuck::cast_slice(&vertices),
            bytemuck::cast_slice(&indices),
        )?;
        let points = [
            width as f32 / pixels_per_point,
            height as f32 / pixels_per_point,
        ];
        let (pipeline, sampler) = (self.pipeline.clone(), self.sampler.clone());
        g.simple_pass("ui", &self.pipeline)
            .texture(&first, &self.sampler)
            .color(target, LoadOp::Load)
            .constants(&points)
            .record(move |cx| {
                cx.bind_vertex_buffer(&vb);
                cx.bind_index_buffer(&ib);
                let mut bound = first.raw;
                for d in &draws {
                    if d.texture.raw != bound {
                        cx.push_descriptors(
                            &pipeline,
                            &[(0, Descriptor::StaticSampled(&d.texture, &sampler))],
                        );
                        bound = d.texture.raw;
                    }
                    let [x, y, w, h] = d.scissor;
                    cx.set_scissor(x, y, w, h);
                    cx.draw_indexed_range(d.count, d.first_index, d.vertex_offset);
                }
            });
        Ok(())
    }

    /// This frame's vertex and index buffers holding `vertices` and `indices`:
    /// the ring slot's own when no frame holds them any more and they are large
    /// enough, else new ones (sized to the next power of two).
    fn buffers(&mut self, vertices: &[u8], indices: &[u8]) -> Result<(Arc<Buffer>, Arc<Buffer>)> {
        let slot = self.next;
        self.next = (self.next + 1) % RING;
        // The frame that used this slot RING frames ago has been retired.
        if let Some((v, i)) = self.in_use[slot].take() {
            self.ring[slot] = Arc::try_unwrap(v).ok().zip(Arc::try_unwrap(i).ok());
        }
        let fits = |b: &Buffer, n: usize| b.size as usize >= n;
        let mut pair = match self.ring[slot].take() {
            Some((v, i)) if fits(&v, vertices.len()) && fits(&i, indices.len()) => (v, i),
            _ => {
                let buffer = |name: &str, n: usize, usage| {
                    Buffer::new(
                        &self.ctx,
                        name,
                        n.next_power_of_two().max(4096) as u64,
                        usage,
                        MemoryLocation::CpuToGpu,
                    )
                };
                (
                    buffer(
                        "egui vertices",
                        vertices.len(),
                        vk::BufferUsageFlags::VERTEX_BUFFER,
                    )?,
                    buffer(
                        "egui indices",
                        indices.len(),
                        vk::BufferUsageFlags::INDEX_BUFFER,
                    )?,
                )
            }
        };
        for (buffer, bytes) in [(&mut pair.0, vertices), (&mut pair.1, indices)] {
            let mapped = buffer
                .mapped_mut()
                .ok_or_else(|| Error::Graph("egui buffers are not host-visible".into()))?;
            mapped[..bytes.len()].copy_from_slice(bytes);
        }
        let pair = (Arc::new(pair.0), Arc::new(pair.1));
        self.in_use[slot] = Some(pair.clone());
        Ok(pair)
    }
}
