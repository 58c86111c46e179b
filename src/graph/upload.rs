//! Moving data between host and device through the graph: one-shot uploads of
//! static buffers and textures (with GPU mip generation; each runs a tiny graph on
//! its own executor and waits, and leaves the result ready for any shader), and
//! the readback pass frames end with.

use super::{Access, BufferHandle, Executor, Graph, ImageHandle, Imported};
use crate::error::{Error, Result};
use crate::gpu::{Buffer, Context, Image, ImageDesc, MemoryLocation};
use ash::vk;
use std::sync::Arc;

fn staging(ctx: &Arc<Context>, name: &str, bytes: &[u8]) -> Result<Arc<Buffer>> {
    let mut buf = Buffer::new(
        ctx,
        &format!("{name} (staging)"),
        bytes.len() as u64,
        vk::BufferUsageFlags::TRANSFER_SRC,
        MemoryLocation::CpuToGpu,
    )?;
    buf.mapped_mut()
        .ok_or_else(|| Error::Graph("staging buffer is not host-visible".into()))?
        .copy_from_slice(bytes);
    Ok(Arc::new(buf))
}

/// A device-local buffer holding `bytes`, left ready for `final_access`
/// (e.g. `VertexBuffer`, `IndexBuffer`, `ComputeBufferRead`).
pub fn upload_buffer(
    ctx: &Arc<Context>,
    name: &str,
    bytes: &[u8],
    final_access: Access,
) -> Result<Arc<Buffer>> {
    let usage = final_access.buffer_usage() | vk::BufferUsageFlags::TRANSFER_DST;
    let buffer = Arc::new(Buffer::new(
        ctx,
        name,
        bytes.len() as u64,
        usage,
        MemoryLocation::GpuOnly,
    )?);
    let mut g = Graph::new();
    // Host writes before vkQueueSubmit are visible to the device: nothing to wait for.
    let src = g.import_buffer(
        "staging",
        Imported::Buffer(staging(ctx, name, bytes)?),
        None,
        None,
    );
    let mut dst = g.import_buffer(
        name,
        Imported::Buffer(buffer.clone()),
        None,
        Some(final_access),
    );
    let size = bytes.len() as u64;
    let mut p = g.add_pass("upload");
    let s = p.read_buffer(&src, Access::TransferSrc);
    let d = p.write_buffer(&mut dst, Access::TransferDst);
    p.record(move |cx| cx.copy_buffer(s, d, size));
    run_once(ctx, g)?;
    Ok(buffer)
}

/// Number of mip levels of a full chain down to 1×1.
pub fn full_mip_count(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

/// A sampled texture from tightly packed level-0 texels of `desc.format`; levels
/// 1.. (when `desc.mip_levels > 1`) are generated on the GPU by linear blits.
/// Left in SHADER_READ_ONLY_OPTIMAL, visible to every shader stage.
pub fn upload_texture(
    ctx: &Arc<Context>,
    name: &str,
    desc: ImageDesc,
    texels: &[u8],
) -> Result<Arc<Image>> {
    let texel = crate::gpu::texel_bytes(desc.format).ok_or_else(|| {
        Error::Graph(format!(
            "{name}: unsupported upload format {:?}",
            desc.format
        ))
    })?;
    let expected = desc.width as usize * desc.height as usize * texel as usize;
    if texels.len() != expected {
        return Err(Error::Input(format!(
            "{name}: {} bytes of texels for a {}x{} {:?} texture ({expected} expected)",
            texels.len(),
            desc.width,
            desc.height,
            desc.format
        )));
    }
    let usage = vk::ImageUsageFlags::SAMPLED
        | vk::ImageUsageFlags::TRANSFER_DST
        | vk::ImageUsageFlags::TRANSFER_SRC;
    let image = Arc::new(Image::new(ctx, name, desc, usage)?);
    let mut g = Graph::new();
    let src = g.import_buffer(
        "staging",
        Imported::Buffer(staging(ctx, name, texels)?),
        None,
        None,
    );
    let mut dst = g.import_image(
        name,
        Imported::Image(image.clone()),
        None,
        Some(Access::ShaderSampled),
    );
    let mut p = g.add_pass("upload");
    let s = p.read_buffer(&src, Access::TransferSrc);
    let d = p.write(&mut dst, Access::TransferDst);
    p.record(move |cx| cx.copy_buffer_to_image(s, d));
    if desc.mip_levels > 1 {
        let mut p = g.add_pass("mips");
        let m = p.write(&mut dst, Access::Blit);
        p.record(move |cx| cx.generate_mips(m));
    }
    run_once(ctx, g)?;
    Ok(image)
}

fn run_once(ctx: &Arc<Context>, g: Graph) -> Result<()> {
    let mut ex = Executor::new(ctx, 1)?;
    ex.run(g)?;
    ex.finish()?;
    Ok(())
}

/// A host-visible buffer that frames copy an image or a buffer into; read it
/// after the frame's fence (`Executor::finish`).
pub struct Readback {
    buffer: Arc<Buffer>,
}

impl Readback {
    pub fn new(ctx: &Arc<Context>, name: &str, bytes: u64) -> Result<Self> {
        let buffer = Buffer::new(
            ctx,
            name,
            bytes,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        Ok(Self {
            buffer: Arc::new(buffer),
        })
    }

    fn import(&self, g: &mut Graph) -> BufferHandle {
        g.import_buffer(
            "readback",
            Imported::Buffer(self.buffer.clone()),
            Some(Access::HostRead),
            Some(Access::HostRead),
        )
    }

    /// A pass that copies level 0 of `image`, tightly packed.
    pub fn image_pass(&self, g: &mut Graph, image: &ImageHandle) {
        let mut out = self.import(g);
        let mut p = g.add_pass("readback");
        let src = p.read(image, Access::TransferSrc);
        let dst = p.write_buffer(&mut out, Access::TransferDst);
        p.record(move |cx| cx.copy_image_to_buffer(src, dst));
    }

    /// A pass that copies the start of `buffer` (as much as this one holds).
    pub fn buffer_pass(&self, g: &mut Graph, buffer: &BufferHandle) {
        let size = self.buffer.size.min(buffer.size);
        let mut out = self.import(g);
        let mut p = g.add_pass("readback");
        let src = p.read_buffer(buffer, Access::TransferSrc);
        let dst = p.write_buffer(&mut out, Access::TransferDst);
        p.record(move |cx| cx.copy_buffer(src, dst, size));
    }

    /// The copied bytes (valid once the frames that copy have finished).
    pub fn bytes(&self) -> Result<&[u8]> {
        self.buffer
            .mapped()
            .ok_or_else(|| Error::Graph("readback buffer is not host-visible".into()))
    }
}
