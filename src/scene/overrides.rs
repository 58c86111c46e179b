//! The command-line flags that replace scene-file keys. One table entry per flag
//! gives its help, clap attributes, type, the key it replaces and an example
//! value; [`Overrides`], its `apply` and [`Overrides::KEYS`] follow from it
//! (docs/design/architecture.md, "Adding a CLI flag for a scene key").

use std::path::PathBuf;

use super::env::EnvSource;
use super::file::{
    self, parse_env_source, Chain, IrradianceShading, Kernel, LightsMode, MediumPreset, Occlusion,
    SceneFile, ToneCurve, UvOrigin,
};
use crate::error::Result;

/// `--scene`, for every command that reads a scene.
#[derive(Clone, Debug, Default, clap::Args)]
pub struct SceneArg {
    /// Scene file (docs/reference/scene-format.md), or `builtin` for the built-in
    /// procedural head under the sky; default: assets/default.toml, looked for
    /// in $DERMIS_ASSETS, ./assets, then beside the executable (docs/reference/command-line.md, "Assets").
    #[arg(long)]
    pub scene: Option<PathBuf>,
}

impl SceneArg {
    /// The scene file it names ([`file::scene_by_name`]).
    pub fn file(&self) -> Result<SceneFile> {
        Ok(file::scene_by_name(self.scene.as_deref())?)
    }

    /// The scene it names, with `overrides` applied.
    pub fn load(&self, overrides: &Overrides) -> Result<SceneFile> {
        overrides.apply(self.file()?)
    }

    /// The scene file it names (the default scene's when none).
    pub fn path(&self) -> Result<PathBuf> {
        match &self.scene {
            Some(p) => Ok(p.clone()),
            None => Ok(file::default_scene_path()?),
        }
    }
}

/// A flag of [`Overrides`] and the scene key it replaces.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OverrideKey {
    /// The field, e.g. `irradiance_res` (the flag `--irradiance-res`).
    pub field: &'static str,
    /// The dotted scene key, e.g. `render.irradiance_resolution`.
    pub key: &'static str,
    /// A value other than the default's, for the tests.
    pub example: &'static str,
}

impl OverrideKey {
    /// `--irradiance-res`.
    pub fn flag(&self) -> String {
        format!("--{}", self.field.replace('_', "-"))
    }
}

/// `field: Type => scene.key, example "value";` after the flag's doc comment and
/// `#[arg(...)]` attributes (`long` is added).
macro_rules! overrides {
    ($(
        $(#[$attr:meta])*
        $field:ident: $ty:ty => $($key:ident).+, example $example:literal;
    )*) => {
        /// Flags that replace scene-file keys, each `None` when not given.
        #[derive(Clone, Debug, Default, clap::Args)]
        pub struct Overrides {
            $(
                $(#[$attr])*
                #[arg(long)]
                pub $field: Option<$ty>,
            )*
        }

        impl Overrides {
            /// Every flag with its scene key, in declaration order.
            pub const KEYS: &'static [OverrideKey] = &[$(OverrideKey {
                field: stringify!($field),
                key: stringify!($($key).+),
                example: $example,
            }),*];

            /// Sets the key of every flag given.
            fn set_keys(self, file: &mut SceneFile) {
                $(if let Some(v) = self.$field {
                    set(&mut file.$($key).+, v);
                })*
            }

            /// The flags given, by field, with their values as TOML.
            #[cfg(test)]
            fn given(&self) -> Vec<(&'static str, toml::Value)> {
                let mut given = Vec::new();
                $(if let Some(v) = &self.$field {
                    given.push((stringify!($field), toml::Value::try_from(v).unwrap()));
                })*
                given
            }
        }
    };
}

overrides! {
    /// glTF mesh (.glb/.gltf), replacing the scene's.
    mesh: PathBuf => mesh, example "/scans/head.glb";
    /// Millimetres per mesh unit (e.g. 50.3 for the Lee Perry-Smith scan).
    mm_per_unit: f32 => mm_per_unit, example "50.3";
    /// Environment: a .hdr/.exr file, `sky[:elevation=..,azimuth=..,turbidity=..]`
    /// or `uniform:R,G,B`.
    #[arg(value_parser = parse_env_source)]
    env: EnvSource => environment.source, example "uniform:1,0.5,0.25";
    /// Environment rotation about +Y, degrees.
    #[arg(allow_hyphen_values = true)]
    env_rotate: f32 => environment.rotation_deg, example "-90";
    /// Bright sources taken out of the environment as shadowed directional
    /// lights, replacing the scene's `environment.lights`: `auto` (compact
    /// sources holding ≥ 5 % of the energy) or a count 0..=8 (0: none).
    #[arg(value_name = "auto|N", allow_hyphen_values = true)]
    env_lights: LightsMode => environment.lights, example "2";
    /// Exposure in EV stops, replacing `render.exposure`; without either it is
    /// metered from the frame (the skin's log-average luminance to 0.18).
    #[arg(allow_hyphen_values = true)]
    exposure: f32 => render.exposure, example "-1.5";
    /// Tone curve, replacing `render.tone_curve`: `linear` (clip), `aces`
    /// (Narkowicz's ACES fit) or `neutral` (Khronos PBR Neutral).
    #[arg(value_enum)]
    tone_curve: ToneCurve => render.tone_curve, example "aces";
    /// Glow (d'Eon & Luebke's two-Gaussian bloom), replacing `render.glow`.
    #[arg(value_name = "on|off", hide_possible_values = true, value_parser = on_off())]
    glow: bool => render.glow, example "on";
    /// Glow intensity (≥ 0), replacing `render.glow_intensity`.
    #[arg(allow_hyphen_values = true)]
    glow_intensity: f32 => render.glow_intensity, example "2";
    /// Draw the environment behind the head, replacing `render.skybox`.
    #[arg(value_name = "on|off", hide_possible_values = true, value_parser = on_off())]
    skybox: bool => render.skybox, example "off";
    /// Display colour (linear, each in [0, 1]) where the skybox is off and
    /// the mesh does not cover, replacing `render.background`.
    #[arg(value_name = "R,G,B", value_parser = parse_rgb)]
    background: [f32; 3] => render.background, example "0.25,0.5,1";
    /// Scale on the profile's six variances (the paper's blurring width; 0:
    /// no blur), replacing `skin.blur_width`.
    #[arg(allow_hyphen_values = true)]
    blur_width: f32 => skin.blur_width, example "0.5";
    /// Share of the blurred irradiance in the diffuse term, 0..1 (the
    /// paper's blurring amount; 0: unblurred), replacing `skin.blur_amount`.
    #[arg(allow_hyphen_values = true)]
    blur_amount: f32 => skin.blur_amount, example "0.25";
    /// Scale (≥ 0) on the light transmitted through thin skin (ears, nostrils)
    /// from shadowed lights behind it; 0: off. Replaces `skin.transmission`.
    #[arg(allow_hyphen_values = true)]
    transmission: f32 => skin.transmission, example "0.5";
    /// The skin's medium, replacing `skin.medium.preset`: `deon2007` (the
    /// paper's Gaussians) or one of Jensen et al. 2001's measured media, from
    /// which the profile, the transmission and the specular follow
    /// (docs/design/media.md).
    #[arg(value_enum)]
    medium: MediumPreset => skin.medium.preset, example "jensen-skin1";
    /// Blur along the surface metric of the UVs, shear included (off: along u
    /// and v, their scale only), replacing `skin.shear_correction`.
    #[arg(value_name = "on|off", hide_possible_values = true, value_parser = on_off())]
    shear_correction: bool => skin.shear_correction, example "off";
    /// Correct the blur levels where the skin folds or a UV seam cuts it
    /// (a precomputed 3-D term), replacing `skin.fold_correction`.
    #[arg(value_name = "on|off", hide_possible_values = true, value_parser = on_off())]
    fold_correction: bool => skin.fold_correction, example "on";
    /// The numbered UV checker as the albedo, replacing `textures.test_texture`.
    #[arg(value_name = "on|off", hide_possible_values = true, value_parser = on_off())]
    test_texture: bool => textures.test_texture, example "on";
    /// A second shadow map per shadowed light, fitted to what the camera sees
    /// (finer where the face is), replacing `render.shadow_focus`.
    #[arg(value_name = "on|off", hide_possible_values = true, value_parser = on_off())]
    shadow_focus: bool => render.shadow_focus, example "off";
    /// Side of the UV-space irradiance texture (power of two, 256..8192).
    irradiance_res: u32 => render.irradiance_resolution, example "512";
    /// How the irradiance pass reaches the texels, replacing
    /// `render.irradiance_shading`: `raster` (the mesh by its UVs every frame),
    /// `compute` (a pass over a texel map drawn once per render) or `auto`
    /// (raster on a CPU device, compute on a GPU).
    #[arg(value_enum)]
    irradiance_shading: IrradianceShading => render.irradiance_shading, example "compute";
    /// Per-vertex occlusion (default: the scene's, raytrace).
    #[arg(value_enum)]
    occlusion: Occlusion => skin.occlusion, example "raster";
    /// Light the skin reflects onto itself (interreflected transfer), replacing
    /// `skin.interreflection`.
    #[arg(value_name = "on|off", hide_possible_values = true, value_parser = on_off())]
    interreflection: bool => skin.interreflection, example "off";
    /// Blur kernel of the diffusion chain, replacing the scene's `skin.kernel`.
    #[arg(value_enum)]
    kernel: Kernel => skin.kernel, example "accurate";
    /// Resolutions of the diffusion chain, replacing the scene's `skin.chain`:
    /// `full` blurs every level at the irradiance resolution, `adaptive` each at
    /// the coarsest resolution its Gaussian allows.
    #[arg(value_enum)]
    chain: Chain => skin.chain, example "full";
    /// The maps' UV origin, replacing the scene's (bottom-left: flipped on load).
    #[arg(value_enum)]
    uv_origin: UvOrigin => textures.uv_origin, example "bottom-left";
    /// Output width in pixels, replacing the scene's.
    width: u32 => render.width, example "640";
    /// Output height in pixels, replacing the scene's.
    height: u32 => render.height, example "480";
}

impl Overrides {
    /// Applies the flags given and re-validates the result.
    pub fn apply(&self, mut file: SceneFile) -> Result<SceneFile> {
        self.clone().set_keys(&mut file);
        file.validate()
            .map_err(|m| crate::Error::Input(format!("command line: {m}")))?;
        Ok(file)
    }
}

/// A key set from its flag's value (`T` or `Option<T>`).
fn set<T, U: From<T>>(key: &mut U, value: T) {
    *key = U::from(value);
}

/// `on|off` (and the other spellings clap reads as a boolean).
fn on_off() -> clap::builder::BoolishValueParser {
    clap::builder::BoolishValueParser::new()
}

/// `--background R,G,B`.
fn parse_rgb(s: &str) -> std::result::Result<[f32; 3], String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|c| c.trim().parse::<f32>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|e| format!("{s:?}: {e}"))?;
    v.try_into()
        .map_err(|_| format!("{s:?}: expected three numbers R,G,B"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::{CommandFactory, Parser};

    /// A command line of the overrides alone.
    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        overrides: Overrides,
    }

    /// `[a.b] c = value` for the key `a.b.c`.
    fn toml_at(key: &str, value: toml::Value) -> String {
        let doc = key.rsplit('.').fold(value, |v, part| {
            toml::Value::Table(toml::map::Map::from_iter([(part.to_string(), v)]))
        });
        toml::to_string(&doc).unwrap()
    }

    /// Every flag, given its example, changes its key and only its key: the
    /// result is the scene file that sets that key to the same value.
    #[test]
    fn every_flag_reaches_its_scene_key() {
        let default = SceneFile::default();
        for k in Overrides::KEYS {
            let flag = k.flag();
            let cli = Cli::try_parse_from(["dermis", &flag, k.example])
                .unwrap_or_else(|e| panic!("{flag} {}: {e}", k.example));
            let given = cli.overrides.given();
            assert_eq!(given.len(), 1, "{flag}: {given:?}");
            assert_eq!(given[0].0, k.field, "{flag}");
            let applied = cli.overrides.apply(default.clone()).unwrap();
            assert_ne!(applied, default, "{flag} {}: changed nothing", k.example);
            let text = toml_at(k.key, given[0].1.clone());
            let expected: SceneFile = toml::from_str(&text)
                .unwrap_or_else(|e| panic!("{flag}: {text:?} is no scene file: {e}"));
            assert_eq!(applied, expected, "{flag} should set {text:?}");
        }
    }

    #[test]
    fn keys_name_each_flag_and_key_once() {
        let command = Cli::command();
        let longs: Vec<&str> = command
            .get_arguments()
            .filter_map(|a| a.get_long())
            .filter(|l| *l != "help")
            .collect();
        assert_eq!(longs.len(), Overrides::KEYS.len());
        for k in Overrides::KEYS {
            assert!(longs.contains(&&k.flag()[2..]), "{}", k.flag());
            assert_eq!(k.key, k.key.replace(' ', ""), "{}", k.key);
            let same = Overrides::KEYS.iter().filter(|o| o.key == k.key).count();
            assert_eq!(same, 1, "{} is replaced by {same} flags", k.key);
        }
    }

    #[test]
    fn bad_values_name_the_key_or_the_flag() {
        let empty = Cli::try_parse_from(["dermis", "--env", " "]).err().unwrap();
        assert!(
            empty.to_string().contains(file::EMPTY_ENV_SOURCE),
            "{empty}"
        );
        let cli = Cli::try_parse_from(["dermis", "--width", "0"]).unwrap();
        let e = cli.overrides.apply(SceneFile::default()).unwrap_err();
        assert!(e.to_string().contains("command line: render.width"), "{e}");
    }
}
