//! A thin, RAII layer over ash: context (instance, device, validation), memory
//! (gpu-allocator), images, buffers, samplers, pipelines, embedded SPIR-V.

mod cache;
mod context;
mod pipeline;
mod pipeline_cache;
mod reflect;
mod resources;
pub mod shaders;
mod swapchain;
mod validation;

pub use cache::{Memo, Pipelines};
pub use context::{Context, ContextOptions, DeviceInfo, MemoryHeap};
pub use pipeline::{GraphicsDesc, Pipeline};
pub use reflect::ShaderLayout;
pub(crate) use resources::full_range;
pub use resources::{aspect, texel_bytes, Buffer, Image, ImageDesc, Sampler};
pub use swapchain::{Acquired, Surface, Swapchain};
pub use validation::{validation_messages, ValidationLog};

pub use gpu_allocator::MemoryLocation;
