//! A render that lasts (the viewer's): the scene uploaded and the frame's
//! pipelines built once, then frames on demand, each encoded for display and
//! copied into an image of its own that another graph samples. Moving the camera
//! only makes the frame's uniforms again, turning the environment also its SH
//! and the lights' shadows; anything else is a new session.

use super::frame_graph::Frame;
use super::{check_target, settings, View};
use crate::error::Result;
use crate::gpu::{Context, Image, ImageDesc};
use crate::graph::{Access, Executor, Graph, Imported, Kept};
use crate::post::PostSettings;
use crate::scene::camera::Camera;
use crate::scene::file::SceneFile;
use crate::scene::Scene;
use crate::timing::FrameTiming;
use ash::vk;
use std::sync::Arc;

pub struct Session {
    ctx: Arc<Context>,
    scene: Scene,
    frame: Frame,
    executor: Executor,
    /// What the session's frames have computed and keep (stretch maps, SH,
    /// the prefiltered environment, shadows).
    kept: Kept,
    /// Every view of the session's frame (`render --view list`).
    views: Vec<String>,
}

impl Session {
    /// A session of `scene`; its `textures.test_texture` puts the checker on.
    pub fn new(ctx: &Arc<Context>, scene: Scene) -> Result<Self> {
        let skin = settings(ctx, &scene)?;
        let frame = Frame::new(ctx, &scene, &scene.albedo, skin, false)?;
        // Its passes wait for a window frame in progress (gpu::Context::foreground).
        let mut executor = Executor::new(ctx, 1)?;
        executor.set_background();
        let size = (scene.file.render.width, scene.file.render.height);
        Ok(Self {
            views: frame.views(size)?,
            ctx: ctx.clone(),
            executor,
            scene,
            frame,
            kept: Kept::default(),
        })
    }

    /// Every view the session can render: the screen views, then the frame
    /// graph's images.
    pub fn views(&self) -> &[String] {
        &self.views
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Bright sources the session's frames light with (`environment.lights`).
    pub fn extracted_lights(&self) -> usize {
        self.frame.extracted_lights()
    }

    /// Takes `file` for the next frames when it differs from the session's
    /// scene only in what a session changes between frames: the camera and
    /// the size (see [`Session::set_camera`]), the environment's rotation and
    /// the post-processing (post::PostSettings); returns false, taking
    /// nothing, when it needs a new session. The one place that decides.
    pub fn update(&mut self, file: &SceneFile) -> Result<bool> {
        let fixed = |f: &SceneFile| {
            let mut f = f.clone();
            f.render = PostSettings::clear(&f.render);
            (f.render.width, f.render.height) = (0, 0);
            f.camera = Default::default();
            f.environment.rotation_deg = 0.0;
            f
        };
        if fixed(file) != fixed(&self.scene.file) {
            return Ok(false);
        }
        let size = (self.scene.file.render.width, self.scene.file.render.height);
        self.scene.file.render = file.render.clone();
        (self.scene.file.render.width, self.scene.file.render.height) = size;
        self.frame.set_post(PostSettings::resolve(&file.render));
        self.set_rotation(file.environment.rotation_deg)?;
        Ok(true)
    }

    /// Turns the environment (`environment.rotation_deg`) without a new session:
    /// its SH are rotated, its extracted sources turned with their shadows.
    pub fn set_rotation(&mut self, rotation_deg: f32) -> Result<()> {
        if self.scene.file.environment.rotation_deg == rotation_deg {
            return Ok(());
        }
        self.scene.file.environment.rotation_deg = rotation_deg;
        self.frame.set_rotation(&self.ctx, &self.scene)
    }

    /// Moves the camera and sets the frame's size (its aspect): uniforms only.
    pub fn set_camera(&mut self, camera: Camera, (width, height): (u32, u32)) -> Result<()> {
        check_target(&self.ctx.info, width, height)?;
        self.scene.camera = camera;
        self.scene.file.render.width = width;
        self.scene.file.render.height = height;
        self.frame.set_camera(&self.ctx, &self.scene)
    }

    /// Renders `view` once and waits for it: the displayable image (RGBA8,
    /// sRGB-encoded, left in SHADER_READ_ONLY_OPTIMAL for fragment sampling)
    /// and the frame's report.
    pub fn render(&mut self, view: &View) -> Result<(Arc<Image>, Option<FrameTiming>)> {
        let size = (self.scene.file.render.width, self.scene.file.render.height);
        let mut g = Graph::with_kept(self.kept.clone());
        let images = self.frame.graph(&mut g, view, size)?;
        let ldr = match images.ldr {
            Some(ldr) => ldr,
            None => self.frame.encode(&mut g, images.image, view),
        };
        let (w, h) = (ldr.desc.width, ldr.desc.height);
        let image = Arc::new(Image::new(
            &self.ctx,
            "viewer frame",
            ImageDesc::new(w, h, ldr.desc.format),
            // TRANSFER_SRC: it can be read back (tests/it/session.rs).
            vk::ImageUsageFlags::TRANSFER_DST
                | vk::ImageUsageFlags::SAMPLED
                | vk::ImageUsageFlags::TRANSFER_SRC,
        )?);
        let mut out = g.import_image(
            "viewer frame",
            Imported::Image(image.clone()),
            None,
            Some(Access::FragmentSampled),
        );
        let mut p = g.add_pass("to viewer");
        let (src, dst) = (
            p.read(&ldr, Access::TransferSrc),
            p.write(&mut out, Access::TransferDst),
        );
        // As render writes it (render::flipped).
        let flip = super::flipped(&self.scene, view);
        p.record(move |cx| match flip {
            true => cx.copy_image_flipped(src, dst),
            false => cx.copy_image(src, dst),
        });
        let compiled = self.executor.compile(g)?;
        // Kept once the frame has been submitted.
        let kept = compiled.plan.kept.clone();
        let mut reports = self
            .executor
            .submit(compiled)?
            .into_iter()
            .collect::<Vec<_>>();
        reports.extend(self.executor.finish()?);
        self.kept = kept;
        Ok((image, reports.pop()))
    }
}
