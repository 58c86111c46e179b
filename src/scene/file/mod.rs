//! The TOML scene file: which mesh, maps, lighting, camera, skin parameters and
//! render settings to use. Every field is optional; `docs/reference/scene-format.md` lists
//! each one with its unit, default, valid range and the source of the default.
//!
//! [`load_scene`] parses, checks every value ([`SceneFile::validate`]) and resolves
//! relative paths against the scene file's directory. Errors are [`SceneError`]s:
//! one line that names the file and the problem.

mod camera;
mod environment;
mod error;
mod medium;
mod render;
mod skin;
#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::env::EnvSource;
pub use camera::{Camera, Light, LightKind, Orbit};
pub use environment::{
    parse_env_source, Environment, LightsMode, EMPTY_ENV_SOURCE, MAX_EXTRACTED_LIGHTS,
};
use error::one_line;
pub use error::SceneError;
pub use medium::{Inversion, Medium, MediumPreset, SpecularRule, MAX_IOR};
pub use render::{Gamma, IrradianceShading, Render, ToneCurve, MAX_RENDER_SIZE};
pub use skin::{
    Chain, Kernel, Occlusion, ProfileGaussian, Skin, SpecularRegion, MAX_BLUR_WIDTH,
    PROFILE_SUM_TOLERANCE, REGION_COUNT,
};

// ---------------------------------------------------------------------------
// The scene description. Field defaults are documented in docs/reference/scene-format.md.

/// A parsed scene. `SceneFile::default()` is the built-in head under the `sky`
/// environment with every other setting at its default.
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SceneFile {
    /// glTF mesh (.glb or .gltf); `None` = the built-in head.
    pub mesh: Option<PathBuf>,
    /// Millimetres per mesh unit; `None` = glTF's metres (1000).
    pub mm_per_unit: Option<f32>,
    pub textures: Textures,
    pub environment: Environment,
    pub camera: Camera,
    pub lights: Vec<Light>,
    pub skin: Skin,
    pub render: Render,
}

/// Texture maps; each `None` means a constant stand-in (see the docs).
#[derive(Clone, Debug, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Textures {
    /// Diffuse albedo, sRGB.
    pub albedo: Option<PathBuf>,
    /// Tangent-space normal map, linear (glTF convention: +Y toward image top).
    pub normal: Option<PathBuf>,
    /// Specular intensity, linear grey; scales the region's ρs.
    pub specular: Option<PathBuf>,
    /// Beckmann roughness m, linear grey (value / 255); replaces the region's m.
    pub roughness: Option<PathBuf>,
    /// Face-region ids: red channel = index into `skin.regions` (0..=9).
    pub regions: Option<PathBuf>,
    /// Which corner of the maps the UV origin is; applies to every map given.
    pub uv_origin: UvOrigin,
    /// Replace the albedo by the numbered UV checker (`texture::test_texture`;
    /// the paper's "toggle test texture").
    pub test_texture: bool,
}

/// The texture corner at UV (0, 0), i.e. the image row that v = 0 samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum UvOrigin {
    /// glTF 2.0 (UV (0, 0) is "the upper left corner of a texture image"),
    /// Vulkan, Direct3D: row 0 at v = 0. The renderer's own convention.
    #[default]
    TopLeft,
    /// OpenGL: row 0 at v = 1. The maps are flipped vertically on load and the
    /// bitangent sign negated (`Scene::load`).
    BottomLeft,
}

impl std::str::FromStr for UvOrigin {
    type Err = String;
    /// The scene file's spelling: `top-left` or `bottom-left`.
    fn from_str(s: &str) -> Result<UvOrigin, String> {
        match s {
            "top-left" => Ok(UvOrigin::TopLeft),
            "bottom-left" => Ok(UvOrigin::BottomLeft),
            _ => Err(format!("{s:?}: expected top-left or bottom-left")),
        }
    }
}

// ---------------------------------------------------------------------------
// Loading

/// What `--scene` names: `builtin` is the built-in procedural head under the sky
/// ([`SceneFile::default`]); anything else a scene file.
pub const BUILTIN: &str = "builtin";

/// The scene `dermis render` draws when none is named: `assets/default.toml`, the
/// scan under a CC0 map, framed as a portrait, found by [`crate::assets::find`].
pub fn default_scene_path() -> Result<PathBuf, SceneError> {
    crate::assets::find("default.toml").map_err(SceneError::Assets)
}

/// The scene a command line names: `None` the default scene, [`BUILTIN`] the
/// built-in head, else a scene file.
pub fn scene_by_name(name: Option<&Path>) -> Result<SceneFile, SceneError> {
    match name {
        Some(p) if p == Path::new(BUILTIN) => Ok(SceneFile::default()),
        Some(p) => load_scene(p),
        None => load_scene(&default_scene_path()?),
    }
}

/// Reads, parses, validates a scene file and resolves its relative paths against
/// the file's directory.
pub fn load_scene(path: &Path) -> Result<SceneFile, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_scene(&text, path)
}

/// Parses and validates scene text as if it were the file `path` (used in messages
/// and as the base for relative paths; the file itself is not read).
pub fn parse_scene(text: &str, path: &Path) -> Result<SceneFile, SceneError> {
    let mut scene: SceneFile = toml::from_str(text).map_err(|e| toml_error(path, text, &e))?;
    scene
        .validate()
        .map_err(|message| SceneError::invalid(path, message))?;
    let base = match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
        _ => PathBuf::from("."),
    };
    scene.resolve_paths(&base);
    Ok(scene)
}

/// The toml crate's message with 1-based line and column from its byte span.
fn toml_error(path: &Path, text: &str, e: &toml::de::Error) -> SceneError {
    let Some(span) = e.span() else {
        return SceneError::invalid(path, e.message());
    };
    let before = text.get(..span.start).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before.get(line_start..).map_or(0, |s| s.chars().count()) + 1;
    SceneError::Toml {
        path: path.to_path_buf(),
        line,
        column,
        message: one_line(e.message()),
    }
}

impl SceneFile {
    /// Joins every relative path onto `base` (absolute paths are kept).
    pub fn resolve_paths(&mut self, base: &Path) {
        let fix = |p: &mut Option<PathBuf>| {
            if let Some(path) = p {
                *path = base.join(&*path);
            }
        };
        fix(&mut self.mesh);
        fix(&mut self.textures.albedo);
        fix(&mut self.textures.normal);
        fix(&mut self.textures.specular);
        fix(&mut self.textures.roughness);
        fix(&mut self.textures.regions);
        match &mut self.environment.source {
            EnvSource::File(path) => *path = base.join(&*path),
            EnvSource::Cube(faces) => faces.iter_mut().for_each(|p| *p = base.join(&*p)),
            EnvSource::Uniform(_) | EnvSource::Sky(_) => {}
        }
    }

    /// Checks every value; the error names the key, e.g. `render.width = 0: ...`.
    pub fn validate(&self) -> Result<(), String> {
        if let Some(mm) = self.mm_per_unit {
            positive("mm_per_unit", mm)?;
        }
        self.environment.validate()?;
        self.camera.validate()?;
        for (i, light) in self.lights.iter().enumerate() {
            light.validate(&format!("lights[{i}]"))?;
        }
        self.skin.validate()?;
        self.render.validate()
    }
}

fn finite(key: &str, v: f32) -> Result<(), String> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(format!("{key} = {v}: must be a finite number"))
    }
}

fn positive(key: &str, v: f32) -> Result<(), String> {
    finite(key, v)?;
    if v > 0.0 {
        Ok(())
    } else {
        Err(format!("{key} = {v}: must be greater than 0"))
    }
}

fn non_negative(key: &str, v: f32) -> Result<(), String> {
    finite(key, v)?;
    if v >= 0.0 {
        Ok(())
    } else {
        Err(format!("{key} = {v}: must not be negative"))
    }
}

fn in_range(key: &str, v: f32, lo: f32, hi: f32) -> Result<(), String> {
    finite(key, v)?;
    if (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(format!("{key} = {v}: must be in [{lo}, {hi}]"))
    }
}

fn finite3(key: &str, v: [f32; 3]) -> Result<Vec3, String> {
    let v = Vec3::from(v);
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!(
            "{key} = {v}: every component must be a finite number"
        ))
    }
}

fn nonzero3(key: &str, v: [f32; 3]) -> Result<Vec3, String> {
    let v = finite3(key, v)?;
    if v.length_squared() > 0.0 {
        Ok(v)
    } else {
        Err(format!("{key} = [0, 0, 0]: must not be the zero vector"))
    }
}
