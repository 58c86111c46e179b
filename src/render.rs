//! The `render` command's library side: build the frame graph, run it for a
//! number of frames, read the image back, and report per-pass timings.

use crate::error::{Error, Result};
use crate::gpu::{Buffer, Context, ContextOptions, DeviceInfo, MemoryLocation};
use crate::graph::{Executor, Graph};
use crate::profile::RunReport;
use crate::testscene::TestScene;
use ash::vk;
use std::sync::Arc;

#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// Frames to render; with more than one, the first is warm-up and excluded
    /// from the median (lavapipe compiles shaders on first use).
    pub frames: u32,
    pub context: ContextOptions,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            width: 1024,
            height: 1024,
            frames: 1,
            context: ContextOptions::from_env(),
        }
    }
}

pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
    /// sRGB-encoded RGBA8, row-major, top row first.
    pub rgba8: Vec<u8>,
    pub report: RunReport,
    /// The compiled plan of the last frame, as `--dump-graph` prints it.
    pub plan: String,
}

/// Checks a requested target size against the device before allocating anything.
pub fn check_target(info: &DeviceInfo, width: u32, height: u32) -> Result<()> {
    let max = info.max_image_dimension_2d;
    if width == 0 || height == 0 || width > max || height > max {
        return Err(Error::Input(format!(
            "target {width}x{height} is outside what {} allows (1..={max} pixels per side)",
            info.name
        )));
    }
    Ok(())
}

pub fn render(opts: &RenderOptions) -> Result<RenderOutput> {
    let ctx = Context::new(&opts.context)?;
    render_with(&ctx, opts)
}

pub fn render_with(ctx: &Arc<Context>, opts: &RenderOptions) -> Result<RenderOutput> {
    let (w, h) = (opts.width, opts.height);
    check_target(&ctx.info, w, h)?;
    let scene = TestScene::new(ctx)?;
    let readback = Arc::new(Buffer::new(
        ctx,
        "readback",
        w as u64 * h as u64 * 4,
        vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuToCpu,
    )?);
    let mut executor = Executor::new(ctx, 2)?;
    let mut reports = Vec::new();
    let mut plan = String::new();
    for _ in 0..opts.frames.max(1) {
        let mut g = Graph::new();
        scene.frame(&mut g, w, h, &readback);
        let compiled = executor.compile(g)?;
        plan = compiled.plan.to_string();
        reports.extend(executor.submit(compiled)?);
    }
    reports.extend(executor.finish()?);
    let rgba8 = readback
        .mapped()
        .ok_or_else(|| Error::Graph("readback buffer is not host-visible".into()))?
        .to_vec();
    let report = RunReport::new(&ctx.info, w, h, reports, executor.pool_bytes());
    Ok(RenderOutput {
        width: w,
        height: h,
        rgba8,
        report,
        plan,
    })
}
