//! `[skin]`: kernel, chain, occlusion, interreflection, profile, regions, blur, transmission.

use serde::{Deserialize, Serialize};

use super::medium::Medium;
use super::{in_range, non_negative, positive};

/// Blur kernel for the Gaussian chain.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Kernel {
    /// d'Eon's 7 taps at -3σ..3σ (GPU Gems 3 §14.5; weights in docs/design/skin.md, "Blur kernels").
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
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, clap::ValueEnum)]
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
    /// Light the skin reflects onto itself (Sloan et al. 2002's interreflected
    /// transfer, light::interreflection), with every occlusion but `off`.
    pub interreflection: bool,
    /// Correct blur widths for UV distortion with the stretch map (the paper's
    /// section II.B); off: one texels-per-mm constant for the whole mesh.
    pub stretch_correction: bool,
    /// Blur along the surface metric of the UVs, not only their scale: the V
    /// pass steps along the surface perpendicular of ∂P/∂u (docs/records/2026-11-26-shear-aware-diffusion.md,
    /// "Shear-aware diffusion"); off: along v, as if the UV axes met at right
    /// angles on the surface.
    pub shear_correction: bool,
    /// Add, per blurred level, the light the texture-space chain cannot carry
    /// where the skin comes back within the profile's reach through the tissue
    /// (seams, squeezed UVs, folds), precomputed per mesh (skin::fold); off:
    /// the chain alone.
    pub fold_correction: bool,
    /// Scale on every variance of the profile (the paper's "blurring width";
    /// 0: no blur).
    pub blur_width: f32,
    /// Share of the blurred irradiance in the diffuse term, the rest unblurred
    /// (the paper's "blurring amount"; 0: unblurred).
    pub blur_amount: f32,
    /// Scale on the light transmitted through thin skin from shadowed lights
    /// behind it (translucent shadow maps, docs/records/2026-11-26-transmission.md "Transmission"; ≥ 0,
    /// 0: off).
    pub transmission: f32,
    /// The medium the profile, the transmission and the specular follow
    /// (`[skin.medium]`; default `deon2007`, no medium).
    pub medium: Medium,
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
            interreflection: true,
            stretch_correction: true,
            shear_correction: true,
            fold_correction: false,
            blur_width: 1.0,
            blur_amount: 1.0,
            transmission: 1.0,
            medium: Medium::default(),
        }
    }
}

/// Largest `skin.blur_width`: ten times the variances is σ₆ ≈ 8.6 mm, a blur
/// across the whole cheek.
pub const MAX_BLUR_WIDTH: f32 = 10.0;

/// Allowed deviation of each channel's profile weight sum from 1.
pub const PROFILE_SUM_TOLERANCE: f32 = 0.01;

impl Skin {
    pub(super) fn validate(&self) -> Result<(), String> {
        in_range("skin.mix", self.mix, 0.0, 1.0)?;
        in_range("skin.blur_width", self.blur_width, 0.0, MAX_BLUR_WIDTH)?;
        in_range("skin.blur_amount", self.blur_amount, 0.0, 1.0)?;
        non_negative("skin.transmission", self.transmission)?;
        if let Some(profile) = &self.profile {
            validate_profile(profile)?;
            if !self.medium.is_deon2007() {
                return Err(
                    "skin.profile and a skin.medium other than deon2007 both give \
                            the profile: keep one"
                        .into(),
                );
            }
        }
        self.medium.validate()?;
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
