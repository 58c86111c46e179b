//! What a pass's recording closure works with: its resolved resources and the
//! few commands passes record (bind, push descriptors and constants, dispatch,
//! draw, copies, mips, clears). The only place outside `gpu/` with raw `cmd_*`
//! calls besides the executor's barriers, labels and timestamps.

use super::{BufferRef, ImageRef};
use crate::gpu::{full_range, Buffer, Context, Image, ImageDesc, Pipeline, Sampler};
use ash::vk;
use std::sync::Arc;

#[derive(Clone, Copy, Debug)]
pub struct ResolvedImage {
    pub raw: vk::Image,
    pub view: vk::ImageView,
    pub desc: ImageDesc,
}

/// A descriptor for [`PassCx::push_descriptors`]; layouts follow the graph's
/// access vocabulary (storage: GENERAL, sampled: SHADER_READ_ONLY_OPTIMAL).
pub enum Descriptor<'a> {
    StorageImage(ImageRef),
    Sampled(ImageRef, &'a Sampler),
    /// An image outside the graph, already in SHADER_READ_ONLY_OPTIMAL.
    StaticSampled(&'a Image, &'a Sampler),
    Uniform(BufferRef),
    Storage(BufferRef),
    /// A static uniform buffer outside the graph (uploaded with final access `UniformRead`).
    StaticUniform(&'a Buffer),
    /// A static storage buffer outside the graph (uploaded with `ComputeBufferRead`).
    StaticStorage(&'a Buffer),
}

/// What a pass's closure records with.
pub struct PassCx<'a> {
    pub ctx: &'a Arc<Context>,
    pub cmd: vk::CommandBuffer,
    images: &'a [Option<ResolvedImage>],
    buffers: &'a [Option<vk::Buffer>],
}

impl<'a> PassCx<'a> {
    pub(super) fn new(
        ctx: &'a Arc<Context>,
        cmd: vk::CommandBuffer,
        images: &'a [Option<ResolvedImage>],
        buffers: &'a [Option<vk::Buffer>],
    ) -> Self {
        Self {
            ctx,
            cmd,
            images,
            buffers,
        }
    }

    pub fn image(&self, r: ImageRef) -> ResolvedImage {
        self.images[r.0].expect("ImageRef names an image of this graph")
    }

    pub fn buffer(&self, r: BufferRef) -> vk::Buffer {
        self.buffers[r.0].expect("BufferRef names a buffer of this graph")
    }

    fn device(&self) -> &ash::Device {
        &self.ctx.device
    }

    pub fn bind(&self, p: &Pipeline) {
        unsafe {
            self.device()
                .cmd_bind_pipeline(self.cmd, p.bind_point, p.raw)
        };
    }

    /// Pushes set 0: (binding number, descriptor) pairs.
    pub fn push_descriptors(&self, p: &Pipeline, descriptors: &[(u32, Descriptor)]) {
        let image = |view, sampler: Option<&Sampler>, layout| vk::DescriptorImageInfo {
            sampler: sampler.map_or(vk::Sampler::null(), |s| s.raw),
            image_view: view,
            image_layout: layout,
        };
        let buffer = |raw| vk::DescriptorBufferInfo {
            buffer: raw,
            offset: 0,
            range: vk::WHOLE_SIZE,
        };
        let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        // (binding, type, image info, buffer info) per descriptor.
        let infos: Vec<_> = descriptors
            .iter()
            .map(|(binding, d)| {
                let (ty, img, buf) = match *d {
                    Descriptor::StorageImage(r) => (
                        vk::DescriptorType::STORAGE_IMAGE,
                        Some(image(self.image(r).view, None, vk::ImageLayout::GENERAL)),
                        None,
                    ),
                    Descriptor::Sampled(r, s) => (
                        vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                        Some(image(self.image(r).view, Some(s), read_only)),
                        None,
                    ),
                    Descriptor::StaticSampled(i, s) => (
                        vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                        Some(image(i.view, Some(s), read_only)),
                        None,
                    ),
                    Descriptor::Uniform(b) => (
                        vk::DescriptorType::UNIFORM_BUFFER,
                        None,
                        Some(buffer(self.buffer(b))),
                    ),
                    Descriptor::Storage(b) => (
                        vk::DescriptorType::STORAGE_BUFFER,
                        None,
                        Some(buffer(self.buffer(b))),
                    ),
                    Descriptor::StaticUniform(b) => (
                        vk::DescriptorType::UNIFORM_BUFFER,
                        None,
                        Some(buffer(b.raw)),
                    ),
                    Descriptor::StaticStorage(b) => (
                        vk::DescriptorType::STORAGE_BUFFER,
                        None,
                        Some(buffer(b.raw)),
                    ),
                };
                (*binding, ty, img, buf)
            })
            .collect();
        let writes: Vec<_> = infos
            .iter()
            .map(|(binding, ty, img, buf)| {
                let w = vk::WriteDescriptorSet::default()
                    .dst_binding(*binding)
                    .descriptor_type(*ty);
                match (img, buf) {
                    (Some(i), _) => w.image_info(std::slice::from_ref(i)),
                    (_, Some(b)) => w.buffer_info(std::slice::from_ref(b)),
                    _ => w,
                }
            })
            .collect();
        unsafe {
            self.ctx.push_descriptor.cmd_push_descriptor_set(
                self.cmd,
                p.bind_point,
                p.layout,
                0,
                &writes,
            )
        };
    }

    pub fn push_constants<T: bytemuck::NoUninit>(&self, p: &Pipeline, data: &T) {
        self.push_constant_bytes(p, bytemuck::bytes_of(data));
    }

    pub fn push_constant_bytes(&self, p: &Pipeline, bytes: &[u8]) {
        unsafe {
            self.device()
                .cmd_push_constants(self.cmd, p.layout, p.stages, 0, bytes)
        };
    }

    /// Dispatches `groups` workgroups (x, y, z).
    pub fn dispatch(&self, groups: [u32; 3]) {
        unsafe {
            self.device()
                .cmd_dispatch(self.cmd, groups[0], groups[1], groups[2])
        };
    }

    /// Binds a static vertex buffer (uploaded with final access `VertexBuffer`).
    pub fn bind_vertex_buffer(&self, buffer: &Buffer) {
        unsafe {
            self.device()
                .cmd_bind_vertex_buffers(self.cmd, 0, &[buffer.raw], &[0])
        };
    }

    /// Binds a static u32 index buffer (uploaded with final access `IndexBuffer`).
    pub fn bind_index_buffer(&self, buffer: &Buffer) {
        unsafe {
            self.device()
                .cmd_bind_index_buffer(self.cmd, buffer.raw, 0, vk::IndexType::UINT32)
        };
    }

    pub fn draw_indexed(&self, indices: u32, instances: u32) {
        unsafe {
            self.device()
                .cmd_draw_indexed(self.cmd, indices, instances, 0, 0, 0)
        };
    }

    /// Restricts drawing to a rectangle of the attachment (viewport and scissor).
    pub fn set_viewport(&self, x: u32, y: u32, width: u32, height: u32) {
        let viewport = vk::Viewport {
            x: x as f32,
            y: y as f32,
            width: width as f32,
            height: height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        let scissor = vk::Rect2D {
            offset: vk::Offset2D {
                x: x as i32,
                y: y as i32,
            },
            extent: vk::Extent2D { width, height },
        };
        unsafe {
            self.device().cmd_set_viewport(self.cmd, 0, &[viewport]);
            self.device().cmd_set_scissor(self.cmd, 0, &[scissor]);
        }
    }

    /// Restricts drawing to a rectangle of the attachment (scissor only).
    pub fn set_scissor(&self, x: u32, y: u32, width: u32, height: u32) {
        let scissor = vk::Rect2D {
            offset: vk::Offset2D {
                x: x as i32,
                y: y as i32,
            },
            extent: vk::Extent2D { width, height },
        };
        unsafe { self.device().cmd_set_scissor(self.cmd, 0, &[scissor]) };
    }

    /// `count` indices from `first` of the bound index buffer, each plus `vertex_offset`.
    pub fn draw_indexed_range(&self, count: u32, first: u32, vertex_offset: i32) {
        unsafe {
            self.device()
                .cmd_draw_indexed(self.cmd, count, 1, first, vertex_offset, 0)
        };
    }

    pub fn draw(&self, vertices: u32, instances: u32) {
        unsafe { self.device().cmd_draw(self.cmd, vertices, instances, 0, 0) };
    }

    /// Copies the first `size` bytes of `src` to the start of `dst`.
    pub fn copy_buffer(&self, src: BufferRef, dst: BufferRef, size: u64) {
        let region = vk::BufferCopy {
            src_offset: 0,
            dst_offset: 0,
            size,
        };
        unsafe {
            self.device()
                .cmd_copy_buffer(self.cmd, self.buffer(src), self.buffer(dst), &[region])
        };
    }

    /// Copies level 0 of `src` (TRANSFER_SRC_OPTIMAL) into `dst` (TRANSFER_DST_OPTIMAL):
    /// same size and format.
    pub fn copy_image(&self, src: ImageRef, dst: ImageRef) {
        let (s, d) = (self.image(src), self.image(dst));
        let layers = color_layers(0);
        let region = vk::ImageCopy::default()
            .src_subresource(layers)
            .dst_subresource(layers)
            .extent(vk::Extent3D {
                width: s.desc.width.min(d.desc.width),
                height: s.desc.height.min(d.desc.height),
                depth: 1,
            });
        unsafe {
            self.device().cmd_copy_image(
                self.cmd,
                s.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                d.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
            )
        };
    }

    /// Copies `src` into `dst` (same size and format) with its rows in reverse
    /// order: a blit from the bottom row up.
    pub fn copy_image_flipped(&self, src: ImageRef, dst: ImageRef) {
        let (s, d) = (self.image(src), self.image(dst));
        let layers = color_layers(0);
        let (w, h) = (s.desc.width as i32, s.desc.height as i32);
        let region = vk::ImageBlit2::default()
            .src_subresource(layers)
            .src_offsets([
                vk::Offset3D { x: 0, y: h, z: 0 },
                vk::Offset3D { x: w, y: 0, z: 1 },
            ])
            .dst_subresource(layers)
            .dst_offsets([vk::Offset3D::default(), vk::Offset3D { x: w, y: h, z: 1 }]);
        let regions = [region];
        let blit = vk::BlitImageInfo2::default()
            .src_image(s.raw)
            .src_image_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
            .dst_image(d.raw)
            .dst_image_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
            .regions(&regions)
            .filter(vk::Filter::NEAREST);
        unsafe { self.device().cmd_blit_image2(self.cmd, &blit) };
    }

    pub fn copy_image_to_buffer(&self, image: ImageRef, buffer: BufferRef) {
        self.copy_level_to_buffer(image, 0, buffer);
    }

    /// Copies mip `level` of `image` into the start of `buffer`, tightly packed.
    pub fn copy_level_to_buffer(&self, image: ImageRef, level: u32, buffer: BufferRef) {
        let img = self.image(image);
        let region = vk::BufferImageCopy::default()
            .image_subresource(color_layers(level))
            .image_extent(vk::Extent3D {
                width: (img.desc.width >> level).max(1),
                height: (img.desc.height >> level).max(1),
                depth: 1,
            });
        unsafe {
            self.device().cmd_copy_image_to_buffer(
                self.cmd,
                img.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                self.buffer(buffer),
                &[region],
            )
        };
    }

    pub fn copy_buffer_to_image(&self, buffer: BufferRef, image: ImageRef) {
        let img = self.image(image);
        let region = vk::BufferImageCopy::default()
            .image_subresource(color_layers(0))
            .image_extent(vk::Extent3D {
                width: img.desc.width,
                height: img.desc.height,
                depth: 1,
            });
        unsafe {
            self.device().cmd_copy_buffer_to_image(
                self.cmd,
                self.buffer(buffer),
                img.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
            )
        };
    }

    /// Fills mip levels 1.. from level 0 by successive linear blits, for a pass
    /// that declared [`Access::Blit`](super::Access::Blit). The per-level barriers
    /// between blits are internal to this pass; all levels end in
    /// TRANSFER_DST_OPTIMAL, as the graph expects after `Blit`.
    pub fn generate_mips(&self, image: ImageRef) {
        use vk::AccessFlags2 as A;
        use vk::ImageLayout as L;
        use vk::PipelineStageFlags2 as S;
        let img = self.image(image);
        let levels = img.desc.mip_levels;
        let level = |base: u32, count: u32| vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: base,
            level_count: count,
            base_array_layer: 0,
            layer_count: 1,
        };
        let barrier = |range, old, new, src_access, dst_access| {
            vk::ImageMemoryBarrier2::default()
                .src_stage_mask(S::BLIT | S::COPY)
                .src_access_mask(src_access)
                .dst_stage_mask(S::BLIT)
                .dst_access_mask(dst_access)
                .old_layout(old)
                .new_layout(new)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(img.raw)
                .subresource_range(range)
        };
        let d = self.device();
        let (mut w, mut h) = (img.desc.width as i32, img.desc.height as i32);
        for i in 1..levels {
            let to_src = [barrier(
                level(i - 1, 1),
                L::TRANSFER_DST_OPTIMAL,
                L::TRANSFER_SRC_OPTIMAL,
                A::TRANSFER_WRITE,
                A::TRANSFER_READ,
            )];
            unsafe {
                d.cmd_pipeline_barrier2(
                    self.cmd,
                    &vk::DependencyInfo::default().image_memory_barriers(&to_src),
                )
            };
            let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
            let region = vk::ImageBlit2::default()
                .src_subresource(color_layers(i - 1))
                .src_offsets([vk::Offset3D::default(), vk::Offset3D { x: w, y: h, z: 1 }])
                .dst_subresource(color_layers(i))
                .dst_offsets([vk::Offset3D::default(), vk::Offset3D { x: nw, y: nh, z: 1 }]);
            let regions = [region];
            let blit = vk::BlitImageInfo2::default()
                .src_image(img.raw)
                .src_image_layout(L::TRANSFER_SRC_OPTIMAL)
                .dst_image(img.raw)
                .dst_image_layout(L::TRANSFER_DST_OPTIMAL)
                .regions(&regions)
                .filter(vk::Filter::LINEAR);
            unsafe { d.cmd_blit_image2(self.cmd, &blit) };
            (w, h) = (nw, nh);
        }
        if levels > 1 {
            let back = [barrier(
                level(0, levels - 1),
                L::TRANSFER_SRC_OPTIMAL,
                L::TRANSFER_DST_OPTIMAL,
                A::NONE,
                A::TRANSFER_READ | A::TRANSFER_WRITE,
            )];
            unsafe {
                d.cmd_pipeline_barrier2(
                    self.cmd,
                    &vk::DependencyInfo::default().image_memory_barriers(&back),
                )
            };
        }
    }

    pub fn clear_image(&self, image: ImageRef, rgba: [f32; 4]) {
        let img = self.image(image);
        let value = vk::ClearColorValue { float32: rgba };
        unsafe {
            self.device().cmd_clear_color_image(
                self.cmd,
                img.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &value,
                &[full_range(img.desc.format, img.desc.mip_levels)],
            )
        };
    }
}

/// Mip `level` of a colour image's single layer, for copies and blits.
fn color_layers(level: u32) -> vk::ImageSubresourceLayers {
    vk::ImageSubresourceLayers {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        mip_level: level,
        base_array_layer: 0,
        layer_count: 1,
    }
}
