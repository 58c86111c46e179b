//! What a render writes: a screen view, which has shading of its own (the final
//! image, its terms, the debug views), or any image of the frame graph by name
//! (the paper's debug views of the intermediates: irradiance, stretch and blur
//! levels, the prefiltered environment …), read back as stored.

use crate::error::{Error, Result};
use crate::light::direct::DirectView;
use crate::post::debug::DebugView;
pub use crate::post::Shown;
use crate::skin::shade::ShadeMode;

/// A view with shading of its own: the pass that writes its screen image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Screen {
    /// The skin pass: the final image, or its diffuse, specular or transmitted
    /// term alone.
    Skin(ShadeMode),
    /// Direct diffuse shading in screen space (no scattering), or the
    /// per-vertex occlusion relative to open sky.
    Direct(DirectView),
    /// Depth, normals, albedo, regions (post::debug).
    Debug(DebugView),
    /// The final image with the numbered UV checker as the albedo (scene::checker).
    TestTexture,
    /// The direct term integrated on the CPU by Monte Carlo against the full
    /// environment map with ray-cast visibility (light::reference): slow, offline.
    Reference,
}

impl Screen {
    /// Every screen view, in the order `--view list` prints them.
    pub fn all() -> impl Iterator<Item = Screen> {
        ShadeMode::ALL
            .map(Screen::Skin)
            .into_iter()
            .chain(DirectView::ALL.map(Screen::Direct))
            .chain([Screen::Reference])
            .chain(DebugView::ALL.map(Screen::Debug))
            .chain([Screen::TestTexture])
    }

    pub fn name(self) -> &'static str {
        match self {
            Screen::Skin(mode) => mode.name(),
            Screen::Direct(view) => view.name(),
            Screen::Debug(view) => view.name(),
            Screen::TestTexture => "test-texture",
            Screen::Reference => "reference",
        }
    }

    /// How the view is shown.
    pub fn shown(self) -> Shown {
        match self {
            Screen::Skin(_)
            | Screen::TestTexture
            | Screen::Reference
            | Screen::Direct(DirectView::Shading) => Shown::Exposed,
            Screen::Direct(DirectView::Occlusion) => Shown::Fraction,
            Screen::Debug(view) => view.shown(),
        }
    }
}

/// What `render` writes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum View {
    Screen(Screen),
    /// An image of the frame graph by name (`render --view list`), read back
    /// as stored, without tone mapping: the UV-space intermediates.
    Image(String),
}

impl View {
    /// The final image: texture-space diffusion and specular.
    pub const FINAL: View = View::Screen(Screen::Skin(ShadeMode::Full));

    /// The screen view named `name`, else the graph image of that name (the
    /// frame checks that it has one).
    pub fn named(name: &str) -> View {
        Screen::all()
            .find(|s| s.name() == name)
            .map_or_else(|| View::Image(name.into()), View::Screen)
    }

    /// `--view NAME`: [`View::named`], for a name that can be one.
    pub fn parse(name: &str) -> Result<View> {
        if name.trim().is_empty() {
            return Err(Error::Input(
                "--view: empty; `dermis render --view list` lists the views".into(),
            ));
        }
        Ok(View::named(name))
    }

    pub fn name(&self) -> &str {
        match self {
            View::Screen(s) => s.name(),
            View::Image(name) => name,
        }
    }

    /// Whether the view is an intermediate image rather than a screen image:
    /// read back as stored, without tone mapping.
    pub fn uv_space(&self) -> bool {
        matches!(self, View::Image(_))
    }

    /// How the view is shown (an image as stored is exposed like radiance).
    pub fn shown(&self) -> Shown {
        match self {
            View::Screen(s) => s.shown(),
            View::Image(_) => Shown::Exposed,
        }
    }
}

impl std::str::FromStr for View {
    type Err = Error;

    fn from_str(s: &str) -> Result<View> {
        View::parse(s)
    }
}

impl std::fmt::Display for View {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        let names: Vec<_> = Screen::all().map(Screen::name).collect();
        assert_eq!(names.len(), 12, "{names:?}");
        for s in Screen::all() {
            assert_eq!(View::parse(s.name()).unwrap(), View::Screen(s));
        }
        assert_eq!(View::parse("blur4").unwrap(), View::Image("blur4".into()));
        assert_eq!(View::parse("final").unwrap(), View::FINAL);
        assert!(View::parse(" ").is_err());
        assert!(View::named("irradiance").uv_space() && !View::FINAL.uv_space());
    }
}
