//! What a render writes: the final image or one intermediate (the paper's debug
//! views).

use crate::error::{Error, Result};

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
    /// The same quantity integrated on the CPU by Monte Carlo against the full
    /// environment map with ray-cast visibility (light::reference): slow, offline.
    Reference,
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
    /// Every view, in the order `--help` lists them.
    pub const ALL: [View; 15] = [
        View::Final,
        View::Diffuse,
        View::Specular,
        View::Direct,
        View::Reference,
        View::Occlusion,
        View::Irradiance,
        View::Stretch,
        View::Blur(1),
        View::Blur(2),
        View::Blur(3),
        View::Blur(4),
        View::Blur(5),
        View::Blur(6),
        View::Prefiltered,
    ];

    /// The command-line name: `final`, …, `blur1`…`blur6`, `prefiltered`.
    pub fn name(self) -> &'static str {
        match self {
            View::Final => "final",
            View::Diffuse => "diffuse",
            View::Specular => "specular",
            View::Direct => "direct",
            View::Reference => "reference",
            View::Occlusion => "occlusion",
            View::Irradiance => "irradiance",
            View::Stretch => "stretch",
            View::Blur(k) => {
                ["blur1", "blur2", "blur3", "blur4", "blur5", "blur6"][(k.clamp(1, 6) - 1) as usize]
            }
            View::Prefiltered => "prefiltered",
        }
    }

    pub fn parse(s: &str) -> Result<View> {
        Self::ALL
            .into_iter()
            .find(|v| v.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Self::ALL.iter().map(|v| v.name()).collect();
                Error::Input(format!("unknown view {s:?}: {}", names.join(", ")))
            })
    }

    /// Whether the view is an intermediate texture rather than a screen image:
    /// read back as stored, without tone mapping.
    pub fn uv_space(self) -> bool {
        matches!(
            self,
            View::Irradiance | View::Stretch | View::Blur(_) | View::Prefiltered
        )
    }
}

impl clap::ValueEnum for View {
    fn value_variants<'a>() -> &'a [Self] {
        &Self::ALL
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.name()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for v in View::ALL {
            assert_eq!(View::parse(v.name()).unwrap(), v);
        }
        assert_eq!(View::parse("blur4").unwrap(), View::Blur(4));
        let e = View::parse("blur7").unwrap_err().to_string();
        assert!(e.contains("blur6") && e.contains("prefiltered"), "{e}");
    }
}
