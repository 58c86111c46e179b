//! What a render writes: the final image or one intermediate (the paper's debug
//! views).

use crate::error::{Error, Result};
use crate::light::prefilter;

/// What `render` writes: the final image or one intermediate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// The final image: texture-space diffusion (+ specular when it lands).
    Final,
    /// The diffuse (subsurface) term alone.
    Diffuse,
    /// The Kelemen/Szirmay-Kalos specular term alone (the paper's Fig. 1).
    Specular,
    /// Direct diffuse shading in screen space, no scattering (for comparison).
    Direct,
    /// The per-vertex transfer's DC term relative to open sky (1 = unoccluded).
    Occlusion,
    /// UV-space irradiance (coverage-premultiplied, as stored).
    Irradiance,
    /// UV-space stretch map (texels per mm in R and G; alpha = coverage).
    Stretch,
    /// UV-space blur level 1..=6 (as stored).
    Blur(u8),
    /// The KS-prefiltered environment: its roughness levels stacked top to bottom
    /// (light::prefilter).
    Prefiltered,
}

impl View {
    pub fn parse(s: &str) -> Result<View> {
        Ok(match s {
            "final" => View::Final,
            "diffuse" => View::Diffuse,
            "specular" => View::Specular,
            "direct" => View::Direct,
            "occlusion" => View::Occlusion,
            "irradiance" => View::Irradiance,
            "stretch" => View::Stretch,
            "prefiltered" => View::Prefiltered,
            _ => match s.strip_prefix("blur").and_then(|k| k.parse::<u8>().ok()) {
                Some(k @ 1..=6) => View::Blur(k),
                _ => {
                    return Err(Error::Input(format!(
                    "unknown view {s:?}: final, diffuse, specular, direct, occlusion, irradiance, stretch, blur1..blur6, prefiltered"
                )))
                }
            },
        })
    }

    /// The name [`View::parse`] reads.
    pub fn name(self) -> String {
        match self {
            View::Final => "final".into(),
            View::Diffuse => "diffuse".into(),
            View::Specular => "specular".into(),
            View::Direct => "direct".into(),
            View::Occlusion => "occlusion".into(),
            View::Irradiance => "irradiance".into(),
            View::Stretch => "stretch".into(),
            View::Blur(k) => format!("blur{k}"),
            View::Prefiltered => "prefiltered".into(),
        }
    }

    /// Whether the view is an intermediate texture rather than a screen image:
    /// read back as stored, without tone mapping.
    pub fn uv_space(self) -> bool {
        matches!(
            self,
            View::Irradiance | View::Stretch | View::Blur(_) | View::Prefiltered
        )
    }

    /// The size of the image the view reads back.
    pub(super) fn size(self, screen: (u32, u32), irradiance_resolution: u32) -> (u32, u32) {
        match self {
            View::Prefiltered => (prefilter::WIDTH, prefilter::HEIGHT * prefilter::LEVELS),
            v if v.uv_space() => (irradiance_resolution, irradiance_resolution),
            _ => screen,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back() {
        let all = [
            "final",
            "diffuse",
            "specular",
            "direct",
            "occlusion",
            "irradiance",
        ]
        .into_iter()
        .chain(["stretch", "blur1", "blur6", "prefiltered"]);
        for name in all {
            assert_eq!(View::parse(name).unwrap().name(), name);
        }
    }
}
