//! The commands the executor records around each pass: the planned barriers
//! and the dynamic-rendering scope of a raster pass (attachments, viewport,
//! scissor).

use super::pass_cx::ResolvedImage;
use super::plan::Barrier;
use super::{Attachment, LoadOp, PassDecl};
use crate::gpu::full_range;
use ash::vk;

pub(super) fn barriers(
    device: &ash::Device,
    cmd: vk::CommandBuffer,
    barriers: &[Barrier],
    images: &[Option<ResolvedImage>],
    buffers: &[Option<vk::Buffer>],
) {
    if barriers.is_empty() {
        return;
    }
    let mut image_barriers = Vec::new();
    let mut buffer_barriers = Vec::new();
    for b in barriers {
        match (b.layouts, images[b.resource], buffers[b.resource]) {
            (Some((old, new)), Some(img), _) => image_barriers.push(
                vk::ImageMemoryBarrier2::default()
                    .src_stage_mask(b.src_stage)
                    .src_access_mask(b.src_access)
                    .dst_stage_mask(b.dst_stage)
                    .dst_access_mask(b.dst_access)
                    .old_layout(old)
                    .new_layout(new)
                    .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .image(img.raw)
                    .subresource_range(full_range(img.desc.format, img.desc.mip_levels)),
            ),
            (None, _, Some(buffer)) => buffer_barriers.push(
                vk::BufferMemoryBarrier2::default()
                    .src_stage_mask(b.src_stage)
                    .src_access_mask(b.src_access)
                    .dst_stage_mask(b.dst_stage)
                    .dst_access_mask(b.dst_access)
                    .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .buffer(buffer)
                    .offset(0)
                    .size(vk::WHOLE_SIZE),
            ),
            _ => {}
        }
    }
    let dep = vk::DependencyInfo::default()
        .image_memory_barriers(&image_barriers)
        .buffer_memory_barriers(&buffer_barriers);
    unsafe { device.cmd_pipeline_barrier2(cmd, &dep) };
}

pub(super) fn begin_rendering(
    device: &ash::Device,
    cmd: vk::CommandBuffer,
    pass: &PassDecl,
    images: &[Option<ResolvedImage>],
) {
    let attachment = |a: &Attachment| {
        let img = images[a.resource].expect("attachments are images");
        let (load_op, clear) = match a.load {
            LoadOp::Clear(c) => (vk::AttachmentLoadOp::CLEAR, c),
            LoadOp::Load => (vk::AttachmentLoadOp::LOAD, [0.0; 4]),
            LoadOp::DontCare => (vk::AttachmentLoadOp::DONT_CARE, [0.0; 4]),
        };
        let clear_value = if a.depth {
            vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: clear[0],
                    stencil: 0,
                },
            }
        } else {
            vk::ClearValue {
                color: vk::ClearColorValue { float32: clear },
            }
        };
        let layout = if a.depth {
            vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL
        } else {
            vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL
        };
        let info = vk::RenderingAttachmentInfo::default()
            .image_view(img.view)
            .image_layout(layout)
            .load_op(load_op)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(clear_value);
        (info, img.desc.extent())
    };
    let colors: Vec<_> = pass
        .attachments
        .iter()
        .filter(|a| !a.depth)
        .map(|a| attachment(a).0)
        .collect();
    let depth = pass.attachments.iter().find(|a| a.depth).map(attachment);
    let extent = pass
        .attachments
        .first()
        .map(|a| attachment(a).1)
        .unwrap_or_default();
    let area = vk::Rect2D {
        offset: vk::Offset2D { x: 0, y: 0 },
        extent,
    };
    let mut info = vk::RenderingInfo::default()
        .render_area(area)
        .layer_count(1)
        .color_attachments(&colors);
    if let Some((d, _)) = &depth {
        info = info.depth_attachment(d);
    }
    let viewport = vk::Viewport {
        x: 0.0,
        y: 0.0,
        width: extent.width as f32,
        height: extent.height as f32,
        min_depth: 0.0,
        max_depth: 1.0,
    };
    unsafe {
        device.cmd_begin_rendering(cmd, &info);
        device.cmd_set_viewport(cmd, 0, &[viewport]);
        device.cmd_set_scissor(cmd, 0, &[area]);
    }
}
