//! The one access vocabulary every pass uses. Stages, access masks, image layouts
//! and usage flags are all derived from it (after vk-sync and kajiya-rg).

use ash::vk;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Access {
    /// Sampled (texture) read in a compute shader.
    ComputeSampled,
    /// `imageLoad` in a compute shader.
    ComputeStorageRead,
    /// `imageStore` in a compute shader.
    ComputeStorageWrite,
    /// `imageLoad` and `imageStore` of the same image in a compute shader.
    ComputeStorageReadWrite,
    /// Sampled read in a vertex shader.
    VertexSampled,
    /// Sampled read in a fragment shader.
    FragmentSampled,
    /// Sampled read in any shader stage: how static textures are left after upload.
    ShaderSampled,
    /// Colour attachment (load, store, blend).
    ColorAttachment,
    /// Depth attachment (test and write).
    DepthAttachment,
    /// Read by a copy or a blit.
    TransferSrc,
    /// Written by a copy, a blit or a clear.
    TransferDst,
    /// Blits within one image (mip generation); leaves it in TRANSFER_DST_OPTIMAL.
    Blit,
    /// Storage buffer read in a compute shader.
    ComputeBufferRead,
    /// Storage buffer write in a compute shader.
    ComputeBufferWrite,
    /// Storage buffer read in a fragment shader.
    FragmentBufferRead,
    /// Storage buffer read in any shader stage: how static data buffers are left.
    ShaderBufferRead,
    VertexBuffer,
    IndexBuffer,
    /// Uniform buffer read by any shader stage.
    UniformRead,
    /// Read by the host after the frame's fence (e.g. readback).
    HostRead,
    /// A swapchain image just acquired: the frame's submission waits on its
    /// semaphore at the colour-attachment stage, which the first barrier chains
    /// with; its contents are discarded. An import's initial access only.
    Acquired,
    /// Handed to the presentation engine (PRESENT_SRC_KHR); the frame's
    /// submission signals the present's semaphore. An import's final access only.
    Present,
}

/// What an access means to the synchronisation model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AccessInfo {
    pub stages: vk::PipelineStageFlags2,
    pub access: vk::AccessFlags2,
    pub layout: vk::ImageLayout,
    pub writes: bool,
}

impl Access {
    pub fn info(self) -> AccessInfo {
        use vk::AccessFlags2 as A;
        use vk::ImageLayout as L;
        use vk::PipelineStageFlags2 as S;
        let (stages, access, layout, writes) = match self {
            Access::ComputeSampled => (
                S::COMPUTE_SHADER,
                A::SHADER_SAMPLED_READ,
                L::SHADER_READ_ONLY_OPTIMAL,
                false,
            ),
            Access::ComputeStorageRead => {
                (S::COMPUTE_SHADER, A::SHADER_STORAGE_READ, L::GENERAL, false)
            }
            Access::ComputeStorageWrite => {
                (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE, L::GENERAL, true)
            }
            Access::ComputeStorageReadWrite => (
                S::COMPUTE_SHADER,
                A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
                L::GENERAL,
                true,
            ),
            Access::VertexSampled => (
                S::VERTEX_SHADER,
                A::SHADER_SAMPLED_READ,
                L::SHADER_READ_ONLY_OPTIMAL,
                false,
            ),
            Access::FragmentSampled => (
                S::FRAGMENT_SHADER,
                A::SHADER_SAMPLED_READ,
                L::SHADER_READ_ONLY_OPTIMAL,
                false,
            ),
            Access::ShaderSampled => (
                S::VERTEX_SHADER | S::FRAGMENT_SHADER | S::COMPUTE_SHADER,
                A::SHADER_SAMPLED_READ,
                L::SHADER_READ_ONLY_OPTIMAL,
                false,
            ),
            Access::ColorAttachment => (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE,
                L::COLOR_ATTACHMENT_OPTIMAL,
                true,
            ),
            Access::DepthAttachment => (
                S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS,
                A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE,
                L::DEPTH_ATTACHMENT_OPTIMAL,
                true,
            ),
            Access::TransferSrc => (
                S::COPY | S::BLIT,
                A::TRANSFER_READ,
                L::TRANSFER_SRC_OPTIMAL,
                false,
            ),
            Access::TransferDst => (
                S::COPY | S::BLIT | S::CLEAR,
                A::TRANSFER_WRITE,
                L::TRANSFER_DST_OPTIMAL,
                true,
            ),
            Access::Blit => (
                S::BLIT,
                A::TRANSFER_READ | A::TRANSFER_WRITE,
                L::TRANSFER_DST_OPTIMAL,
                true,
            ),
            Access::ComputeBufferRead => (
                S::COMPUTE_SHADER,
                A::SHADER_STORAGE_READ,
                L::UNDEFINED,
                false,
            ),
            Access::ComputeBufferWrite => (
                S::COMPUTE_SHADER,
                A::SHADER_STORAGE_WRITE,
                L::UNDEFINED,
                true,
            ),
            Access::ShaderBufferRead => (
                S::VERTEX_SHADER | S::FRAGMENT_SHADER | S::COMPUTE_SHADER,
                A::SHADER_STORAGE_READ,
                L::UNDEFINED,
                false,
            ),
            Access::FragmentBufferRead => (
                S::FRAGMENT_SHADER,
                A::SHADER_STORAGE_READ,
                L::UNDEFINED,
                false,
            ),
            Access::VertexBuffer => (
                S::VERTEX_ATTRIBUTE_INPUT,
                A::VERTEX_ATTRIBUTE_READ,
                L::UNDEFINED,
                false,
            ),
            Access::IndexBuffer => (S::INDEX_INPUT, A::INDEX_READ, L::UNDEFINED, false),
            Access::UniformRead => (
                S::VERTEX_SHADER | S::FRAGMENT_SHADER | S::COMPUTE_SHADER,
                A::UNIFORM_READ,
                L::UNDEFINED,
                false,
            ),
            Access::HostRead => (S::HOST, A::HOST_READ, L::UNDEFINED, false),
            Access::Acquired => (S::COLOR_ATTACHMENT_OUTPUT, A::NONE, L::UNDEFINED, false),
            Access::Present => (S::NONE, A::NONE, L::PRESENT_SRC_KHR, false),
        };
        AccessInfo {
            stages,
            access,
            layout,
            writes,
        }
    }

    /// Whether the access applies to images, buffers, or both.
    pub fn for_images(self) -> bool {
        !matches!(
            self,
            Access::ComputeBufferRead
                | Access::ComputeBufferWrite
                | Access::FragmentBufferRead
                | Access::ShaderBufferRead
                | Access::VertexBuffer
                | Access::IndexBuffer
                | Access::UniformRead
                | Access::HostRead
        )
    }

    pub fn for_buffers(self) -> bool {
        !self.for_images() || matches!(self, Access::TransferSrc | Access::TransferDst)
    }

    pub fn image_usage(self) -> vk::ImageUsageFlags {
        use vk::ImageUsageFlags as U;
        match self {
            Access::ComputeSampled
            | Access::VertexSampled
            | Access::FragmentSampled
            | Access::ShaderSampled => U::SAMPLED,
            Access::ComputeStorageRead
            | Access::ComputeStorageWrite
            | Access::ComputeStorageReadWrite => U::STORAGE,
            Access::ColorAttachment => U::COLOR_ATTACHMENT,
            Access::DepthAttachment => U::DEPTH_STENCIL_ATTACHMENT,
            Access::TransferSrc => U::TRANSFER_SRC,
            Access::TransferDst => U::TRANSFER_DST,
            Access::Blit => U::TRANSFER_SRC | U::TRANSFER_DST,
            _ => U::empty(),
        }
    }

    pub fn buffer_usage(self) -> vk::BufferUsageFlags {
        use vk::BufferUsageFlags as U;
        match self {
            Access::ComputeBufferRead
            | Access::ComputeBufferWrite
            | Access::FragmentBufferRead
            | Access::ShaderBufferRead => U::STORAGE_BUFFER,
            // A pass may also fetch the triangles itself (a static storage
            // buffer: skin::irradiance's texel map).
            Access::VertexBuffer => U::VERTEX_BUFFER | U::STORAGE_BUFFER,
            Access::IndexBuffer => U::INDEX_BUFFER | U::STORAGE_BUFFER,
            Access::UniformRead => U::UNIFORM_BUFFER,
            Access::TransferSrc => U::TRANSFER_SRC,
            Access::TransferDst => U::TRANSFER_DST,
            _ => U::empty(),
        }
    }
}
