//! The TOML scene file: which mesh, maps, lighting, camera, skin parameters and
//! render settings to use. Every field is optional; `docs/scene-format.md` lists
//! each one with its unit, default, valid range and the source of the default.
//!
//! [`load_scene`] parses, checks every value ([`SceneFile::validate`]) and resolves
//! relative paths against the scene file's directory. Errors are [`SceneError`]s:
//! one line that names the file and the problem.

use std::fmt;
use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::{Deserialize, Deserializer, Serialize};

use super::env::{EnvSource, SkyParams};

/// Everything that can go wrong reading scene input (scene file, mesh, textures).
/// Each message is a single line that starts with the offending file.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be opened or read.
    #[error("{}: cannot read file: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// TOML syntax or a field of the wrong name or type (line and column are 1-based).
    #[error("{}: line {line}, column {column}: {message}", path.display())]
    Toml {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    /// A scene value out of its valid range; the message names the key.
    #[error("{}: {message}", path.display())]
    Invalid { path: PathBuf, message: String },
    /// A mesh file that cannot be used.
    #[error("{}: {message}", path.display())]
    Mesh { path: PathBuf, message: String },
    /// A texture file that cannot be used.
    #[error("{}: {message}", path.display())]
    Texture { path: PathBuf, message: String },
}

impl From<SceneError> for crate::error::Error {
    fn from(e: SceneError) -> Self {
        crate::error::Error::BadInput(Box::new(e))
    }
}

impl SceneError {
    pub(crate) fn invalid(path: &Path, message: impl AsRef<str>) -> SceneError {
        SceneError::Invalid {
            path: path.to_path_buf(),
            message: one_line(message.as_ref()),
        }
    }

    pub(crate) fn mesh(path: &Path, message: impl AsRef<str>) -> SceneError {
        SceneError::Mesh {
            path: path.to_path_buf(),
            message: one_line(message.as_ref()),
        }
    }

    pub(crate) fn texture(path: &Path, message: impl AsRef<str>) -> SceneError {
        SceneError::Texture {
            path: path.to_path_buf(),
            message: one_line(message.as_ref()),
        }
    }
}

/// Collapses any run of whitespace (including newlines) to one space.
fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

// ---------------------------------------------------------------------------
// The scene description. Field defaults are documented in docs/scene-format.md.

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
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, clap::ValueEnum)]
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

/// Distant lighting.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Environment {
    /// `sky`, `sky:elevation=..,azimuth=..,turbidity=..`, `uniform:R,G,B`,
    /// `cube:...` or a file path (resolved against the scene file's directory on
    /// load), parsed when the file is read.
    #[serde(deserialize_with = "env_source")]
    pub source: EnvSource,
    /// Rotation about +Y, degrees.
    pub rotation_deg: f32,
    /// Radiance multiplier.
    pub intensity: f32,
    /// Which bright sources are taken out of the map as directional lights
    /// (`light::extract`).
    #[serde(deserialize_with = "env_lights")]
    pub lights: LightsMode,
}

impl Default for Environment {
    fn default() -> Environment {
        Environment {
            source: EnvSource::Sky(SkyParams::default()),
            rotation_deg: 0.0,
            intensity: 1.0,
            lights: LightsMode::Auto,
        }
    }
}

/// Most lights `light::extract` takes out of one environment map: each costs a
/// shadow map per frame, and the CC0 maps need at most 4 (docs/lighting.md).
pub const MAX_EXTRACTED_LIGHTS: usize = 8;

/// How many bright sources are extracted from the environment map as lights:
/// `"auto"` or a count `0..=`[`MAX_EXTRACTED_LIGHTS`] (0: none, the map is used
/// whole). Written `auto` or `N` (scene file: the string `"auto"` or an integer).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LightsMode {
    /// Every compact source holding a large share of the map's energy (the rule
    /// in `light::extract`).
    #[default]
    Auto,
    /// The `n` strongest candidates, whatever their share or size.
    Count(usize),
}

impl LightsMode {
    fn bad(value: impl fmt::Display) -> String {
        format!(
            "expected \"auto\" or a number of lights in 0..={MAX_EXTRACTED_LIGHTS}, got '{value}'"
        )
    }

    fn count(n: i128) -> Result<LightsMode, String> {
        match usize::try_from(n) {
            Ok(n) if n <= MAX_EXTRACTED_LIGHTS => Ok(LightsMode::Count(n)),
            _ => Err(LightsMode::bad(n)),
        }
    }
}

impl std::str::FromStr for LightsMode {
    type Err = String;
    fn from_str(s: &str) -> Result<LightsMode, String> {
        match s.trim() {
            "auto" => Ok(LightsMode::Auto),
            t => match t.parse::<i128>() {
                Ok(n) => LightsMode::count(n),
                Err(_) => Err(LightsMode::bad(s)),
            },
        }
    }
}

impl fmt::Display for LightsMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LightsMode::Auto => f.write_str("auto"),
            LightsMode::Count(n) => write!(f, "{n}"),
        }
    }
}

impl Serialize for LightsMode {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            LightsMode::Auto => s.serialize_str("auto"),
            LightsMode::Count(n) => s.serialize_u64(*n as u64),
        }
    }
}

impl<'de> Deserialize<'de> for LightsMode {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<LightsMode, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = LightsMode;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(
                    f,
                    "\"auto\" or a number of lights in 0..={MAX_EXTRACTED_LIGHTS}"
                )
            }
            fn visit_str<E: serde::de::Error>(self, s: &str) -> Result<LightsMode, E> {
                s.parse().map_err(E::custom)
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<LightsMode, E> {
                LightsMode::count(v.into()).map_err(E::custom)
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<LightsMode, E> {
                LightsMode::count(v.into()).map_err(E::custom)
            }
        }
        d.deserialize_any(V)
    }
}

/// `environment.lights`: [`LightsMode`]'s message, prefixed with the key.
fn env_lights<'de, D: Deserializer<'de>>(d: D) -> Result<LightsMode, D::Error> {
    LightsMode::deserialize(d)
        .map_err(|e| serde::de::Error::custom(format!("environment.lights: {e}")))
}

/// The message for an empty `environment.source` (scene file or `--env`).
pub(crate) const EMPTY_ENV_SOURCE: &str =
    "environment.source is empty: use \"sky\", \"uniform:R,G,B\" or a file path";

/// `environment.source`: parsed once, here, with `EnvSource`'s `FromStr`.
fn env_source<'de, D: Deserializer<'de>>(d: D) -> Result<EnvSource, D::Error> {
    let s = String::deserialize(d)?;
    if s.trim().is_empty() {
        return Err(serde::de::Error::custom(EMPTY_ENV_SOURCE));
    }
    s.parse().map_err(serde::de::Error::custom)
}

/// Camera: `position`/`target`/`up` (world mm) or an `orbit` around the mesh centre.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Camera {
    pub position: Option<[f32; 3]>,
    /// Point looked at; `None` = the mesh's bounding-box centre.
    pub target: Option<[f32; 3]>,
    /// `None` = +Y.
    pub up: Option<[f32; 3]>,
    pub orbit: Option<Orbit>,
    /// Vertical field of view, degrees.
    pub fov_deg: f32,
    pub near_mm: f32,
    pub far_mm: f32,
}

impl Default for Camera {
    fn default() -> Camera {
        Camera {
            position: None,
            target: None,
            up: None,
            orbit: None,
            fov_deg: 30.0,
            near_mm: 10.0,
            far_mm: 10_000.0,
        }
    }
}

/// A camera on a sphere around the mesh's bounding-box centre, looking at it.
/// yaw 0, pitch 0 puts the camera on +Z (the glTF front), +Y up.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Orbit {
    /// Rotation about +Y, degrees, counter-clockwise seen from above (+X side at 90).
    pub yaw_deg: f32,
    /// Elevation above the horizontal plane, degrees, in (-90, 90).
    pub pitch_deg: f32,
    /// Distance from the centre, mm.
    pub distance_mm: f32,
}

impl Default for Orbit {
    fn default() -> Orbit {
        Orbit {
            yaw_deg: 0.0,
            pitch_deg: 0.0,
            distance_mm: 700.0,
        }
    }
}

impl Camera {
    /// Eye, target and up vector (world mm) given the mesh's bounding-box centre.
    pub fn eye_target_up(&self, mesh_centre: Vec3) -> (Vec3, Vec3, Vec3) {
        let up = self.up.map(Vec3::from).unwrap_or(Vec3::Y);
        match self.position {
            Some(p) => (
                Vec3::from(p),
                self.target.map(Vec3::from).unwrap_or(mesh_centre),
                up,
            ),
            None => {
                let o = self.orbit.unwrap_or_default();
                let (yaw, pitch) = (o.yaw_deg.to_radians(), o.pitch_deg.to_radians());
                let dir = Vec3::new(
                    pitch.cos() * yaw.sin(),
                    pitch.sin(),
                    pitch.cos() * yaw.cos(),
                );
                (mesh_centre + o.distance_mm * dir, mesh_centre, up)
            }
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LightKind {
    Directional,
    Point,
}

/// An analytic light added to the environment.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Light {
    pub kind: LightKind,
    /// Directional: the direction light travels (from the light into the scene).
    pub direction: Option<[f32; 3]>,
    /// Point: world position, mm.
    pub position: Option<[f32; 3]>,
    /// Linear RGB.
    #[serde(default = "white")]
    pub color: [f32; 3],
    /// Directional: irradiance on a surface facing the light, in environment
    /// radiance units × sr. Point: the same at 1000 mm; falls off as 1/d².
    #[serde(default = "one")]
    pub intensity: f32,
    /// Casts shadows through the shadow/depth pass.
    #[serde(default = "yes")]
    pub shadow: bool,
    /// Directional: the source's angular diameter, degrees (the sun: 0.53);
    /// 0 is a parallel beam. It softens the shadow and widens the highlight.
    #[serde(default)]
    pub angular_diameter_deg: f32,
}

fn white() -> [f32; 3] {
    [1.0, 1.0, 1.0]
}
fn one() -> f32 {
    1.0
}
fn yes() -> bool {
    true
}

/// Blur kernel for the Gaussian chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Kernel {
    /// d'Eon's 7 taps at -3σ..3σ (GPU Gems 3 §14.5; weights in ARCHITECTURE.md).
    Deon7,
    /// Wider, exactly normalised Gaussian taps (reference quality).
    Accurate,
}

/// At which resolutions the six Gaussians of the diffusion chain are blurred.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Chain {
    /// Every level at `render.irradiance_resolution` (GPU Gems 3 §14.5).
    Full,
    /// Each level at the coarsest resolution its width allows (skin::chain).
    Adaptive,
}

/// How the per-vertex SH transfer's visibility is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Occlusion {
    /// The paper's cube maps rasterised per vertex on the GPU.
    Raster,
    /// Rays cast on the CPU (the default).
    Raytrace,
    /// No self-occlusion (unshadowed transfer).
    Off,
}

/// One term of the sum-of-Gaussians diffusion profile.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileGaussian {
    /// Variance v in mm², G(v, r) = exp(-r²/2v) / (2πv).
    pub variance_mm2: f32,
    /// Linear RGB weight of this term.
    pub weights: [f32; 3],
}

/// Kelemen/Szirmay-Kalos specular parameters of one face region.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpecularRegion {
    pub name: String,
    /// Specular scale ρs.
    pub rho_s: f32,
    /// Beckmann roughness m.
    pub m: f32,
}

/// Number of face regions the region map indexes (Weyrich et al. 2006, used by
/// GPU Gems 3 §14.3).
pub const REGION_COUNT: usize = 10;

/// Skin appearance parameters.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Skin {
    /// Albedo applied before scattering as albedo^mix, after as albedo^(1-mix)
    /// (pre-/post-scatter texturing, GPU Gems 3 §14.5).
    pub mix: f32,
    pub kernel: Kernel,
    pub chain: Chain,
    /// Sum-of-Gaussians profile, variances strictly increasing; `None`: the
    /// skin model's published six-Gaussian profile (skin::profile).
    pub profile: Option<Vec<ProfileGaussian>>,
    /// Exactly [`REGION_COUNT`] regions; `None`: the skin model's defaults
    /// (skin::specular).
    pub regions: Option<Vec<SpecularRegion>>,
    pub occlusion: Occlusion,
    /// Correct blur widths for UV distortion with the stretch map (the paper's
    /// section II.B); off: one texels-per-mm constant for the whole mesh.
    pub stretch_correction: bool,
    /// Scale on every variance of the profile (the paper's "blurring width";
    /// 0: no blur).
    pub blur_width: f32,
    /// Share of the blurred irradiance in the diffuse term, the rest unblurred
    /// (the paper's "blurring amount"; 0: unblurred).
    pub blur_amount: f32,
}

impl Default for Skin {
    fn default() -> Skin {
        Skin {
            mix: 0.5,
            kernel: Kernel::Deon7,
            chain: Chain::Adaptive,
            profile: None,
            regions: None,
            occlusion: Occlusion::Raytrace,
            stretch_correction: true,
            blur_width: 1.0,
            blur_amount: 1.0,
        }
    }
}

/// The tone curve from exposed radiance to display values in [0, 1]
/// (post::tonemap, docs/post.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum ToneCurve {
    /// Clip to [0, 1].
    #[default]
    Linear,
    /// Narkowicz's fit of the ACES filmic curve (RRT + sRGB ODT).
    Aces,
    /// Khronos PBR Neutral (2024).
    Neutral,
}

/// Output transfer function.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Gamma {
    /// The piecewise sRGB curve (IEC 61966-2-1).
    Srgb,
    /// A pure power: encoded = linear^(1/γ). `"linear"` in the file is 1.0.
    Power(f32),
}

impl<'de> Deserialize<'de> for Gamma {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Gamma, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = Gamma;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("\"srgb\", \"linear\" or a number (a power-law gamma)")
            }
            fn visit_str<E: serde::de::Error>(self, s: &str) -> Result<Gamma, E> {
                match s {
                    "srgb" => Ok(Gamma::Srgb),
                    "linear" => Ok(Gamma::Power(1.0)),
                    _ => Err(E::invalid_value(serde::de::Unexpected::Str(s), &self)),
                }
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Gamma, E> {
                Ok(Gamma::Power(v as f32))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Gamma, E> {
                Ok(Gamma::Power(v as f32))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Gamma, E> {
                Ok(Gamma::Power(v as f32))
            }
        }
        d.deserialize_any(V)
    }
}

/// Output image and internal resolution.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Render {
    pub width: u32,
    pub height: u32,
    /// Side of the UV-space irradiance and blur targets (power of two, 256..=8192).
    pub irradiance_resolution: u32,
    /// Side of each light's shadow map (power of two, 256..=8192).
    pub shadow_resolution: u32,
    /// Exposure in EV (stops): output = radiance × 2^exposure. `None`: metered
    /// from the rendered frame (post::meter).
    pub exposure: Option<f32>,
    pub gamma: Gamma,
    pub tone_curve: ToneCurve,
    /// Draw the environment behind the head (its alpha stays 0: the HDR image's
    /// alpha is the mesh's coverage either way).
    pub skybox: bool,
    /// Display colour (linear, before the transfer function) where the mesh
    /// does not cover the image and the skybox is off.
    pub background: [f32; 3],
    /// d'Eon & Luebke's glow (post::glow).
    pub glow: bool,
    /// Multiplier of the glow kernel.
    pub glow_intensity: f32,
}

impl Default for Render {
    fn default() -> Render {
        Render {
            width: 1280,
            height: 720,
            irradiance_resolution: 4096,
            shadow_resolution: 2048,
            exposure: None,
            gamma: Gamma::Srgb,
            tone_curve: ToneCurve::Linear,
            skybox: true,
            background: [0.0; 3],
            glow: false,
            glow_intensity: 1.0,
        }
    }
}

/// Largest accepted render width or height.
pub const MAX_RENDER_SIZE: u32 = 16384;

// ---------------------------------------------------------------------------
// Loading

/// What `--scene` names: `builtin` is the built-in procedural head under the sky
/// ([`SceneFile::default`]); anything else a scene file.
pub const BUILTIN: &str = "builtin";

/// The scene `dermis render` draws when none is named: `assets/default.toml`, the
/// scan under a CC0 map, framed as a portrait.
pub fn default_scene_path() -> PathBuf {
    crate::assets::dir().join("default.toml")
}

/// The scene a command line names: `None` the default scene, [`BUILTIN`] the
/// built-in head, else a scene file.
pub fn scene_by_name(name: Option<&Path>) -> Result<SceneFile, SceneError> {
    match name {
        Some(p) if p == Path::new(BUILTIN) => Ok(SceneFile::default()),
        Some(p) => load_scene(p),
        None => load_scene(&default_scene_path()),
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

impl Environment {
    fn validate(&self) -> Result<(), String> {
        finite("environment.rotation_deg", self.rotation_deg)?;
        non_negative("environment.intensity", self.intensity)
    }
}

impl Camera {
    fn validate(&self) -> Result<(), String> {
        let fov = self.fov_deg;
        finite("camera.fov_deg", fov)?;
        if !(fov > 1.0 && fov < 179.0) {
            return Err(format!(
                "camera.fov_deg = {fov}: must be in (1, 179) degrees"
            ));
        }
        positive("camera.near_mm", self.near_mm)?;
        positive("camera.far_mm", self.far_mm)?;
        if self.far_mm <= self.near_mm {
            return Err(format!(
                "camera.far_mm = {} must be greater than camera.near_mm = {}",
                self.far_mm, self.near_mm
            ));
        }
        match (self.position, &self.orbit) {
            (Some(_), Some(_)) => {
                return Err(
                    "camera: give either position (with target, up) or orbit, not both".into(),
                )
            }
            (None, _) if self.target.is_some() || self.up.is_some() => {
                return Err("camera.target and camera.up need camera.position".into())
            }
            _ => {}
        }
        if let Some(p) = self.position {
            let p = finite3("camera.position", p)?;
            let up = match self.up {
                Some(u) => nonzero3("camera.up", u)?,
                None => Vec3::Y,
            };
            if let Some(t) = self.target {
                let view = finite3("camera.target", t)? - p;
                if view.length_squared() == 0.0 {
                    return Err("camera.target equals camera.position".into());
                }
                if view.normalize().cross(up.normalize()).length() < 1e-3 {
                    return Err("camera.up is parallel to the viewing direction".into());
                }
            }
        }
        if let Some(o) = &self.orbit {
            finite("camera.orbit.yaw_deg", o.yaw_deg)?;
            finite("camera.orbit.pitch_deg", o.pitch_deg)?;
            if !(o.pitch_deg > -90.0 && o.pitch_deg < 90.0) {
                return Err(format!(
                    "camera.orbit.pitch_deg = {}: must be in (-90, 90) degrees",
                    o.pitch_deg
                ));
            }
            positive("camera.orbit.distance_mm", o.distance_mm)?;
        }
        Ok(())
    }
}

impl Light {
    fn validate(&self, key: &str) -> Result<(), String> {
        match self.kind {
            LightKind::Directional => {
                if self.position.is_some() {
                    return Err(format!(
                        "{key}.position: a directional light has a direction, not a position"
                    ));
                }
                let d = self.direction.ok_or_else(|| {
                    format!("{key}.direction is required for a directional light")
                })?;
                nonzero3(&format!("{key}.direction"), d)?;
                // A cap wider than 40° is no longer one direction (its cosine
                // lobe and shadow would be far off).
                in_range(
                    &format!("{key}.angular_diameter_deg"),
                    self.angular_diameter_deg,
                    0.0,
                    40.0,
                )?;
            }
            LightKind::Point => {
                if self.angular_diameter_deg != 0.0 {
                    return Err(format!(
                        "{key}.angular_diameter_deg: only directional lights have an angular size"
                    ));
                }
                if self.direction.is_some() {
                    return Err(format!(
                        "{key}.direction: a point light has a position, not a direction"
                    ));
                }
                let p = self
                    .position
                    .ok_or_else(|| format!("{key}.position is required for a point light"))?;
                finite3(&format!("{key}.position"), p)?;
            }
        }
        for (c, v) in ["r", "g", "b"].iter().zip(self.color) {
            non_negative(&format!("{key}.color.{c}"), v)?;
        }
        non_negative(&format!("{key}.intensity"), self.intensity)
    }
}

/// Largest `skin.blur_width`: ten times the variances is σ₆ ≈ 8.6 mm, a blur
/// across the whole cheek.
pub const MAX_BLUR_WIDTH: f32 = 10.0;

/// Allowed deviation of each channel's profile weight sum from 1.
pub const PROFILE_SUM_TOLERANCE: f32 = 0.01;

impl Skin {
    fn validate(&self) -> Result<(), String> {
        in_range("skin.mix", self.mix, 0.0, 1.0)?;
        in_range("skin.blur_width", self.blur_width, 0.0, MAX_BLUR_WIDTH)?;
        in_range("skin.blur_amount", self.blur_amount, 0.0, 1.0)?;
        if let Some(profile) = &self.profile {
            validate_profile(profile)?;
        }
        if let Some(regions) = &self.regions {
            validate_regions(regions)?;
        }
        Ok(())
    }
}

fn validate_profile(profile: &[ProfileGaussian]) -> Result<(), String> {
    if profile.is_empty() {
        return Err("skin.profile is empty: give at least one Gaussian".into());
    }
    let mut sums = [0.0f32; 3];
    let mut previous: Option<f32> = None;
    for (i, g) in profile.iter().enumerate() {
        let key = format!("skin.profile[{i}]");
        non_negative(&format!("{key}.variance_mm2"), g.variance_mm2)?;
        if let Some(prev) = previous {
            if g.variance_mm2 <= prev {
                return Err(format!(
                    "{key}.variance_mm2 = {}: variances must increase strictly (the blur chain \
                     blurs each level from the previous one by the difference)",
                    g.variance_mm2
                ));
            }
        }
        previous = Some(g.variance_mm2);
        for (c, (sum, w)) in sums.iter_mut().zip(g.weights).enumerate() {
            non_negative(&format!("{key}.weights[{c}]"), w)?;
            *sum += w;
        }
    }
    for (c, sum) in ["red", "green", "blue"].iter().zip(sums) {
        if (sum - 1.0).abs() > PROFILE_SUM_TOLERANCE {
            return Err(format!(
                "skin.profile: the {c} weights sum to {sum}, not 1 (±{PROFILE_SUM_TOLERANCE})"
            ));
        }
    }
    Ok(())
}

fn validate_regions(regions: &[SpecularRegion]) -> Result<(), String> {
    if regions.len() != REGION_COUNT {
        return Err(format!(
            "skin.regions has {} entries; it needs exactly {REGION_COUNT}",
            regions.len()
        ));
    }
    for (i, r) in regions.iter().enumerate() {
        in_range(&format!("skin.regions[{i}].rho_s"), r.rho_s, 0.0, 1.0)?;
        positive(&format!("skin.regions[{i}].m"), r.m)?;
        in_range(&format!("skin.regions[{i}].m"), r.m, 0.0, 1.0)?;
    }
    Ok(())
}

impl Render {
    fn validate(&self) -> Result<(), String> {
        for (key, v) in [("render.width", self.width), ("render.height", self.height)] {
            if v == 0 || v > MAX_RENDER_SIZE {
                return Err(format!("{key} = {v}: must be in 1..={MAX_RENDER_SIZE}"));
            }
        }
        for (key, r) in [
            ("render.irradiance_resolution", self.irradiance_resolution),
            ("render.shadow_resolution", self.shadow_resolution),
        ] {
            if !r.is_power_of_two() || !(256..=8192).contains(&r) {
                return Err(format!("{key} = {r}: must be a power of two in 256..=8192"));
            }
        }
        if let Some(e) = self.exposure {
            finite("render.exposure", e)?;
        }
        if let Gamma::Power(g) = self.gamma {
            finite("render.gamma", g)?;
            if !(g > 0.0 && g <= 10.0) {
                return Err(format!("render.gamma = {g}: must be in (0, 10]"));
            }
        }
        for (c, v) in ["r", "g", "b"].iter().zip(self.background) {
            in_range(&format!("render.background.{c}"), v, 0.0, 1.0)?;
        }
        non_negative("render.glow_intensity", self.glow_intensity)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<SceneFile, SceneError> {
        parse_scene(text, Path::new("/scenes/scene.toml"))
    }

    fn err(text: &str) -> String {
        match parse(text) {
            Ok(s) => panic!("accepted: {text}\n{s:?}"),
            Err(e) => {
                let msg = e.to_string();
                assert!(msg.starts_with("/scenes/scene.toml: "), "{msg}");
                assert!(!msg.contains('\n'), "{msg}");
                msg
            }
        }
    }

    /// The repository root: this file lives at `src/scene/file.rs`.
    fn repo_root() -> PathBuf {
        let here = Path::new(file!());
        let file = if here.is_absolute() {
            here.to_path_buf()
        } else {
            Path::new(env!("CARGO_MANIFEST_DIR")).join(here)
        };
        file.ancestors().nth(3).map(Path::to_path_buf).unwrap()
    }

    /// The ```toml blocks of docs/scene-format.md.
    fn doc_examples() -> Vec<String> {
        let doc = repo_root().join("docs/scene-format.md");
        let text = std::fs::read_to_string(&doc).unwrap();
        let mut blocks = Vec::new();
        let mut current: Option<String> = None;
        for line in text.lines() {
            match (&mut current, line.trim_start()) {
                (None, l) if l.starts_with("```toml") => current = Some(String::new()),
                (Some(_), l) if l.starts_with("```") => blocks.extend(current.take()),
                (Some(block), _) => {
                    block.push_str(line);
                    block.push('\n');
                }
                _ => {}
            }
        }
        blocks
    }

    #[test]
    fn scenes_by_name() {
        let d = scene_by_name(None).unwrap();
        assert!(
            d.mesh.as_ref().unwrap().ends_with("LeePerrySmith.glb"),
            "{d:?}"
        );
        assert_eq!(d.mm_per_unit, Some(50.3));
        assert_eq!(d.textures.uv_origin, UvOrigin::BottomLeft);
        assert_eq!(
            scene_by_name(Some(Path::new(BUILTIN))).unwrap(),
            SceneFile::default()
        );
        assert!(scene_by_name(Some(Path::new("no/such.toml"))).is_err());
    }

    #[test]
    fn empty_file_is_the_default_scene() {
        let scene = parse("").unwrap();
        assert_eq!(scene, SceneFile::default());
        assert!(SceneFile::default().validate().is_ok());
        assert_eq!(scene.mesh, None);
        assert_eq!(
            scene.environment.source,
            EnvSource::Sky(SkyParams::default())
        );
        assert_eq!(scene.skin.mix, 0.5);
        assert_eq!(scene.skin.profile, None);
        assert_eq!(scene.skin.regions, None);
        assert_eq!(scene.render.irradiance_resolution, 4096);
        assert_eq!(scene.render.gamma, Gamma::Srgb);
    }

    #[test]
    fn full_file_parses_and_resolves_paths() {
        let text = r#"
mesh = "meshes/head.glb"
mm_per_unit = 50.3

[textures]
albedo = "maps/albedo.jpg"
normal = "/abs/normal.png"

[environment]
source = "env/studio.exr"
rotation_deg = 90
intensity = 2.5

[camera]
orbit = { yaw_deg = 30, pitch_deg = 10, distance_mm = 600 }
fov_deg = 25

[[lights]]
kind = "directional"
direction = [0, -1, -1]
color = [1, 0.9, 0.8]
intensity = 3
angular_diameter_deg = 0.53

[[lights]]
kind = "point"
position = [0, 500, 500]
shadow = false

[skin]
mix = 0.25
kernel = "accurate"
occlusion = "off"
blur_width = 0.5
blur_amount = 0.75
profile = [
  { variance_mm2 = 0.01, weights = [0.5, 0.5, 0.5] },
  { variance_mm2 = 1.0, weights = [0.5, 0.5, 0.5] },
]

[render]
width = 640
height = 480
irradiance_resolution = 1024
exposure = -1.5
gamma = 2.2
tone_curve = "neutral"
skybox = false
background = [0.1, 0.2, 0.3]
glow = true
glow_intensity = 0.5
"#;
        let s = parse(text).unwrap();
        assert_eq!(s.mesh, Some(PathBuf::from("/scenes/meshes/head.glb")));
        assert_eq!(s.mm_per_unit, Some(50.3));
        assert_eq!(
            s.textures.albedo,
            Some(PathBuf::from("/scenes/maps/albedo.jpg"))
        );
        assert_eq!(s.textures.normal, Some(PathBuf::from("/abs/normal.png")));
        assert_eq!(s.textures.specular, None);
        assert_eq!(
            s.environment.source,
            EnvSource::File(PathBuf::from("/scenes/env/studio.exr"))
        );
        assert_eq!(s.environment.intensity, 2.5);
        assert_eq!(s.camera.fov_deg, 25.0);
        assert_eq!(s.lights.len(), 2);
        assert_eq!(s.lights[0].kind, LightKind::Directional);
        assert!(s.lights[0].shadow);
        assert_eq!(s.lights[0].angular_diameter_deg, 0.53);
        assert_eq!(s.lights[1].angular_diameter_deg, 0.0);
        assert_eq!(s.lights[1].color, [1.0, 1.0, 1.0]);
        assert!(!s.lights[1].shadow);
        assert_eq!(s.skin.kernel, Kernel::Accurate);
        assert_eq!(s.skin.occlusion, Occlusion::Off);
        assert_eq!(s.skin.profile.as_ref().map(Vec::len), Some(2));
        assert_eq!(s.render.gamma, Gamma::Power(2.2));
        assert_eq!(s.render.exposure, Some(-1.5));
        assert_eq!(s.render.tone_curve, ToneCurve::Neutral);
        assert!(!s.render.skybox && s.render.glow);
        assert_eq!(s.render.background, [0.1, 0.2, 0.3]);
        assert_eq!(s.render.glow_intensity, 0.5);
        assert_eq!((s.skin.blur_width, s.skin.blur_amount), (0.5, 0.75));
        assert!(!s.textures.test_texture);

        // Orbit: yaw 30, pitch 10, 600 mm from the centre.
        let centre = Vec3::new(1.0, 2.0, 3.0);
        let (eye, target, up) = s.camera.eye_target_up(centre);
        assert_eq!(target, centre);
        assert_eq!(up, Vec3::Y);
        assert!(((eye - centre).length() - 600.0).abs() < 1e-3);
        let d = (eye - centre) / 600.0;
        assert!((d.y - 10f32.to_radians().sin()).abs() < 1e-6);
        assert!((d.x / d.z - 30f32.to_radians().tan()).abs() < 1e-5);
    }

    #[test]
    fn environment_keywords_are_not_paths() {
        for src in [
            "sky",
            "sky:elevation=30,azimuth=10,turbidity=3",
            "uniform:1,1,1",
        ] {
            let s = parse(&format!("[environment]\nsource = \"{src}\"")).unwrap();
            assert_eq!(s.environment.source, src.parse::<EnvSource>().unwrap());
        }
        let s = parse("[environment]\nsource = \"skylight.hdr\"").unwrap();
        assert_eq!(
            s.environment.source,
            EnvSource::File(PathBuf::from("/scenes/skylight.hdr"))
        );
        let s = parse_scene("mesh = \"a.glb\"", Path::new("scene.toml")).unwrap();
        assert_eq!(s.mesh, Some(PathBuf::from("./a.glb")));
        let s = parse(
            "[environment]\nsource = \"cube:f/px.hdr, nx.hdr,py.hdr,ny.hdr,pz.hdr,/abs/nz.hdr\"",
        )
        .unwrap();
        let EnvSource::Cube(faces) = &s.environment.source else {
            panic!("{:?}", s.environment.source)
        };
        assert_eq!(faces[0], PathBuf::from("/scenes/f/px.hdr"));
        assert_eq!(faces[1], PathBuf::from("/scenes/nx.hdr"));
        assert_eq!(faces[5], PathBuf::from("/abs/nz.hdr"));
    }

    #[test]
    fn bad_environment_sources_name_the_file_and_line() {
        for (src, needle) in [
            (
                "uniform:1,nan,1",
                "environment source 'uniform:1,nan,1': radiance NaN must be finite and >= 0",
            ),
            ("uniform", "expected uniform:R,G,B or uniform:V"),
            ("sky:foo=1", "unknown key 'foo'"),
            ("sky:elevation=95", "sky: elevation 95° is outside [0, 90]"),
            ("cube:a.hdr,b.hdr", "six face files"),
            (" ", "environment.source is empty"),
        ] {
            let msg = err(&format!("[environment]\nsource = \"{src}\""));
            assert!(
                msg.contains("line 2,") && msg.contains(needle),
                "{src}: {msg}"
            );
        }
    }

    #[test]
    fn environment_lights_auto_or_a_count() {
        assert_eq!(parse("").unwrap().environment.lights, LightsMode::Auto);
        for (text, mode) in [
            ("\"auto\"", LightsMode::Auto),
            ("0", LightsMode::Count(0)),
            ("3", LightsMode::Count(3)),
            ("8", LightsMode::Count(8)),
            ("\"2\"", LightsMode::Count(2)),
        ] {
            let s = parse(&format!("[environment]\nlights = {text}")).unwrap();
            assert_eq!(s.environment.lights, mode, "{text}");
        }
        for (text, needle) in [
            ("-1", "got '-1'"),
            ("9", "got '9'"),
            ("\"sometimes\"", "got 'sometimes'"),
            ("\"-2\"", "got '-2'"),
            ("1.5", "floating point `1.5`"),
            ("true", "boolean `true`"),
        ] {
            let msg = err(&format!("[environment]\nlights = {text}"));
            assert!(
                msg.contains("line 2,")
                    && msg.contains("environment.lights")
                    && msg.contains(needle),
                "{text}: {msg}"
            );
        }
        // The same grammar on the command line and in JSON.
        for mode in [LightsMode::Auto, LightsMode::Count(0), LightsMode::Count(5)] {
            assert_eq!(mode.to_string().parse::<LightsMode>(), Ok(mode));
            let json = serde_json::to_string(&mode).unwrap();
            assert_eq!(serde_json::from_str::<LightsMode>(&json).unwrap(), mode);
        }
        assert_eq!(
            serde_json::to_string(&LightsMode::Auto).unwrap(),
            "\"auto\""
        );
        assert_eq!(serde_json::to_string(&LightsMode::Count(3)).unwrap(), "3");
        let e = "-3".parse::<LightsMode>().unwrap_err();
        assert_eq!(
            e,
            "expected \"auto\" or a number of lights in 0..=8, got '-3'"
        );
        assert!("".parse::<LightsMode>().unwrap_err().contains("got ''"));
    }

    #[test]
    fn uv_origin_defaults_to_top_left() {
        assert_eq!(parse("").unwrap().textures.uv_origin, UvOrigin::TopLeft);
        for (text, origin) in [
            ("top-left", UvOrigin::TopLeft),
            ("bottom-left", UvOrigin::BottomLeft),
        ] {
            let s = parse(&format!("[textures]\nuv_origin = \"{text}\"")).unwrap();
            assert_eq!(s.textures.uv_origin, origin);
            assert_eq!(text.parse::<UvOrigin>(), Ok(origin));
        }
        assert!("TopLeft"
            .parse::<UvOrigin>()
            .unwrap_err()
            .contains("top-left or bottom-left"));
    }

    #[test]
    fn camera_look_at() {
        let s = parse("[camera]\nposition = [0, 0, 500]\n").unwrap();
        let (eye, target, up) = s.camera.eye_target_up(Vec3::new(0.0, 10.0, 0.0));
        assert_eq!(eye, Vec3::new(0.0, 0.0, 500.0));
        assert_eq!(target, Vec3::new(0.0, 10.0, 0.0));
        assert_eq!(up, Vec3::Y);
        // Default camera: orbit yaw 0 pitch 0 puts the eye on +Z at 700 mm.
        let (eye, _, _) = Camera::default().eye_target_up(Vec3::ZERO);
        assert!((eye - Vec3::new(0.0, 0.0, 700.0)).length() < 1e-3);
    }

    #[test]
    fn unknown_key_names_key_and_line() {
        let msg = err("[render]\nwidth = 10\n\n[camera]\nfov = 30\n");
        assert!(msg.contains("line 5, column 1"), "{msg}");
        assert!(msg.contains("unknown field `fov`"), "{msg}");
        let msg = err("meshes = \"a.glb\"");
        assert!(msg.contains("line 1") && msg.contains("`meshes`"), "{msg}");
        let msg = err("[skin]\nprofile = [{ variance_mm2 = 1, weights = [1,1,1], extra = 2 }]");
        assert!(msg.contains("line 2") && msg.contains("`extra`"), "{msg}");
        let msg = err("[[lights]]\nkind = \"point\"\nposition = [0,0,0]\ncolour = [1,1,1]");
        assert!(msg.contains("line 4") && msg.contains("`colour`"), "{msg}");
    }

    #[test]
    fn syntax_and_type_errors_have_positions() {
        for (text, line, needle) in [
            ("[render\nwidth = 3", 1, ""),
            ("[render]\nwidth = ", 2, ""),
            ("mesh = \"unterminated", 1, ""),
            ("[render]\nwidth = \"wide\"", 2, "invalid type"),
            ("[render]\nwidth = -5", 2, ""),
            ("[render]\nwidth = 1.5", 2, "invalid type"),
            ("[skin]\nmix = \"half\"", 2, "invalid type"),
            ("[skin]\nkernel = \"box\"", 2, "unknown variant"),
            (
                "[textures]\nuv_origin = \"bottom-right\"",
                2,
                "unknown variant `bottom-right`, expected `top-left` or `bottom-left`",
            ),
            ("[[lights]]\nkind = \"spot\"", 2, "unknown variant"),
            ("[[lights]]\ndirection = [0,0,1]", 1, "missing field `kind`"),
            ("[render]\ngamma = \"s-rgb\"", 2, "srgb"),
            (
                "[render]\ntone_curve = \"sepia\"",
                2,
                "unknown variant `sepia`",
            ),
            ("[render]\nglow = \"yes\"", 2, "invalid type"),
            ("[camera]\nposition = [1, 2]", 2, ""),
            ("lights = 3", 1, "invalid type"),
        ] {
            let msg = err(text);
            assert!(msg.contains(&format!("line {line},")), "{text:?}: {msg}");
            assert!(msg.contains(needle), "{text:?}: {msg}");
        }
    }

    #[test]
    fn out_of_range_values_are_rejected_with_their_key() {
        for (text, needle) in [
            (
                "[render]\nirradiance_resolution = 3000",
                "render.irradiance_resolution = 3000",
            ),
            (
                "[render]\nirradiance_resolution = 128",
                "render.irradiance_resolution = 128",
            ),
            (
                "[render]\nirradiance_resolution = 16384",
                "render.irradiance_resolution",
            ),
            (
                "[render]\nshadow_resolution = 1000",
                "render.shadow_resolution = 1000",
            ),
            ("[render]\nwidth = 0", "render.width = 0"),
            ("[render]\nheight = 16385", "render.height = 16385"),
            ("[render]\nexposure = nan", "render.exposure"),
            ("[render]\ngamma = 0", "render.gamma"),
            ("[skin]\nmix = 1.5", "skin.mix = 1.5"),
            ("[skin]\nmix = -0.1", "skin.mix"),
            ("[skin]\nmix = nan", "skin.mix = NaN"),
            ("[skin]\nblur_width = -1", "skin.blur_width = -1"),
            ("[skin]\nblur_width = 11", "skin.blur_width = 11"),
            ("[skin]\nblur_amount = 1.5", "skin.blur_amount = 1.5"),
            ("[render]\nglow_intensity = -1", "render.glow_intensity = -1"),
            ("[render]\nbackground = [0, 2, 0]", "render.background.g = 2"),
            (
                "[skin]\nprofile = [{ variance_mm2 = 1, weights = [0.5, 1, 1] }]",
                "red weights sum to 0.5",
            ),
            (
                "[skin]\nprofile = [{ variance_mm2 = -1, weights = [1, 1, 1] }]",
                "skin.profile[0].variance_mm2 = -1",
            ),
            (
                "[skin]\nprofile = [{ variance_mm2 = 2, weights = [0.5, 0.5, 0.5] }, \
                 { variance_mm2 = 1, weights = [0.5, 0.5, 0.5] }]",
                "increase strictly",
            ),
            ("[skin]\nprofile = []", "skin.profile is empty"),
            (
                "[skin]\nregions = [{ name = \"a\", rho_s = 0.2, m = 0.3 }]",
                "exactly 10",
            ),
            (
                "[[lights]]\nkind = \"directional\"\ndirection = [0, -1, 0]\nangular_diameter_deg = 50",
                "lights[0].angular_diameter_deg = 50",
            ),
            (
                "[[lights]]\nkind = \"point\"\nposition = [0, 0, 500]\nangular_diameter_deg = 1",
                "only directional lights",
            ),
            ("[camera]\nfov_deg = 1", "camera.fov_deg = 1"),
            ("[camera]\nfov_deg = 179", "camera.fov_deg = 179"),
            ("[camera]\nfov_deg = inf", "camera.fov_deg"),
            ("[camera]\nnear_mm = 100\nfar_mm = 50", "camera.far_mm"),
            ("[camera]\nposition = [0, nan, 0]", "camera.position"),
            (
                "[camera]\nposition = [0, 0, 1]\ntarget = [0, 0, 1]",
                "camera.target",
            ),
            (
                "[camera]\nposition = [0, 0, 1]\nup = [0, 0, 1]\ntarget = [0, 0, 0]",
                "parallel",
            ),
            (
                "[camera]\norbit = { pitch_deg = 90 }",
                "camera.orbit.pitch_deg",
            ),
            (
                "[camera]\norbit = { distance_mm = 0 }",
                "camera.orbit.distance_mm",
            ),
            ("[camera]\norbit = {}\nposition = [1, 1, 1]", "not both"),
            ("[camera]\ntarget = [1, 1, 1]", "need camera.position"),
            (
                "[[lights]]\nkind = \"directional\"",
                "lights[0].direction is required",
            ),
            (
                "[[lights]]\nkind = \"directional\"\ndirection = [0, 0, 0]",
                "lights[0].direction",
            ),
            (
                "[[lights]]\nkind = \"point\"\ndirection = [0, 0, 1]",
                "lights[0].direction",
            ),
            (
                "[[lights]]\nkind = \"point\"\nposition = [0, 0, 1]\nintensity = -1",
                "lights[0].intensity",
            ),
            (
                "[[lights]]\nkind = \"point\"\nposition = [0, 0, 1]\ncolor = [1, nan, 1]",
                "lights[0].color.g",
            ),
            ("mm_per_unit = 0", "mm_per_unit = 0"),
            ("mm_per_unit = -inf", "mm_per_unit"),
            ("[environment]\nintensity = -1", "environment.intensity"),
            (
                "[environment]\nrotation_deg = nan",
                "environment.rotation_deg",
            ),
            ("[environment]\nsource = \"\"", "environment.source"),
        ] {
            let msg = err(text);
            assert!(msg.contains(needle), "{text:?}: {msg}");
        }
        // Ten custom regions are fine; one bad m is not.
        let mut regions = String::from("[skin]\nregions = [\n");
        for i in 0..10 {
            let m = if i == 7 { 0.0 } else { 0.35 };
            regions.push_str(&format!("{{ name = \"r{i}\", rho_s = 0.15, m = {m} }},\n"));
        }
        regions.push(']');
        assert!(err(&regions).contains("skin.regions[7].m"));
        let fixed = parse(&regions.replace("m = 0 }", "m = 0.2 }")).unwrap();
        assert_eq!(fixed.skin.regions.as_ref().unwrap()[7].m, 0.2);
        assert_eq!(fixed.skin.regions.as_ref().unwrap()[9].name, "r9");
    }

    #[test]
    fn missing_file_is_an_io_error() {
        let path = std::env::temp_dir().join("dermis-no-such-dir/none.toml");
        let msg = load_scene(&path).unwrap_err().to_string();
        assert!(
            msg.contains("none.toml") && msg.contains("cannot read"),
            "{msg}"
        );
    }

    #[test]
    fn truncated_files_fail_cleanly() {
        let text = doc_examples().into_iter().last().unwrap();
        let mut rejected = 0;
        for cut in 1..text.len() {
            let Some(prefix) = text.get(..cut) else {
                continue;
            };
            if let Err(e) = parse(prefix) {
                assert!(!e.to_string().contains('\n'));
                rejected += 1;
            }
        }
        // Many prefixes end mid-token; they must all be reported, not panic.
        assert!(rejected > text.len() / 4, "{rejected} of {}", text.len());
    }

    #[test]
    fn doc_examples_parse_and_validate() {
        let examples = doc_examples();
        assert!(
            examples.len() >= 2,
            "docs/scene-format.md has no ```toml examples"
        );
        for (i, text) in examples.iter().enumerate() {
            if let Err(e) = parse(text) {
                panic!("docs example {i} fails: {e}");
            }
        }
    }

    #[test]
    fn lee_perry_smith_example_loads_end_to_end() {
        // The example is a scene file in the repository root, beside assets/.
        let text = doc_examples().into_iter().last().unwrap();
        let scene = parse_scene(&text, &repo_root().join("head.toml")).unwrap();
        assert_eq!(scene.mm_per_unit, Some(50.3));
        let mesh_path = scene.mesh.as_deref().unwrap();
        let mesh = super::super::gltf::load_mesh(mesh_path, scene.mm_per_unit).unwrap();
        assert_eq!(mesh.triangle_count(), 17_684);
        use super::super::texture::{load_texture, Encoding};
        for (p, enc) in [
            (&scene.textures.albedo, Encoding::Srgb),
            (&scene.textures.normal, Encoding::Linear),
            (&scene.textures.specular, Encoding::Linear),
        ] {
            let t = load_texture(p.as_deref().unwrap(), enc).unwrap();
            assert_eq!((t.width, t.height), (1024, 1024));
        }
    }

    #[test]
    fn fuzzed_scene_text_never_panics() {
        let text = doc_examples().into_iter().last().unwrap();
        let bytes = text.as_bytes();
        let mut rng = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            // xorshift64* (Vigna 2016)
            rng ^= rng >> 12;
            rng ^= rng << 25;
            rng ^= rng >> 27;
            rng.wrapping_mul(0x2545_F491_4F6C_DD1D)
        };
        let (mut ok, mut rejected) = (0, 0);
        for i in 0..400 {
            let mut b = bytes.to_vec();
            if i % 2 == 0 {
                b.truncate((next() as usize) % bytes.len());
            } else {
                for _ in 0..1 + next() % 4 {
                    let at = (next() as usize) % b.len();
                    b[at] ^= 1 << (next() % 8);
                }
            }
            let outcome = std::panic::catch_unwind(|| match String::from_utf8(b) {
                Ok(s) => parse(&s).map(|_| ()).map_err(|e| e.to_string()),
                Err(_) => Err("not UTF-8".to_string()),
            });
            match outcome {
                Ok(Ok(())) => ok += 1,
                Ok(Err(msg)) => {
                    assert!(!msg.contains('\n'), "{msg}");
                    rejected += 1
                }
                Err(_) => panic!("scene parser panicked on case {i}"),
            }
        }
        println!("fuzzed scenes: {ok} accepted, {rejected} rejected");
        assert!(rejected > 0 && ok > 0);
    }
}
