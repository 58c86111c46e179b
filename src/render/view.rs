//! What a render writes: the final image or one intermediate (the paper's debug
//! views).

use crate::error::{Error, Result};

/// What `render` writes: the final image or one intermediate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// The final image: texture-space diffusion and specular.
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
    /// Linear depth over the mesh's bounding sphere (post::debug).
    Depth,
    /// The shading normal after the normal map, world space, 0.5·n + 0.5.
    Normals,
    /// The albedo map on the mesh.
    Albedo,
    /// The face-region ids in distinct colours.
    Regions,
    /// The final image with the numbered UV checker as the albedo (scene::checker).
    TestTexture,
    /// UV-space irradiance (coverage-premultiplied, as stored).
    Irradiance,
    /// UV-space stretch level 0 (unblurred) ..= 5 (texels per mm in R and G;
    /// alpha = coverage).
    Stretch(u8),
    /// UV-space blur level 1..=6 (as stored).
    Blur(u8),
    /// The KS-prefiltered environment: its roughness levels stacked top to bottom
    /// (light::prefilter).
    Prefiltered,
}

/// How a view's image becomes display values (render/: post::Display).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shown {
    /// Radiance: glow, the exposure (given or metered), the scene's tone curve
    /// and transfer function.
    Exposed,
    /// A fraction in [0, 1] (occlusion, albedo): exposure 0, no curve, the
    /// scene's transfer function.
    Fraction,
    /// Data (depth, normals, region colours): the values as they are.
    Data,
}

const STRETCH: [&str; 6] = [
    "stretch", "stretch1", "stretch2", "stretch3", "stretch4", "stretch5",
];
const BLUR: [&str; 6] = ["blur1", "blur2", "blur3", "blur4", "blur5", "blur6"];

impl View {
    /// Every view, in the order `--help` lists them.
    pub const ALL: [View; 25] = [
        View::Final,
        View::Diffuse,
        View::Specular,
        View::Direct,
        View::Reference,
        View::Occlusion,
        View::Depth,
        View::Normals,
        View::Albedo,
        View::Regions,
        View::TestTexture,
        View::Irradiance,
        View::Stretch(0),
        View::Stretch(1),
        View::Stretch(2),
        View::Stretch(3),
        View::Stretch(4),
        View::Stretch(5),
        View::Blur(1),
        View::Blur(2),
        View::Blur(3),
        View::Blur(4),
        View::Blur(5),
        View::Blur(6),
        View::Prefiltered,
    ];

    /// The command-line name: `final`, …, `stretch`, `stretch1`…`stretch5`,
    /// `blur1`…`blur6`, `prefiltered`.
    pub fn name(self) -> &'static str {
        match self {
            View::Final => "final",
            View::Diffuse => "diffuse",
            View::Specular => "specular",
            View::Direct => "direct",
            View::Reference => "reference",
            View::Occlusion => "occlusion",
            View::Depth => "depth",
            View::Normals => "normals",
            View::Albedo => "albedo",
            View::Regions => "regions",
            View::TestTexture => "test-texture",
            View::Irradiance => "irradiance",
            View::Stretch(k) => STRETCH[k.min(5) as usize],
            View::Blur(k) => BLUR[(k.clamp(1, 6) - 1) as usize],
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
            View::Irradiance | View::Stretch(_) | View::Blur(_) | View::Prefiltered
        )
    }

    /// How the view is shown.
    pub fn shown(self) -> Shown {
        match self {
            View::Occlusion | View::Albedo => Shown::Fraction,
            View::Depth | View::Normals | View::Regions => Shown::Data,
            _ => Shown::Exposed,
        }
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
        assert_eq!(View::parse("stretch").unwrap(), View::Stretch(0));
        assert_eq!(View::parse("stretch5").unwrap(), View::Stretch(5));
        let e = View::parse("blur7").unwrap_err().to_string();
        assert!(e.contains("blur6") && e.contains("prefiltered"), "{e}");
        assert!(View::parse("stretch6").is_err());
    }
}
