//! The viewer's controls (the paper's menus, Figs. 4–5: exposure, tone curve,
//! glow, blur width and amount, test texture, skybox, debug views, lighting and
//! diffusion variants) in an egui side panel and
//! the same in a right-click menu over the image, the live per-pass timings and
//! the frame-time graph. The controls edit a scene file and a view; the window
//! renders again when they change.

use super::camera::Orbit;
use crate::render::{Screen, View};
use crate::scene::env::EnvSource;
use crate::scene::file::{Chain, Kernel, LightsMode, Occlusion, SceneFile, ToneCurve};
use crate::timing::FrameTiming;
use std::collections::VecDeque;

/// Frames the timings are the median of, and the graph shows.
pub const HISTORY: usize = 120;
/// Room the panel takes beside the image, in pixels at scale 1: its content makes
/// it wider than its default width of 270 points (345 px in a screenshot of
/// `dermis view` with the timings open).
pub const PANEL_WIDTH: u32 = 360;

/// What the controls edit.
#[derive(Clone, Debug, PartialEq)]
pub struct Controls {
    pub file: SceneFile,
    pub view: View,
    /// What the view menu offers: the session's views (render::session).
    pub views: Vec<String>,
    pub orbit: Orbit,
    /// The environment field: a source typed in (a file, `sky:…`, `uniform:…`).
    pub env_text: String,
    /// Why the last one typed was refused.
    pub env_error: Option<String>,
}

/// Environments offered besides the scene's own: the CC0 maps shipped in
/// `assets/env` (where they are), the built-in sky and a uniform grey.
pub fn environments(scene_env: &EnvSource) -> Vec<(String, EnvSource)> {
    let mut out = vec![("scene's".to_string(), scene_env.clone())];
    for name in crate::assets::ENV_MAPS {
        if let Ok(path) = crate::assets::find(&format!("env/{name}")) {
            out.push((name.to_string(), EnvSource::File(path)));
        }
    }
    for s in ["sky", "uniform:0.5,0.5,0.5"] {
        if let Ok(source) = s.parse() {
            out.push((s.to_string(), source));
        }
    }
    out
}

/// Per-pass history of the rendered frames and the window's frame times.
#[derive(Default)]
pub struct Timings {
    /// Rendered frames (the skin pipeline).
    frames: VecDeque<FrameTiming>,
    /// Window frames (present, ui).
    window: VecDeque<FrameTiming>,
    window_ms: VecDeque<f64>,
}

impl Timings {
    pub fn add_frame(&mut self, report: FrameTiming) {
        push(&mut self.frames, report);
    }

    pub fn add_window_frame(&mut self, report: FrameTiming) {
        push(&mut self.window, report);
    }

    pub fn add_window_ms(&mut self, ms: f64) {
        push(&mut self.window_ms, ms);
    }

    /// (pass, median ms, frames) over the rendered frames kept, then the
    /// window's, in pass order.
    pub fn passes(&self) -> Vec<(String, f64, usize)> {
        [&self.frames, &self.window]
            .into_iter()
            .flat_map(|frames| {
                let mut names: Vec<&str> = Vec::new();
                for p in frames.iter().flat_map(|f| &f.passes) {
                    if !names.contains(&p.name.as_str()) {
                        names.push(&p.name);
                    }
                }
                names.into_iter().map(|n| {
                    let mut v: Vec<f64> = frames.iter().filter_map(|f| f.pass_ns(n)).collect();
                    v.sort_by(f64::total_cmp);
                    (n.to_string(), v[v.len() / 2] / 1e6, v.len())
                })
            })
            .collect()
    }
}

impl Timings {
    /// The window frames' median and worst time, ms.
    pub fn window_summary(&self) -> String {
        let mut v: Vec<f64> = self.window_ms.iter().copied().collect();
        v.sort_by(f64::total_cmp);
        match (v.get(v.len() / 2), v.last()) {
            (Some(median), Some(max)) => format!(
                "window frames: median {median:.1} ms, max {max:.1} ms over {}",
                v.len()
            ),
            _ => "window frames: none".into(),
        }
    }
}

fn push<T>(q: &mut VecDeque<T>, v: T) {
    if q.len() == HISTORY {
        q.pop_front();
    }
    q.push_back(v);
}

/// What the window shows beside the controls.
pub struct Status<'a> {
    pub device: &'a str,
    /// The last render: its size, sources extracted, seconds; or an error.
    pub last: &'a str,
    pub rendering: bool,
}

/// The side panel and the right-click menu over the rest; returns whether a
/// screenshot was asked for and the rest's rectangle (points), where the
/// rendered frame goes.
pub fn show(
    ui: &mut egui::Ui,
    c: &mut Controls,
    envs: &[(String, EnvSource)],
    status: &Status,
    timings: &Timings,
) -> (bool, egui::Rect) {
    let mut screenshot = false;
    // At most half the window: the frame beside it never shrinks to nothing.
    let most = 0.5 * ui.max_rect().width();
    egui::Panel::left("controls")
        .default_size(270.0)
        .size_range(egui::Rangef::new(0.0, most.max(0.0)))
        .show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                ui.heading("dermis");
                ui.label(status.device);
                ui.label(if status.rendering {
                    "rendering…"
                } else {
                    status.last
                });
                ui.separator();
                controls(ui, c, envs);
                ui.separator();
                screenshot = ui.button("Screenshot (F12)").clicked();
                egui::CollapsingHeader::new("Timings")
                    .default_open(true)
                    .show(ui, |ui| timing_table(ui, timings));
                egui::CollapsingHeader::new("Keys").show(ui, |ui| {
                    ui.label(HELP);
                });
            });
        });
    let response = egui::CentralPanel::no_frame()
        .show(ui, |ui| {
            ui.allocate_rect(ui.max_rect(), egui::Sense::click())
        })
        .inner;
    response.context_menu(|ui| controls(ui, c, envs));
    (screenshot, response.rect)
}

/// The keys and the mouse, as the window's help lists them.
pub const HELP: &str = "Left drag: orbit\nRight or middle drag: pan\nWheel: zoom\n\
Shift + left drag: turn the environment\nRight click: the controls\n\
F12: screenshot (PNG)\nR: reload the scene file\nEsc: quit";

/// The paper's menu: view, exposure, lighting, diffusion.
fn controls(ui: &mut egui::Ui, c: &mut Controls, envs: &[(String, EnvSource)]) {
    let f = &mut c.file;
    egui::ComboBox::from_label("view")
        .selected_text(c.view.name())
        .show_ui(ui, |ui| {
            // The CPU reference is too slow for a viewer.
            for name in c.views.iter().filter(|n| *n != Screen::Reference.name()) {
                ui.selectable_value(&mut c.view, View::named(name), name);
            }
        });
    let mut metered = f.render.exposure.is_none();
    ui.checkbox(&mut metered, "metered exposure");
    if metered {
        f.render.exposure = None;
    } else {
        let mut ev = f.render.exposure.unwrap_or(0.0);
        ui.add(egui::Slider::new(&mut ev, -8.0..=8.0).text("exposure (EV)"));
        f.render.exposure = Some(ev);
    }
    egui::ComboBox::from_label("tone curve")
        .selected_text(format!("{:?}", f.render.tone_curve).to_lowercase())
        .show_ui(ui, |ui| {
            for t in [ToneCurve::Linear, ToneCurve::Aces, ToneCurve::Neutral] {
                ui.selectable_value(&mut f.render.tone_curve, t, format!("{t:?}").to_lowercase());
            }
        });
    ui.horizontal(|ui| {
        ui.checkbox(&mut f.render.glow, "glow");
        ui.add_enabled(
            f.render.glow,
            egui::Slider::new(&mut f.render.glow_intensity, 0.0..=4.0).text("intensity"),
        );
    });
    ui.checkbox(&mut f.render.skybox, "skybox");
    ui.checkbox(&mut f.textures.test_texture, "test texture");
    ui.separator();
    let current = envs
        .iter()
        .find(|(_, s)| *s == f.environment.source)
        .map_or_else(|| f.environment.source.to_string(), |(n, _)| n.clone());
    egui::ComboBox::from_label("environment")
        .selected_text(current)
        .show_ui(ui, |ui| {
            for (name, source) in envs {
                ui.selectable_value(&mut f.environment.source, source.clone(), name);
            }
        });
    ui.horizontal(|ui| {
        ui.text_edit_singleline(&mut c.env_text)
            .on_hover_text("a .hdr/.exr file, sky[:…] or uniform:R,G,B");
        if ui.button("load").clicked() {
            match c.env_text.parse::<EnvSource>() {
                Ok(source) => {
                    f.environment.source = source;
                    c.env_error = None;
                }
                Err(e) => c.env_error = Some(e.to_string()),
            }
        }
    });
    if let Some(e) = &c.env_error {
        ui.colored_label(ui.visuals().error_fg_color, e);
    }
    ui.add(egui::Slider::new(&mut f.environment.rotation_deg, 0.0..=360.0).text("rotation (°)"));
    let mut lights = f.environment.lights != LightsMode::Count(0);
    ui.checkbox(&mut lights, "bright sources as lights");
    f.environment.lights = if lights {
        LightsMode::Auto
    } else {
        LightsMode::Count(0)
    };
    egui::ComboBox::from_label("occlusion")
        .selected_text(format!("{:?}", f.skin.occlusion).to_lowercase())
        .show_ui(ui, |ui| {
            for o in [Occlusion::Raytrace, Occlusion::Raster, Occlusion::Off] {
                ui.selectable_value(&mut f.skin.occlusion, o, format!("{o:?}").to_lowercase());
            }
        });
    ui.separator();
    ui.add(egui::Slider::new(&mut f.skin.blur_width, 0.0..=4.0).text("blur width"));
    ui.add(egui::Slider::new(&mut f.skin.blur_amount, 0.0..=1.0).text("blur amount"));
    egui::ComboBox::from_label("irradiance")
        .selected_text(format!("{}²", f.render.irradiance_resolution))
        .show_ui(ui, |ui| {
            for r in [256, 512, 1024, 2048, 4096] {
                ui.selectable_value(&mut f.render.irradiance_resolution, r, format!("{r}²"));
            }
        });
    egui::ComboBox::from_label("kernel")
        .selected_text(format!("{:?}", f.skin.kernel).to_lowercase())
        .show_ui(ui, |ui| {
            for k in [Kernel::Deon7, Kernel::Accurate] {
                ui.selectable_value(&mut f.skin.kernel, k, format!("{k:?}").to_lowercase());
            }
        });
    egui::ComboBox::from_label("chain")
        .selected_text(format!("{:?}", f.skin.chain).to_lowercase())
        .show_ui(ui, |ui| {
            for ch in [Chain::Adaptive, Chain::Full] {
                ui.selectable_value(&mut f.skin.chain, ch, format!("{ch:?}").to_lowercase());
            }
        });
}

/// Per-pass medians of the rendered frames kept, and the window's frame times.
fn timing_table(ui: &mut egui::Ui, t: &Timings) {
    let passes = t.passes();
    ui.label(format!(
        "medians of the last {} rendered and {} window frames",
        t.frames.len(),
        t.window.len()
    ));
    egui::Grid::new("passes").striped(true).show(ui, |ui| {
        for (name, ms, _) in &passes {
            ui.label(name);
            ui.label(format!("{ms:.2} ms"));
            ui.end_row();
        }
    });
    ui.label("window frames (ms):");
    let (rect, _) =
        ui.allocate_exact_size(egui::vec2(ui.available_width(), 60.0), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    let max = t.window_ms.iter().copied().fold(1.0, f64::max);
    let points: Vec<egui::Pos2> = t
        .window_ms
        .iter()
        .enumerate()
        .map(|(i, ms)| {
            egui::pos2(
                rect.left() + rect.width() * i as f32 / HISTORY as f32,
                rect.bottom() - rect.height() * (*ms / max) as f32,
            )
        })
        .collect();
    painter.rect_stroke(
        rect,
        0.0,
        ui.visuals().widgets.noninteractive.bg_stroke,
        egui::StrokeKind::Inside,
    );
    painter.add(egui::Shape::line(
        points,
        ui.visuals().widgets.active.fg_stroke,
    ));
    if let Some(last) = t.window_ms.back() {
        ui.label(format!("last {last:.1} ms, max {max:.1} ms"));
    }
}
