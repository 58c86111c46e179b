//! `[skin.medium]`: which medium the skin is, as the scene states it — a preset,
//! explicit coefficients, or the artists' albedo and mean free path. Checked
//! here; turned into coefficients by `skin::medium`.

use serde::{Deserialize, Serialize};

use super::in_range;

/// A named medium.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum MediumPreset {
    /// d'Eon & Luebke's six Gaussians and their transmission (GPU Gems 3
    /// §14.4), the paper's skin: no medium behind it.
    #[default]
    Deon2007,
    /// Jensen et al. 2001, Fig. 5: skin 1.
    JensenSkin1,
    /// Jensen et al. 2001, Fig. 5: skin 2.
    JensenSkin2,
    /// Jensen et al. 2001, Fig. 5: marble.
    JensenMarble,
    /// Jensen et al. 2001, Fig. 5: skim milk.
    JensenSkimmilk,
    /// Jensen et al. 2001, Fig. 5: potato.
    JensenPotato,
    /// Jensen et al. 2001, Fig. 5: apple.
    JensenApple,
    /// Jensen et al. 2001, Fig. 5: ketchup.
    JensenKetchup,
}

/// How `albedo` becomes the single-scattering albedo (skin::medium).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Inversion {
    /// Christensen & Burley 2015's fit to van de Hulst's semi-infinite medium
    /// (what Cycles' random walk uses), index-matched.
    VanDeHulst,
    /// The classical dipole with the boundary's internal reflection (Jensen et
    /// al. 2001; Cycles' "Random Walk (Skin)" and Christensen–Burley).
    Dipole,
}

/// Which rule gives the specular lobe.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SpecularRule {
    /// The medium's rough dielectric boundary: Fresnel of `ior`, the regions'
    /// roughness, no per-region scale.
    Boundary,
    /// The paper's ten face regions' ρs and m (and the specular map).
    Regions,
}

/// `[skin.medium]`. Exactly one of: `preset`; `sigma_a` with `sigma_s_prime`;
/// `albedo` with `mfp` or `dmfp`. Nothing given: `deon2007`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Medium {
    pub preset: Option<MediumPreset>,
    /// Absorption coefficient, mm⁻¹ (R, G, B).
    pub sigma_a: Option<[f32; 3]>,
    /// Reduced scattering coefficient σs(1 − g), mm⁻¹.
    pub sigma_s_prime: Option<[f32; 3]>,
    /// Multiple-scattering (surface) albedo, linear, each in (0, 1).
    pub albedo: Option<[f32; 3]>,
    /// Mean free path 1/σt, mm (with `albedo`).
    pub mfp: Option<[f32; 3]>,
    /// Diffuse mean free path 1/σtr, mm (with `albedo`): what renderers
    /// usually call the scattering radius.
    pub dmfp: Option<[f32; 3]>,
    /// How `albedo` is inverted; default: `van-de-hulst` with `mfp`, `dipole`
    /// with `dmfp`.
    pub inversion: Option<Inversion>,
    /// Henyey–Greenstein anisotropy, (−1, 1); σs = σs′/(1 − g).
    pub g: f32,
    /// Index of refraction of the boundary.
    pub ior: f32,
    /// Default: `boundary` for a medium, `regions` for `deon2007`.
    pub specular: Option<SpecularRule>,
}

impl Default for Medium {
    fn default() -> Self {
        Medium {
            preset: None,
            sigma_a: None,
            sigma_s_prime: None,
            albedo: None,
            mfp: None,
            dmfp: None,
            inversion: None,
            g: 0.0,
            // Skin's stratum corneum, ≈ 1.4 (GPU Gems 3 §14.3; Jensen et al. 2001: 1.3).
            ior: 1.4,
            specular: None,
        }
    }
}

/// Largest index of refraction accepted (diamond's is 2.42).
pub const MAX_IOR: f32 = 3.0;

impl Medium {
    /// No medium: the paper's Gaussians (`deon2007`).
    pub fn is_deon2007(&self) -> bool {
        self.sigma_a.is_none()
            && self.albedo.is_none()
            && matches!(self.preset, None | Some(MediumPreset::Deon2007))
    }

    pub(super) fn validate(&self) -> Result<(), String> {
        let given = [
            self.preset.is_some(),
            self.sigma_a.is_some() || self.sigma_s_prime.is_some(),
            self.albedo.is_some() || self.mfp.is_some() || self.dmfp.is_some(),
        ];
        if given.iter().filter(|&&g| g).count() > 1 {
            return Err(
                "skin.medium: give one of `preset`, `sigma_a` with `sigma_s_prime`, \
                        or `albedo` with `mfp` or `dmfp`, not several"
                    .into(),
            );
        }
        if given[1] {
            let (Some(a), Some(s)) = (self.sigma_a, self.sigma_s_prime) else {
                return Err("skin.medium: `sigma_a` and `sigma_s_prime` go together".into());
            };
            each("skin.medium.sigma_a", a, |v| v >= 0.0, "≥ 0")?;
            each("skin.medium.sigma_s_prime", s, |v| v > 0.0, "> 0")?;
        }
        if given[2] {
            let Some(albedo) = self.albedo else {
                return Err("skin.medium: `mfp` or `dmfp` needs `albedo`".into());
            };
            each(
                "skin.medium.albedo",
                albedo,
                |v| v > 0.0 && v < 1.0,
                "in (0, 1)",
            )?;
            match (self.mfp, self.dmfp) {
                (Some(l), None) | (None, Some(l)) => {
                    let key = if self.mfp.is_some() { "mfp" } else { "dmfp" };
                    each(&format!("skin.medium.{key}"), l, |v| v > 0.0, "> 0 mm")?;
                }
                _ => {
                    return Err(
                        "skin.medium: `albedo` needs exactly one of `mfp` and `dmfp`".into(),
                    )
                }
            }
        } else if self.inversion.is_some() {
            return Err("skin.medium.inversion applies to `albedo` only".into());
        }
        if !(self.g > -1.0 && self.g < 1.0) {
            return Err(format!("skin.medium.g = {}: must be in (-1, 1)", self.g));
        }
        in_range("skin.medium.ior", self.ior, 1.0, MAX_IOR)?;
        if self.is_deon2007() && self.specular == Some(SpecularRule::Boundary) {
            return Err("skin.medium.specular = \"boundary\" needs a medium; \
                        deon2007 has only the regions' specular"
                .into());
        }
        Ok(())
    }
}

fn each(key: &str, v: [f32; 3], ok: impl Fn(f32) -> bool, want: &str) -> Result<(), String> {
    for (c, x) in ["red", "green", "blue"].iter().zip(v) {
        if !(x.is_finite() && ok(x)) {
            return Err(format!("{key} = {v:?}: the {c} value {x} is not {want}"));
        }
    }
    Ok(())
}
