//! `dermis view`: the paper's main window (Figs. 4–5) on the same renderer and
//! render graph as `dermis render`, presented through a Vulkan swapchain: an orbit
//! camera, the menus' controls in an egui panel and a right-click menu, live
//! per-pass timings. Frames of the skin pipeline are rendered on a thread of
//! their own only when their inputs change (seconds each at 4096² on lavapipe),
//! while the window keeps presenting the last one with the UI at display rate.
//!
//! Files: `app` (the window, events, the frame loop), `present` (swapchain
//! frames), `egui_pass` (egui drawn by our own pass), `worker` (the render
//! thread), `camera` (orbit controls), `ui` (the panel, timings).

mod app;
mod camera;
mod egui_pass;
mod present;
mod ui;
mod worker;

pub use ui::HELP;

use crate::error::{Error, Result};
use crate::gpu::ContextOptions;
use crate::scene::file::SceneFile;
use crate::scene::{load_mesh, Overrides};
use camera::Orbit;
use std::path::PathBuf;

#[derive(Clone, Debug)]
pub struct ViewerOptions {
    /// The scene, with the command line's overrides applied.
    pub scene: SceneFile,
    /// Where it was read from (R reads it again); `None`: the default scene.
    pub scene_path: Option<PathBuf>,
    /// The overrides, applied again on reload.
    pub overrides: Overrides,
    pub context: ContextOptions,
    /// Render this many window frames and exit (headless runs).
    pub frames: Option<u32>,
    /// Where F12 (and a headless run's last frame) writes its PNG.
    pub screenshot: Option<PathBuf>,
}

/// Opens the window and runs until it is closed (or, with `frames`, after them).
pub fn run(opts: ViewerOptions) -> Result<()> {
    // The camera the scene file describes, as an orbit the mouse can move.
    let mesh = load_mesh(&opts.scene)?;
    let bounds = mesh
        .bounds()
        .ok_or_else(|| Error::Input("the mesh is empty".into()))?;
    let orbit = Orbit::of(&crate::scene::camera_for(&opts.scene, bounds));
    let event_loop = winit::event_loop::EventLoop::new().map_err(|e| {
        Error::Window(format!(
            "no display to open a window on ({}); set DISPLAY, or run under Xvfb",
            without_location(&e.to_string())
        ))
    })?;
    let mut app = app::App::new(opts, orbit);
    event_loop
        .run_app(&mut app)
        .map_err(|e| Error::Window(e.to_string()))?;
    match app.error.take() {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// winit's message without the source location it prefixes ("os error at
/// FILE:LINE: message"): a path inside the cargo registry means nothing to a user.
fn without_location(message: &str) -> &str {
    match message.strip_prefix("os error at ") {
        Some(rest) => rest.split_once(": ").map_or(rest, |(_, m)| m),
        None => message,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn winit_messages_lose_their_source_location() {
        let m = "os error at /root/.cargo/registry/src/x/winit-0.30.13/src/platform_impl/linux/mod.rs:765: neither WAYLAND_DISPLAY nor DISPLAY is set.";
        assert_eq!(
            super::without_location(m),
            "neither WAYLAND_DISPLAY nor DISPLAY is set."
        );
        assert_eq!(super::without_location("plain"), "plain");
    }
}
