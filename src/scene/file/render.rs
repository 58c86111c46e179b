//! `[render]`: sizes, resolutions, exposure, tone curve, background, glow.

use std::fmt;

use serde::{Deserialize, Deserializer, Serialize};

use super::{finite, in_range, non_negative};

/// The tone curve from exposed radiance to display values in [0, 1]
/// (post::tonemap, docs/design/post.md).
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

/// How the irradiance pass reaches the texels of the UV layout
/// (skin::irradiance; docs/records/2026-11-27-compute-irradiance.md, "The irradiance pass in compute").
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum IrradianceShading {
    /// `raster` on a CPU device (lavapipe), `compute` on a GPU: the faster of
    /// the two where each was measured.
    Auto,
    /// The mesh rasterised by its UVs every frame.
    Raster,
    /// A compute pass over a texel map rasterised once per render.
    Compute,
}

impl IrradianceShading {
    /// Whether the compute pass runs, on a CPU device or not.
    pub fn compute(self, cpu_device: bool) -> bool {
        match self {
            IrradianceShading::Auto => !cpu_device,
            IrradianceShading::Raster => false,
            IrradianceShading::Compute => true,
        }
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
    /// A second map per shadowed light, fitted to what the camera sees
    /// (light::shadow::Focus).
    pub shadow_focus: bool,
    /// How the irradiance pass reaches the texels (skin::irradiance).
    pub irradiance_shading: IrradianceShading,
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
            shadow_focus: true,
            irradiance_shading: IrradianceShading::Auto,
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

impl Render {
    pub(super) fn validate(&self) -> Result<(), String> {
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
            // Its range depends on the scene's light (scene::range).
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
