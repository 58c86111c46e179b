//! Presenting to a window: the surface (VK_KHR_surface, created through
//! ash-window from raw-window-handle) and the swapchain (VK_KHR_swapchain), whose
//! images are [`Image`]s the render graph imports like any other.

use super::{Context, Image, ImageDesc};
use crate::error::{Error, Result, VkResultExt};
use ash::vk;
use raw_window_handle::{RawDisplayHandle, RawWindowHandle};
use std::sync::Arc;

/// A window's Vulkan surface.
pub struct Surface {
    /// Keeps the instance alive until the surface is destroyed.
    _ctx: Arc<Context>,
    loader: ash::khr::surface::Instance,
    raw: vk::SurfaceKHR,
}

impl Surface {
    /// The surface of `window` on `display`; the context must have been created
    /// for that display (`ContextOptions::display`).
    pub fn new(
        ctx: &Arc<Context>,
        display: RawDisplayHandle,
        window: RawWindowHandle,
    ) -> Result<Self> {
        let raw =
            unsafe { ash_window::create_surface(&ctx.entry, &ctx.instance, display, window, None) }
                .vk("vkCreateSurfaceKHR")?;
        let surface = Surface {
            _ctx: ctx.clone(),
            loader: ash::khr::surface::Instance::new(&ctx.entry, &ctx.instance),
            raw,
        };
        let supported = unsafe {
            surface
                .loader
                .get_physical_device_surface_support(ctx.physical, ctx.queue_family, raw)
        }
        .vk("vkGetPhysicalDeviceSurfaceSupportKHR")?;
        if !supported {
            return Err(Error::Window(format!(
                "{} cannot present to this window from its queue family",
                ctx.info.name
            )));
        }
        Ok(surface)
    }
}

impl Drop for Surface {
    fn drop(&mut self) {
        unsafe { self.loader.destroy_surface(self.raw, None) };
    }
}

/// What [`Swapchain::acquire`] got.
pub enum Acquired {
    /// Image `index` is ours to draw: wait on `ready` before writing it, signal
    /// `rendered` when done and present with it.
    Image {
        index: u32,
        image: Arc<Image>,
        ready: vk::Semaphore,
        rendered: vk::Semaphore,
    },
    /// The window changed: recreate the swapchain and try again.
    OutOfDate,
}

/// The swapchain of a surface, FIFO (vsync, always supported), in a UNORM format:
/// the tone-map pass writes sRGB-encoded values itself.
pub struct Swapchain {
    ctx: Arc<Context>,
    /// Destroyed after the swapchain (fields drop after `Drop::drop`).
    _surface: Arc<Surface>,
    loader: ash::khr::swapchain::Device,
    raw: vk::SwapchainKHR,
    pub images: Vec<Arc<Image>>,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    /// Acquire semaphores, used round robin (one more than the images).
    ready: Vec<vk::Semaphore>,
    /// Per image: signalled by the frame that draws it, waited on by its present.
    rendered: Vec<vk::Semaphore>,
    next: usize,
}

/// Formats the swapchain may take, in order of preference (8-bit UNORM, written
/// already encoded).
const FORMATS: [vk::Format; 2] = [vk::Format::B8G8R8A8_UNORM, vk::Format::R8G8B8A8_UNORM];

impl Swapchain {
    /// A swapchain of `surface` at the window's size (`width` × `height` where the
    /// surface leaves it to us), replacing `old` if given.
    pub fn new(
        ctx: &Arc<Context>,
        surface: &Arc<Surface>,
        (width, height): (u32, u32),
        old: Option<&Swapchain>,
    ) -> Result<Self> {
        let s = &surface.loader;
        let caps = unsafe { s.get_physical_device_surface_capabilities(ctx.physical, surface.raw) }
            .vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?;
        let formats = unsafe { s.get_physical_device_surface_formats(ctx.physical, surface.raw) }
            .vk("vkGetPhysicalDeviceSurfaceFormatsKHR")?;
        let chosen = FORMATS
            .iter()
            .find_map(|f| formats.iter().find(|sf| sf.format == *f))
            .ok_or_else(|| {
                Error::Window(format!(
                    "the surface offers none of {FORMATS:?} (it offers {:?})",
                    formats.iter().map(|f| f.format).collect::<Vec<_>>()
                ))
            })?;
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: width.clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: height.clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        // Copies out serve screenshots, where the surface allows them.
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
            | (caps.supported_usage_flags & vk::ImageUsageFlags::TRANSFER_SRC);
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(surface.raw)
            .min_image_count(count)
            .image_format(chosen.format)
            .image_color_space(chosen.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(vk::PresentModeKHR::FIFO)
            .clipped(true)
            .old_swapchain(old.map_or(vk::SwapchainKHR::null(), |o| o.raw));
        let loader = ash::khr::swapchain::Device::new(&ctx.instance, &ctx.device);
        let raw = unsafe { loader.create_swapchain(&info, None) }.vk("vkCreateSwapchainKHR")?;
        // From here on, Drop releases what exists.
        let mut swapchain = Swapchain {
            ctx: ctx.clone(),
            _surface: surface.clone(),
            loader,
            raw,
            images: Vec::new(),
            format: chosen.format,
            extent,
            ready: Vec::new(),
            rendered: Vec::new(),
            next: 0,
        };
        let raws =
            unsafe { swapchain.loader.get_swapchain_images(raw) }.vk("vkGetSwapchainImagesKHR")?;
        let desc = ImageDesc::new(extent.width, extent.height, chosen.format);
        for (i, &image) in raws.iter().enumerate() {
            let image = Image::external(ctx, &format!("swapchain {i}"), image, desc, usage)?;
            swapchain.images.push(Arc::new(image));
        }
        let semaphore = || {
            unsafe {
                ctx.device
                    .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
            }
            .vk("vkCreateSemaphore")
        };
        for _ in 0..=raws.len() {
            swapchain.ready.push(semaphore()?);
        }
        for _ in 0..raws.len() {
            swapchain.rendered.push(semaphore()?);
        }
        Ok(swapchain)
    }

    /// The next image to draw (vkAcquireNextImageKHR, waiting as long as it takes).
    pub fn acquire(&mut self) -> Result<Acquired> {
        let ready = self.ready[self.next];
        let got = unsafe {
            self.loader
                .acquire_next_image(self.raw, u64::MAX, ready, vk::Fence::null())
        };
        match got {
            // A suboptimal image is still drawn and presented; the present says
            // so again and the caller recreates then.
            Ok((index, _suboptimal)) => {
                self.next = (self.next + 1) % self.ready.len();
                Ok(Acquired::Image {
                    index,
                    image: self.images[index as usize].clone(),
                    ready,
                    rendered: self.rendered[index as usize],
                })
            }
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(Acquired::OutOfDate),
            Err(result) => Err(Error::Vk {
                call: "vkAcquireNextImageKHR",
                result,
            }),
        }
    }

    /// Presents image `index` once `rendered` is signalled; `false` when the
    /// swapchain no longer matches the window (out of date or suboptimal).
    pub fn present(&self, index: u32, rendered: vk::Semaphore) -> Result<bool> {
        let (swapchains, indices, waits) = ([self.raw], [index], [rendered]);
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&waits)
            .swapchains(&swapchains)
            .image_indices(&indices);
        let queue = self.ctx.queue();
        match unsafe { self.loader.queue_present(*queue, &info) } {
            Ok(suboptimal) => Ok(!suboptimal),
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(false),
            Err(result) => Err(Error::Vk {
                call: "vkQueuePresentKHR",
                result,
            }),
        }
    }
}

impl Drop for Swapchain {
    fn drop(&mut self) {
        // Presents and frames that use the semaphores and images must be over.
        // vkDeviceWaitIdle needs the queue to itself (external synchronisation).
        {
            let _queue = self.ctx.queue();
            let _ = unsafe { self.ctx.device.device_wait_idle() };
        }
        self.images.clear();
        unsafe {
            for &s in self.ready.iter().chain(&self.rendered) {
                self.ctx.device.destroy_semaphore(s, None);
            }
            self.loader.destroy_swapchain(self.raw, None);
        }
    }
}
