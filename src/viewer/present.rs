//! The window's frames: acquire a swapchain image, draw the latest rendered
//! frame letterboxed into it and egui over it, in one render graph whose
//! barriers and layout transitions (acquire → attachment → present) come from
//! the graph like any other resource's; present; recreate the swapchain when the
//! window changes (resized, out of date, suboptimal); read the image back for a
//! screenshot.

use super::egui_pass::EguiPass;
use crate::error::{Error, Result};
use crate::gpu::{
    Acquired, Context, GraphicsDesc, Image, ImageDesc, Pipeline, Sampler, Surface, Swapchain,
};
use crate::graph::upload::{upload_texture, Readback};
use crate::graph::{Access, Executor, FrameSync, Graph, Imported, LoadOp};
use crate::timing::FrameTiming;
use ash::vk;
use egui::epaint::ClippedPrimitive;
use std::path::Path;
use std::sync::Arc;

/// Frames the window keeps in flight.
const FRAMES_IN_FLIGHT: usize = 2;

/// What one window frame produced.
pub struct Presented {
    /// The report of an earlier window frame that has completed (its `present`
    /// and `ui` passes).
    pub report: Option<FrameTiming>,
}

pub struct Presenter {
    ctx: Arc<Context>,
    surface: Arc<Surface>,
    swapchain: Swapchain,
    executor: Executor,
    egui: EguiPass,
    present: Arc<Pipeline>,
    sampler: Arc<Sampler>,
    /// Shown until the first frame is rendered.
    placeholder: Arc<Image>,
    /// The window's size in pixels.
    size: (u32, u32),
}

impl Presenter {
    pub fn new(ctx: &Arc<Context>, surface: Surface, size: (u32, u32)) -> Result<Self> {
        let surface = Arc::new(surface);
        let swapchain = Swapchain::new(ctx, &surface, size, None)?;
        let present = Pipeline::graphics(
            ctx,
            &GraphicsDesc::fullscreen("present.frag", &[swapchain.format]),
        )?;
        let placeholder = upload_texture(
            ctx,
            "no frame yet",
            ImageDesc::new(1, 1, vk::Format::R8G8B8A8_UNORM),
            &[31, 31, 31, 255],
        )?;
        Ok(Self {
            ctx: ctx.clone(),
            egui: EguiPass::new(ctx, swapchain.format)?,
            executor: Executor::new(ctx, FRAMES_IN_FLIGHT)?,
            surface,
            swapchain,
            present,
            sampler: Arc::new(Sampler::clamped(ctx, true)?),
            placeholder,
            size,
        })
    }

    /// The window now has `size` pixels: the swapchain follows on the next frame.
    pub fn resize(&mut self, size: (u32, u32)) {
        self.size = size;
    }

    /// A new swapchain for the window's current size, once every frame that
    /// used the old one is over.
    fn recreate(&mut self) -> Result<()> {
        self.executor.finish()?;
        self.swapchain =
            Swapchain::new(&self.ctx, &self.surface, self.size, Some(&self.swapchain))?;
        Ok(())
    }

    /// Draws `frame` (the latest rendered image; `None` before the first),
    /// letterboxed into `area` (x, y, width, height in pixels), then egui's
    /// `primitives` after applying `textures`, and
    /// presents. With `screenshot`, waits for the frame and writes the window's
    /// image there as PNG. `None` when there was nothing to draw into (a
    /// minimised window, or a swapchain that had to be recreated first).
    pub fn frame(
        &mut self,
        frame: Option<&Arc<Image>>,
        area: [f32; 4],
        primitives: &[ClippedPrimitive],
        textures: &egui::TexturesDelta,
        pixels_per_point: f32,
        screenshot: Option<&Path>,
    ) -> Result<Option<Presented>> {
        self.egui.update_textures(textures)?;
        if screenshot.is_some() && !image_usage_copies(&self.swapchain) {
            return Err(Error::Window(
                "this window's surface does not let its images be copied: no screenshot".into(),
            ));
        }
        if self.size.0 == 0 || self.size.1 == 0 {
            return Ok(None);
        }
        let extent = self.swapchain.extent;
        if (extent.width, extent.height) != self.size {
            self.recreate()?;
        }
        let (index, image, ready, rendered) = match self.swapchain.acquire()? {
            Acquired::Image {
                index,
                image,
                ready,
                rendered,
            } => (index, image, ready, rendered),
            Acquired::OutOfDate => {
                self.recreate()?;
                return Ok(None);
            }
        };
        let (w, h) = (image.desc.width, image.desc.height);
        let mut g = Graph::new();
        let mut target = g.import_image(
            "swapchain",
            Imported::Image(image),
            Some(Access::Acquired),
            Some(Access::Present),
        );
        let rect = letterbox(frame.map(|f| (f.desc.width, f.desc.height)), area);
        let shown = frame.map(|f| pass_import(&mut g, f));
        let pass = g.simple_pass("present", &self.present);
        let pass = match &shown {
            Some(handle) => pass.sample(handle, &self.sampler),
            None => pass.texture(&self.placeholder, &self.sampler),
        };
        pass.color(&mut target, LoadOp::DontCare)
            .constants(&rect)
            .draw(3);
        self.egui
            .pass(&mut g, &mut target, primitives, pixels_per_point)?;
        let readback = match screenshot {
            Some(_) => {
                let r = Readback::new(&self.ctx, "screenshot", u64::from(w) * u64::from(h) * 4)?;
                r.image_pass(&mut g, &target);
                Some(r)
            }
            None => None,
        };
        let compiled = self.executor.compile(g)?;
        // No pass of the render thread's is submitted between this frame's
        // submission and its present: on lavapipe, without this, a window frame
        // also waited behind the passes submitted meanwhile (docs/design/viewer.md).
        let ctx = self.ctx.clone();
        let foreground = ctx.foreground();
        let report = self.executor.submit_synced(
            compiled,
            FrameSync {
                wait: Some((ready, vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT)),
                signal: Some(rendered),
            },
        )?;
        if !self.swapchain.present(index, rendered)? {
            self.recreate()?;
        }
        drop(foreground);
        if let (Some(path), Some(r)) = (screenshot, readback) {
            self.executor.finish()?;
            save_png(path, r.bytes()?, (w, h), self.swapchain.format)?;
        }
        Ok(Some(Presented { report }))
    }

    /// Waits for every frame in flight (before the window closes).
    pub fn finish(&mut self) -> Result<Vec<FrameTiming>> {
        self.executor.finish()
    }
}

/// Whether the swapchain's images can be copied out (screenshots).
fn image_usage_copies(swapchain: &Swapchain) -> bool {
    swapchain
        .images
        .first()
        .is_some_and(|i| i.usage.contains(vk::ImageUsageFlags::TRANSFER_SRC))
}

/// `frame` imported for sampling: the render thread left it in
/// SHADER_READ_ONLY_OPTIMAL after its last write, and waited for it.
fn pass_import(g: &mut Graph, frame: &Arc<Image>) -> crate::graph::ImageHandle {
    g.import_image(
        "rendered frame",
        Imported::Image(frame.clone()),
        Some(Access::FragmentSampled),
        Some(Access::FragmentSampled),
    )
}

/// The largest rectangle of `frame`'s aspect centred in `area` (x, y, w, h).
fn letterbox(frame: Option<(u32, u32)>, [x, y, aw, ah]: [f32; 4]) -> [f32; 4] {
    let (fw, fh) = frame.map_or((aw, ah), |(w, h)| (w as f32, h as f32));
    let scale = (aw / fw).min(ah / fh);
    let (w, h) = (fw * scale, fh * scale);
    [x + (aw - w) / 2.0, y + (ah - h) / 2.0, w, h]
}

/// Writes a swapchain image read back as `format` (BGRA or RGBA) as a PNG, whole
/// or not at all.
fn save_png(path: &Path, bytes: &[u8], (w, h): (u32, u32), format: vk::Format) -> Result<()> {
    let mut rgba = bytes.to_vec();
    if format == vk::Format::B8G8R8A8_UNORM {
        for p in rgba.chunks_exact_mut(4) {
            p.swap(0, 2);
        }
    }
    // Encoded in memory and renamed into place (atomic).
    crate::render::output::write_rgba8_png(path, w, h, &rgba)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_letterboxed_at_their_aspect() {
        // A portrait frame in a landscape area: bars left and right.
        assert_eq!(
            letterbox(Some((768, 960)), [0.0, 0.0, 1200.0, 600.0]),
            [360.0, 0.0, 480.0, 600.0]
        );
        // A landscape frame in a portrait area beside a 100-pixel panel.
        assert_eq!(
            letterbox(Some((200, 100)), [100.0, 0.0, 400.0, 400.0]),
            [100.0, 100.0, 400.0, 200.0]
        );
        // No frame: the whole area.
        assert_eq!(
            letterbox(None, [0.0, 0.0, 640.0, 480.0]),
            [0.0, 0.0, 640.0, 480.0]
        );
    }
}
