//! A small graph workload for testing and measuring the render graph itself: a
//! procedural pattern through two compute blur passes and a graphics pass.

use crate::error::Result;
use crate::gpu::{Context, GraphicsDesc, ImageDesc, Pipeline, Sampler};
use crate::graph::upload::Readback;
use crate::graph::{Graph, ImageHandle, LoadOp};
use ash::vk;
use std::sync::Arc;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BlurPush {
    pub dir: [i32; 2],
    pub radius: i32,
    pub sigma: f32,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CompositePush {
    pub scale: f32,
    pub bias: f32,
    /// Pixels at x ≥ split_x are left untouched (discarded).
    pub split_x: f32,
    pub encode_srgb: u32,
}

/// Pipelines of the test scene; also used by tests to build their own chains.
pub struct TestScene {
    pub pattern: Arc<Pipeline>,
    pub blur: Arc<Pipeline>,
    /// All arithmetic: `alu_heavy.comp` (push: size, iterations).
    pub alu: Arc<Pipeline>,
    /// Composite into RGBA8 (sRGB-encoded by the shader) for PNG output.
    pub composite_rgba8: Arc<Pipeline>,
    /// Composite into RGBA16F (linear), for exact checks.
    pub composite_rgba16f: Arc<Pipeline>,
    pub sampler: Arc<Sampler>,
}

pub const HALF: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

impl TestScene {
    pub fn new(ctx: &Arc<Context>) -> Result<Self> {
        let composite = |format| {
            Pipeline::graphics(ctx, &GraphicsDesc::fullscreen("composite.frag", &[format]))
        };
        Ok(Self {
            pattern: Pipeline::compute(ctx, "pattern.comp")?,
            blur: Pipeline::compute(ctx, "test_blur.comp")?,
            alu: Pipeline::compute(ctx, "alu_heavy.comp")?,
            composite_rgba8: composite(vk::Format::R8G8B8A8_UNORM)?,
            composite_rgba16f: composite(HALF)?,
            sampler: Arc::new(Sampler::clamped(ctx, false)?),
        })
    }

    /// A separable blur (`radius` taps each side, Gaussian `sigma` in texels) of
    /// `src` into a new transient image, as two compute passes.
    pub fn blur(&self, g: &mut Graph, src: &ImageHandle, radius: i32, sigma: f32) -> ImageHandle {
        let mut tmp = g.create_image("blur_tmp", src.desc);
        let mut out = g.create_image("blurred", src.desc);
        self.blur_pass(g, "blur_h", src, &mut tmp, [1, 0], radius, sigma);
        self.blur_pass(g, "blur_v", &tmp, &mut out, [0, 1], radius, sigma);
        out
    }

    #[allow(clippy::too_many_arguments)]
    fn blur_pass(
        &self,
        g: &mut Graph,
        name: &str,
        src: &ImageHandle,
        dst: &mut ImageHandle,
        dir: [i32; 2],
        radius: i32,
        sigma: f32,
    ) {
        let (w, h) = (dst.desc.width, dst.desc.height);
        g.simple_pass(name, &self.blur)
            .sample(src, &self.sampler)
            .store(dst)
            .constants(&BlurPush { dir, radius, sigma })
            .dispatch([w, h, 1]);
    }

    /// Composites `src` into `target` (a colour attachment) with `push`.
    pub fn composite(
        &self,
        g: &mut Graph,
        src: &ImageHandle,
        target: &mut ImageHandle,
        load: LoadOp,
        push: CompositePush,
    ) {
        let pipe = if target.desc.format == HALF {
            &self.composite_rgba16f
        } else {
            &self.composite_rgba8
        };
        g.simple_pass("composite", pipe)
            .sample(src, &self.sampler)
            .color(target, load)
            .constants(&push)
            .draw(3);
    }

    /// The demo frame: pattern → blur_h → blur_v → composite (sRGB) → readback
    /// into `readback` (width × height × 4 bytes, RGBA8).
    pub fn frame(&self, g: &mut Graph, width: u32, height: u32, readback: &Readback) {
        let mut pattern = g.create_image("pattern", ImageDesc::new(width, height, HALF));
        g.simple_pass("pattern", &self.pattern)
            .store(&mut pattern)
            .constants(&[width, height])
            .dispatch([width, height, 1]);
        let blurred = self.blur(g, &pattern, 6, 3.0);
        let mut ldr = g.create_image(
            "ldr",
            ImageDesc::new(width, height, vk::Format::R8G8B8A8_UNORM),
        );
        let push = CompositePush {
            scale: 1.0,
            bias: 0.0,
            split_x: f32::MAX,
            encode_srgb: 1,
        };
        self.composite(g, &blurred, &mut ldr, LoadOp::DontCare, push);
        readback.image_pass(g, &ldr);
    }
}
