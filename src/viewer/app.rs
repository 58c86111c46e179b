//! The window (winit): events to the camera, the controls and the keys; each
//! redraw polls the render thread, runs the UI, sends a new job when something
//! changed, and presents. Headless runs (`--frames N`) resize the window once
//! halfway, then stop after N frames once the last render is shown, taking the
//! screenshot asked for.

use super::camera::{turn_environment, Orbit};
use super::present::Presenter;
use super::ui::{self, Controls, Status, Timings};
use super::worker::{Job, Worker};
use super::ViewerOptions;
use crate::error::{Error, Result};
use crate::gpu::{Context, ContextOptions, Image, Surface};
use crate::scene::env::EnvSource;
use crate::scene::file::scene_by_name;
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use winit::application::ApplicationHandler;
use winit::dpi::{PhysicalPosition, PhysicalSize};
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::{Key, ModifiersState, NamedKey};
use winit::window::{Window, WindowId};

/// What exists once the window is open, in the order it is torn down.
struct Open {
    worker: Worker,
    presenter: Presenter,
    shown: Option<Arc<Image>>,
    egui_state: egui_winit::State,
    window: Arc<Window>,
    ctx: Arc<Context>,
}

pub(super) struct App {
    opts: ViewerOptions,
    open: Option<Open>,
    egui: egui::Context,
    controls: Controls,
    /// The controls and size of the last job sent.
    sent: Option<(Controls, (u32, u32))>,
    envs: Vec<(String, EnvSource)>,
    timings: Timings,
    last: String,
    drag: Option<(MouseButton, PhysicalPosition<f64>)>,
    cursor: PhysicalPosition<f64>,
    modifiers: ModifiersState,
    frames: u32,
    resized: bool,
    screenshot: Option<PathBuf>,
    screenshots: u32,
    previous_frame: Option<Instant>,
    pub(super) error: Option<Error>,
}

impl App {
    pub(super) fn new(opts: ViewerOptions, orbit: Orbit) -> App {
        let envs = ui::environments(&opts.scene.environment.source);
        App {
            controls: Controls {
                file: opts.scene.clone(),
                view: crate::render::View::FINAL,
                views: crate::render::Screen::all()
                    .map(|s| s.name().to_string())
                    .collect(),
                orbit,
                env_text: String::new(),
                env_error: None,
            },
            opts,
            open: None,
            egui: egui::Context::default(),
            sent: None,
            envs,
            timings: Timings::default(),
            last: String::new(),
            drag: None,
            cursor: PhysicalPosition::new(0.0, 0.0),
            modifiers: ModifiersState::empty(),
            frames: 0,
            resized: false,
            screenshot: None,
            screenshots: 0,
            previous_frame: None,
            error: None,
        }
    }

    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<Open> {
        let r = &self.opts.scene.render;
        // The scene's framing beside the panel, unless the command line gave a width.
        let width = self
            .opts
            .overrides
            .width
            .unwrap_or(r.width + ui::PANEL_WIDTH);
        let window = event_loop
            .create_window(
                Window::default_attributes()
                    .with_title("dermis")
                    .with_inner_size(PhysicalSize::new(width, r.height)),
            )
            .map_err(|e| Error::Window(format!("cannot open a window: {e}")))?;
        let window = Arc::new(window);
        let handle_error = |e: raw_window_handle::HandleError| Error::Window(e.to_string());
        let display = event_loop.display_handle().map_err(handle_error)?.as_raw();
        let ctx = Context::new(&ContextOptions {
            display: Some(display),
            ..self.opts.context.clone()
        })?;
        let surface = Surface::new(
            &ctx,
            display,
            window.window_handle().map_err(handle_error)?.as_raw(),
        )?;
        let size = window.inner_size();
        let presenter = Presenter::new(&ctx, surface, (size.width, size.height))?;
        let egui_state = egui_winit::State::new(
            self.egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(ctx.info.max_image_dimension_2d as usize),
        );
        Ok(Open {
            worker: Worker::new(&ctx),
            presenter,
            shown: None,
            egui_state,
            window,
            ctx,
        })
    }

    /// One window frame.
    fn redraw(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let Some(open) = self.open.as_mut() else {
            return Ok(());
        };
        if let Some(done) = open.worker.poll() {
            match done.frame {
                Ok(f) => {
                    self.last = format!(
                        "{}×{}, {} source(s) as lights, {:.2} s{}",
                        f.image.desc.width,
                        f.image.desc.height,
                        f.extracted_lights,
                        f.seconds,
                        if f.rebuilt { " (new session)" } else { "" }
                    );
                    open.shown = Some(f.image);
                    self.controls.views = f.views;
                    if let Some(r) = f.report {
                        self.timings.add_frame(r);
                    }
                }
                // A headless run waits for a render: one that failed ends it.
                Err(e) if self.opts.frames.is_some() => return Err(e),
                Err(e) => self.last = format!("error: {e}"),
            }
        }
        let input = open.egui_state.take_egui_input(&open.window);
        let status = Status {
            device: &open.ctx.info.name,
            last: &self.last,
            rendering: !open.worker.idle(),
        };
        let (controls, envs, timings) = (&mut self.controls, &self.envs, &self.timings);
        let (mut shot, mut area) = (false, egui::Rect::NOTHING);
        let output = self.egui.run_ui(input, |ui| {
            let (s, a) = ui::show(ui, controls, envs, &status, timings);
            (shot, area) = (shot || s, a);
        });
        open.egui_state
            .handle_platform_output(&open.window, output.platform_output);
        let primitives = self.egui.tessellate(output.shapes, output.pixels_per_point);
        // The frame fills the area beside the panel, in pixels.
        let area = area * output.pixels_per_point;
        let rect = [
            area.min.x,
            area.min.y,
            area.width().max(0.0),
            area.height().max(0.0),
        ];
        // At least a pixel: the panel takes at most half the window (ui::show).
        let size = (
            rect[2].round().max(1.0) as u32,
            rect[3].round().max(1.0) as u32,
        );
        let window = open.window.inner_size();
        let minimised = window.width == 0 || window.height == 0;
        if !minimised && self.sent.as_ref() != Some(&(self.controls.clone(), size)) {
            open.worker.send(Job {
                file: self.controls.file.clone(),
                view: self.controls.view.clone(),
                camera: self.controls.orbit.camera(),
                size,
            });
            self.sent = Some((self.controls.clone(), size));
        }
        if shot {
            self.screenshots += 1;
            self.screenshot = Some(screenshot_path(&self.opts, self.screenshots));
        }
        // Headless runs: resize once halfway; stop once the last render is shown.
        let headless = self.opts.frames;
        if let Some(n) = headless {
            if !self.resized && self.frames >= n / 2 {
                self.resized = true;
                let _ = open.window.request_inner_size(PhysicalSize::new(
                    (window.width * 3 / 4).max(1),
                    (window.height * 3 / 4).max(1),
                ));
            }
        }
        let last_frame = headless.is_some_and(|n| {
            self.frames + 1 >= n && self.resized && open.worker.idle() && open.shown.is_some()
        });
        if last_frame && self.screenshot.is_none() {
            self.screenshot = self.opts.screenshot.clone();
        }
        let presented = open.presenter.frame(
            open.shown.as_ref(),
            rect,
            &primitives,
            &output.textures_delta,
            output.pixels_per_point,
            self.screenshot.as_deref(),
        )?;
        if let Some(presented) = presented {
            self.frames += 1;
            if let Some(r) = presented.report {
                self.timings.add_window_frame(r);
            }
            let now = Instant::now();
            if let Some(before) = self.previous_frame.replace(now) {
                self.timings
                    .add_window_ms((now - before).as_secs_f64() * 1e3);
            }
            if let Some(path) = self.screenshot.take() {
                eprintln!("wrote {}", path.display());
            }
            if last_frame {
                event_loop.exit();
            }
        }
        Ok(())
    }

    /// The next frame is written to a PNG.
    fn request_screenshot(&mut self) {
        self.screenshots += 1;
        self.screenshot = Some(screenshot_path(&self.opts, self.screenshots));
    }

    /// R: the scene file read again (with the command line's overrides).
    fn reload(&mut self) -> Result<()> {
        let file = scene_by_name(self.opts.scene_path.as_deref())?;
        self.controls.file = self.opts.overrides.apply(file)?;
        self.envs = ui::environments(&self.controls.file.environment.source);
        Ok(())
    }

    fn event(&mut self, event_loop: &ActiveEventLoop, event: &WindowEvent) -> Result<()> {
        let Some(open) = self.open.as_mut() else {
            return Ok(());
        };
        let consumed = open
            .egui_state
            .on_window_event(&open.window, event)
            .consumed;
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => open.presenter.resize((size.width, size.height)),
            WindowEvent::RedrawRequested => return self.redraw(event_loop),
            WindowEvent::ModifiersChanged(m) => self.modifiers = m.state(),
            WindowEvent::KeyboardInput { event: key, .. }
                if !consumed && key.state == ElementState::Pressed && !key.repeat =>
            {
                match &key.logical_key {
                    Key::Named(NamedKey::Escape) => event_loop.exit(),
                    Key::Named(NamedKey::F12) => self.request_screenshot(),
                    Key::Character(c) if c.eq_ignore_ascii_case("r") => {
                        if let Err(e) = self.reload() {
                            self.last = format!("reload failed: {e}");
                        }
                    }
                    _ => {}
                }
            }
            WindowEvent::MouseInput { state, button, .. } => match state {
                ElementState::Pressed if !self.egui.is_pointer_over_egui() => {
                    self.drag = Some((*button, self.cursor));
                }
                ElementState::Released => self.drag = None,
                _ => {}
            },
            WindowEvent::CursorMoved { position, .. } => {
                if let Some((button, from)) = self.drag {
                    let (dx, dy) = ((position.x - from.x) as f32, (position.y - from.y) as f32);
                    let orbit = &mut self.controls.orbit;
                    match button {
                        MouseButton::Left if self.modifiers.shift_key() => {
                            let env = &mut self.controls.file.environment;
                            env.rotation_deg = turn_environment(env.rotation_deg, dx);
                        }
                        MouseButton::Left => orbit.rotate(dx, dy),
                        MouseButton::Right | MouseButton::Middle => {
                            orbit.pan(dx, dy, open.window.inner_size().height as f32)
                        }
                        _ => {}
                    }
                    self.drag = Some((button, *position));
                }
                self.cursor = *position;
            }
            WindowEvent::MouseWheel { delta, .. } if !consumed => {
                let notches = match delta {
                    MouseScrollDelta::LineDelta(_, y) => *y,
                    MouseScrollDelta::PixelDelta(p) => (p.y / 40.0) as f32,
                };
                self.controls.orbit.zoom(notches);
            }
            _ => {}
        }
        Ok(())
    }

    /// Tears down in order: the render thread, the frames in flight and the
    /// swapchain, the window, then the device.
    fn close(&mut self) -> Result<()> {
        for (pass, ms, frames) in self.timings.passes() {
            log::info!("{pass}: median {ms:.2} ms over {frames} frame(s)");
        }
        log::info!("{}", self.timings.window_summary());
        if let Some(mut open) = self.open.take() {
            drop(open.worker);
            open.presenter.finish()?;
            drop(open.presenter);
            drop(open.shown);
            drop(open.egui_state);
            drop(open.window);
            drop(open.ctx);
        }
        Ok(())
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: Error) {
        self.error.get_or_insert(e);
        event_loop.exit();
    }
}

/// Screenshot `n`'s file: `--screenshot`'s path, else `dermis-screenshot-N.png`.
fn screenshot_path(opts: &ViewerOptions, n: u32) -> PathBuf {
    opts.screenshot
        .clone()
        .unwrap_or_else(|| PathBuf::from(format!("dermis-screenshot-{n}.png")))
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.open.is_none() {
            match self.open(event_loop) {
                Ok(open) => self.open = Some(open),
                Err(e) => self.fail(event_loop, e),
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        if let Err(e) = self.event(event_loop, &event) {
            self.fail(event_loop, e);
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        // The UI redraws at display rate (FIFO presents pace it).
        if let Some(open) = &self.open {
            open.window.request_redraw();
        }
    }

    fn exiting(&mut self, _: &ActiveEventLoop) {
        if let Err(e) = self.close() {
            self.error.get_or_insert(e);
        }
    }
}
