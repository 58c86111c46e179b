//! `[environment]`: the source, its rotation and intensity, the lights taken
//! out of it.

use std::fmt;

use serde::{Deserialize, Deserializer, Serialize};

use super::{finite, non_negative};
use crate::scene::env::{EnvError, EnvSource, SkyParams};

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
/// shadow map per frame, and the CC0 maps need at most 4 (docs/design/lighting.md).
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
pub const EMPTY_ENV_SOURCE: &str =
    "environment.source is empty: use \"sky\", \"uniform:R,G,B\" or a file path";

/// An environment source as the scene file and the command line (`--env`, the
/// `ENV` of `sh` and `lights`) read it: not empty, then `EnvSource`'s grammar.
pub fn parse_env_source(s: &str) -> Result<EnvSource, String> {
    if s.trim().is_empty() {
        return Err(EMPTY_ENV_SOURCE.into());
    }
    s.parse().map_err(|e: EnvError| e.to_string())
}

/// `environment.source`, by [`parse_env_source`].
fn env_source<'de, D: Deserializer<'de>>(d: D) -> Result<EnvSource, D::Error> {
    parse_env_source(&String::deserialize(d)?).map_err(serde::de::Error::custom)
}

impl Environment {
    pub(super) fn validate(&self) -> Result<(), String> {
        finite("environment.rotation_deg", self.rotation_deg)?;
        non_negative("environment.intensity", self.intensity)
    }
}
