//! Images, buffers and samplers. Each owns its memory and holds the context alive,
//! so destruction order is right on every path (errors included).

use super::Context;
use crate::error::{Error, Result, VkResultExt};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

/// The shape of a 2D image; with usage it keys the transient pool.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ImageDesc {
    pub width: u32,
    pub height: u32,
    pub format: vk::Format,
    pub mip_levels: u32,
}

impl ImageDesc {
    pub fn new(width: u32, height: u32, format: vk::Format) -> Self {
        Self {
            width,
            height,
            format,
            mip_levels: 1,
        }
    }
    pub fn extent(&self) -> vk::Extent2D {
        vk::Extent2D {
            width: self.width,
            height: self.height,
        }
    }
}

/// Bytes per texel of the formats dermis uses (for readback and memory reports).
pub fn texel_bytes(format: vk::Format) -> Option<u32> {
    Some(match format {
        vk::Format::R8_UNORM => 1,
        vk::Format::R8G8B8A8_UNORM
        | vk::Format::R8G8B8A8_SRGB
        | vk::Format::R32_SFLOAT
        | vk::Format::D32_SFLOAT => 4,
        vk::Format::R16G16B16A16_SFLOAT
        | vk::Format::R16G16B16A16_UNORM
        | vk::Format::R32G32_SFLOAT => 8,
        vk::Format::R32G32B32A32_SFLOAT => 16,
        _ => return None,
    })
}

pub struct Image {
    ctx: Arc<Context>,
    pub raw: vk::Image,
    pub view: vk::ImageView,
    pub desc: ImageDesc,
    pub usage: vk::ImageUsageFlags,
    allocation: Option<Allocation>,
    /// The image is someone else's (a swapchain's): only the view is ours.
    external: bool,
}

impl Image {
    pub fn new(
        ctx: &Arc<Context>,
        name: &str,
        desc: ImageDesc,
        usage: vk::ImageUsageFlags,
    ) -> Result<Self> {
        let max = ctx.info.max_image_dimension_2d;
        if desc.width == 0 || desc.height == 0 || desc.width > max || desc.height > max {
            return Err(Error::Input(format!(
                "image {name}: {}x{} is outside what {} allows (1..={max} per side)",
                desc.width, desc.height, ctx.info.name
            )));
        }
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(desc.format)
            .extent(vk::Extent3D {
                width: desc.width,
                height: desc.height,
                depth: 1,
            })
            .mip_levels(desc.mip_levels)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let device = &ctx.device;
        let raw = unsafe { device.create_image(&info, None) }.vk("vkCreateImage")?;
        // Build the rest inside a value whose Drop releases what exists so far.
        let mut image = Image {
            ctx: ctx.clone(),
            raw,
            view: vk::ImageView::null(),
            desc,
            usage,
            allocation: None,
            external: false,
        };
        let requirements = unsafe { device.get_image_memory_requirements(raw) };
        let allocation = allocate(ctx, name, requirements, MemoryLocation::GpuOnly, false)?;
        unsafe { device.bind_image_memory(raw, allocation.memory(), allocation.offset()) }
            .vk("vkBindImageMemory")?;
        image.allocation = Some(allocation);
        image.create_view(name)?;
        ctx.name(raw, name);
        Ok(image)
    }

    /// The view of every level, named `name`.
    fn create_view(&mut self, name: &str) -> Result<()> {
        let view_info = vk::ImageViewCreateInfo::default()
            .image(self.raw)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(self.desc.format)
            .subresource_range(full_range(self.desc.format, self.desc.mip_levels));
        self.view = unsafe { self.ctx.device.create_image_view(&view_info, None) }
            .vk("vkCreateImageView")?;
        self.ctx.name(self.view, name);
        Ok(())
    }

    /// An image another object owns (a swapchain's), with a view of our own so
    /// the graph can use it like any other; dropping it destroys only the view.
    pub fn external(
        ctx: &Arc<Context>,
        name: &str,
        raw: vk::Image,
        desc: ImageDesc,
        usage: vk::ImageUsageFlags,
    ) -> Result<Self> {
        let mut image = Image {
            ctx: ctx.clone(),
            raw,
            view: vk::ImageView::null(),
            desc,
            usage,
            allocation: None,
            external: true,
        };
        image.create_view(name)?;
        Ok(image)
    }
}

/// The aspect an image of `format` is viewed and synchronised with.
pub fn aspect(format: vk::Format) -> vk::ImageAspectFlags {
    match format {
        vk::Format::D32_SFLOAT | vk::Format::D16_UNORM => vk::ImageAspectFlags::DEPTH,
        _ => vk::ImageAspectFlags::COLOR,
    }
}

/// Every mip level of an image of `format`.
pub(crate) fn full_range(format: vk::Format, mip_levels: u32) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: aspect(format),
        base_mip_level: 0,
        level_count: mip_levels,
        base_array_layer: 0,
        layer_count: 1,
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        unsafe {
            if self.view != vk::ImageView::null() {
                self.ctx.device.destroy_image_view(self.view, None);
            }
            if !self.external {
                self.ctx.device.destroy_image(self.raw, None);
            }
        }
        if let Some(a) = self.allocation.take() {
            let _ = self.ctx.allocator().free(a);
        }
    }
}

pub struct Buffer {
    ctx: Arc<Context>,
    pub raw: vk::Buffer,
    pub size: u64,
    pub usage: vk::BufferUsageFlags,
    allocation: Option<Allocation>,
}

/// Memory for a resource from the allocator (`linear`: a buffer, not an
/// optimally tiled image), named `name`.
fn allocate(
    ctx: &Context,
    name: &str,
    requirements: vk::MemoryRequirements,
    location: MemoryLocation,
    linear: bool,
) -> Result<Allocation> {
    ctx.allocator()
        .allocate(&AllocationCreateDesc {
            name,
            requirements,
            location,
            linear,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        })
        .map_err(|source| Error::Alloc {
            name: name.into(),
            source,
        })
}

impl Buffer {
    /// `location`: `GpuOnly` for device data, `CpuToGpu` for uploads, `GpuToCpu` for readback.
    pub fn new(
        ctx: &Arc<Context>,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self> {
        let info = vk::BufferCreateInfo::default()
            .size(size.max(4))
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let device = &ctx.device;
        let raw = unsafe { device.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
        let mut buffer = Buffer {
            ctx: ctx.clone(),
            raw,
            size,
            usage,
            allocation: None,
        };
        let requirements = unsafe { device.get_buffer_memory_requirements(raw) };
        let allocation = allocate(ctx, name, requirements, location, true)?;
        unsafe { device.bind_buffer_memory(raw, allocation.memory(), allocation.offset()) }
            .vk("vkBindBufferMemory")?;
        buffer.allocation = Some(allocation);
        ctx.name(raw, name);
        Ok(buffer)
    }

    /// Host view of a mapped buffer (`CpuToGpu` / `GpuToCpu`). Read it only after
    /// the frame that wrote it has completed and made it host-visible (graph `HostRead`).
    pub fn mapped(&self) -> Option<&[u8]> {
        let bytes = self.allocation.as_ref()?.mapped_slice()?;
        bytes.get(..self.size as usize)
    }

    pub fn mapped_mut(&mut self) -> Option<&mut [u8]> {
        let size = self.size as usize;
        self.allocation
            .as_mut()?
            .mapped_slice_mut()?
            .get_mut(..size)
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        unsafe { self.ctx.device.destroy_buffer(self.raw, None) };
        if let Some(a) = self.allocation.take() {
            let _ = self.ctx.allocator().free(a);
        }
    }
}

pub struct Sampler {
    ctx: Arc<Context>,
    pub raw: vk::Sampler,
}

impl Sampler {
    /// Clamp-to-edge sampler; `linear` picks trilinear filtering, else nearest
    /// (texels and mip levels).
    pub fn clamped(ctx: &Arc<Context>, linear: bool) -> Result<Self> {
        Self::new(ctx, linear, None)
    }

    /// A depth-comparison sampler for shadow maps: `texture(sampler2DShadow,
    /// (uv, ref))` returns 1 where ref ≤ the stored depth; `linear` filters the
    /// four comparisons bilinearly.
    pub fn shadow(ctx: &Arc<Context>, linear: bool) -> Result<Self> {
        Self::new(ctx, linear, Some(vk::CompareOp::LESS_OR_EQUAL))
    }

    fn new(ctx: &Arc<Context>, linear: bool, compare: Option<vk::CompareOp>) -> Result<Self> {
        let (filter, mipmap) = if linear {
            (vk::Filter::LINEAR, vk::SamplerMipmapMode::LINEAR)
        } else {
            (vk::Filter::NEAREST, vk::SamplerMipmapMode::NEAREST)
        };
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(filter)
            .min_filter(filter)
            .mipmap_mode(mipmap)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .max_lod(vk::LOD_CLAMP_NONE)
            .compare_enable(compare.is_some())
            .compare_op(compare.unwrap_or(vk::CompareOp::NEVER));
        let raw = unsafe { ctx.device.create_sampler(&info, None) }.vk("vkCreateSampler")?;
        Ok(Self {
            ctx: ctx.clone(),
            raw,
        })
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        unsafe { self.ctx.device.destroy_sampler(self.raw, None) };
    }
}
