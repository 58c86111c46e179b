//! The resolution of every level of the diffusion chain. `full` blurs all six
//! Gaussians at the irradiance resolution (GPU Gems 3 §14.5). `adaptive` stores
//! each level at the coarsest power of two at which its total width still spans
//! [`MIN_SIGMA_TEXELS`] texels, downsampling as it blurs (the Gaussian is the
//! low-pass filter), and takes the unblurred irradiance for a first Gaussian
//! narrower than [`SKIP_SIGMA_TEXELS`] (d'Eon & Luebke §14.5 suggest it for the
//! first term). docs/design/cost-model.md shows what it costs and how far it is off.
//! Either way a level whose blur spans at most [`Stencil::Five`]'s σ in texels
//! of its source's resolution is blurred in one pass instead of two;
//! so is a level that halves its source's side, with the 5×5 stencil, where
//! its σ spans at most that in texels of its own resolution beyond the 2×2 box
//! its centre tap reads.

use super::profile::Profile;
use crate::scene::file::Chain;

/// Smallest total σ, in texels of its own resolution at the mesh's mean stretch,
/// a level after the first is stored with: a Gaussian narrower than a texel is
/// not reconstructed by bilinear lookups (the impulse-response test of
/// tests/it/skin_diffusion.rs fails from about 0.7;
/// docs/records/2026-11-29-adaptive-chain-one-texel.md).
pub const MIN_SIGMA_TEXELS: f32 = 1.0;
/// A first increment narrower than this (texels at the irradiance resolution) is
/// not blurred: the level is the irradiance itself.
pub const SKIP_SIGMA_TEXELS: f32 = 2.0;
/// The coarsest level the adaptive chain goes down to.
pub const MIN_RESOLUTION: u32 = 64;
/// Variance per axis, in texels² of a level that halves its source's side,
/// of a bilinear tap at a texel centre of the level: the 2×2 box of the source
/// texels it covers (blur_narrow.comp's BOX).
pub const HALF_BOX_TEXELS2: f32 = 1.0 / 16.0;
/// The texel neighbourhood of a level blurred in one pass (blur_narrow.comp),
/// both directions at once, from a source of its own resolution (or, the 5×5
/// only, of twice it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stencil {
    /// 3×3, four bilinear taps: per axis the tent m/2, 1 − m, m/2 of variance
    /// m = σ², highest at the centre up to m = 2/3.
    Three,
    /// 5×5, nine bilinear taps: per axis weights at 0, ±1, ±2 texels in the
    /// Gaussian's ratio up to m ≈ 1.05, above it (the stretch above the mean)
    /// three equal weights per axis, the sides where they hold m.
    Five,
}

impl Stencil {
    /// The largest σ increment, in texels at the mesh's mean stretch, this
    /// stencil is used for (below the limits above, leaving room for a stretch
    /// above the mean).
    pub fn max_sigma_texels(self) -> f32 {
        match self {
            Stencil::Three => 0.8,
            Stencil::Five => 1.2,
        }
    }

    /// The smallest stencil for a blur of `sigma_texels` (at the level's
    /// resolution) from a source of the same side, or only the 5×5 from one
    /// of twice the side (`halves`: blur_narrow.comp's HALF, whose centre tap,
    /// a 2×2 box of the source, holds [`HALF_BOX_TEXELS2`] of the variance
    /// and the stencil the rest); `None`: two passes.
    fn for_sigma(sigma_texels: f32, halves: bool) -> Option<Self> {
        if halves {
            let stencil = (sigma_texels * sigma_texels - HALF_BOX_TEXELS2)
                .max(0.0)
                .sqrt();
            return (stencil <= Stencil::Five.max_sigma_texels()).then_some(Stencil::Five);
        }
        [Stencil::Three, Stencil::Five]
            .into_iter()
            .find(|s| sigma_texels <= s.max_sigma_texels())
    }
}

/// One level of the chain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Level {
    /// Side of the level's image.
    pub resolution: u32,
    /// σ (mm) of the blur from the previous level's image to this one; `None`:
    /// the level is the previous image, unblurred (an adaptive first level under
    /// [`SKIP_SIGMA_TEXELS`], or any level of a profile scaled to zero width).
    pub sigma_mm: Option<f32>,
    /// The blur is narrow and keeps the previous image's resolution or halves
    /// it: one pass, both directions, over this stencil (skin::blur); `None`:
    /// U then V.
    pub one_pass: Option<Stencil>,
}

/// Plans the six levels. `texels_per_mm`: the stretch the adaptive choice is made
/// for at `resolution` (skin::mean_stretch).
pub fn plan(profile: &Profile, chain: Chain, resolution: u32, texels_per_mm: f32) -> Vec<Level> {
    let mut levels = Vec::new();
    let (mut previous_variance, mut previous_resolution) = (0.0f32, resolution);
    for (k, g) in profile.gaussians.iter().enumerate() {
        let increment = (g.variance_mm2 - previous_variance).max(0.0).sqrt();
        let (side, sigma_mm) = match chain {
            // `skin.blur_width = 0`: every level is the irradiance.
            _ if increment == 0.0 => (previous_resolution, None),
            Chain::Full => (resolution, Some(increment)),
            // The first, narrowest level keeps the full resolution (d'Eon & Luebke
            // §14.5): the irradiance itself when its blur is under SKIP_SIGMA_TEXELS.
            Chain::Adaptive if k == 0 => (
                resolution,
                (increment * texels_per_mm >= SKIP_SIGMA_TEXELS).then_some(increment),
            ),
            Chain::Adaptive => {
                let sigma = g.variance_mm2.sqrt();
                let mut r = previous_resolution;
                while r / 2 >= MIN_RESOLUTION
                    && sigma * texels_per_mm * (r / 2) as f32 / resolution as f32
                        >= MIN_SIGMA_TEXELS
                {
                    r /= 2;
                }
                (r, Some(increment))
            }
        };
        let texels = |sigma: f32| sigma * texels_per_mm * side as f32 / resolution as f32;
        let level = Level {
            resolution: side,
            sigma_mm,
            one_pass: sigma_mm
                .filter(|_| side == previous_resolution || 2 * side == previous_resolution)
                .and_then(|s| Stencil::for_sigma(texels(s), side < previous_resolution)),
        };
        if level.sigma_mm.is_some() {
            previous_variance = g.variance_mm2;
        }
        previous_resolution = level.resolution;
        levels.push(level);
    }
    levels
}

/// How many leading levels are the unblurred irradiance itself (no blur before
/// them): the final pass evaluates those per pixel (skin::shade).
pub fn unblurred_levels(levels: &[Level]) -> usize {
    levels.iter().take_while(|l| l.sigma_mm.is_none()).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Texels written by the blur passes of a plan whose input is `resolution`²
    /// (U pass: new width × old height; V pass: new side²).
    fn blurred_texels(levels: &[Level], resolution: u32) -> u64 {
        let mut previous = resolution as u64;
        let mut texels = 0;
        for l in levels {
            let r = l.resolution as u64;
            if l.sigma_mm.is_some() {
                texels += r * previous + r * r;
            }
            previous = r;
        }
        texels
    }

    #[test]
    fn the_full_chain_blurs_every_level_at_the_irradiance_resolution() {
        let p = Profile::skin();
        let levels = plan(&p, Chain::Full, 1024, 4.0);
        assert_eq!(levels.len(), 6);
        for (l, inc) in levels.iter().zip(p.increments()) {
            assert_eq!(l.resolution, 1024);
            assert_eq!(l.sigma_mm, Some(inc));
        }
    }

    #[test]
    fn adaptive_levels_keep_their_width_in_texels_and_the_total_variance() {
        let p = Profile::skin();
        let (res, stretch) = (4096, 16.0);
        let levels = plan(&p, Chain::Adaptive, res, stretch);
        // σ1 = 0.08 mm is 1.3 texels: the irradiance itself.
        assert_eq!(levels[0].sigma_mm, None);
        assert_eq!(levels[0].resolution, res);
        let mut variance = 0.0;
        let mut previous = res;
        for (l, g) in levels.iter().zip(&p.gaussians).skip(1) {
            variance += l.sigma_mm.unwrap().powi(2);
            // Each computed level has the profile's total variance…
            assert!((variance - g.variance_mm2).abs() < 1e-5, "{l:?}");
            // …spans at least MIN_SIGMA_TEXELS texels, and half its side would not.
            let texels = |r: u32| g.variance_mm2.sqrt() * stretch * r as f32 / res as f32;
            assert!(texels(l.resolution) >= MIN_SIGMA_TEXELS, "{l:?}");
            assert!(l.resolution <= previous);
            assert!(
                texels(l.resolution / 2) < MIN_SIGMA_TEXELS
                    || l.resolution == previous
                    || l.resolution == MIN_RESOLUTION,
                "{l:?}"
            );
            previous = l.resolution;
        }
        let full = blurred_texels(&plan(&p, Chain::Full, res, stretch), res);
        let adaptive = blurred_texels(&levels, res);
        assert!(adaptive * 8 < full, "{adaptive} vs {full}");
    }

    #[test]
    fn a_profile_of_zero_width_is_not_blurred() {
        let mut p = Profile::skin();
        p.gaussians.iter_mut().for_each(|g| g.variance_mm2 = 0.0);
        for chain in [Chain::Full, Chain::Adaptive] {
            for l in plan(&p, chain, 1024, 4.0) {
                assert_eq!(
                    l,
                    Level {
                        resolution: 1024,
                        sigma_mm: None,
                        one_pass: None,
                    }
                );
            }
        }
    }

    #[test]
    fn narrow_levels_at_their_source_resolution_are_one_pass() {
        // The scan at 1024² (1.62 texels/mm): σ increments of levels 2-4 are
        // 0.36, 0.60 and 1.00 texels; 5 and 6 halve the resolution, with
        // increments of 0.97 and 0.94 texels of their own.
        let stencils: Vec<Option<Stencil>> = plan(&Profile::skin(), Chain::Adaptive, 1024, 1.62)
            .iter()
            .map(|l| l.one_pass)
            .collect();
        use Stencil::*;
        assert_eq!(
            stencils,
            [
                None,
                Some(Three),
                Some(Three),
                Some(Five),
                Some(Five),
                Some(Five)
            ]
        );
        // At 4096² (6.46 texels/mm) level 2 is 1.42 texels: two passes.
        // Level 3 halves to 2048² with 1.202 texels, 1.176 beyond the box of
        // its centre tap; levels 4-6 halve with under a texel.
        let stencils: Vec<Option<Stencil>> = plan(&Profile::skin(), Chain::Adaptive, 4096, 6.46)
            .iter()
            .map(|l| l.one_pass)
            .collect();
        assert_eq!(
            stencils,
            [None, None, Some(Five), Some(Five), Some(Five), Some(Five)]
        );
    }

    #[test]
    fn a_wide_first_gaussian_is_blurred() {
        // At 64 texels/mm σ1 = 0.08 mm spans 5 texels.
        let p = Profile::skin();
        assert!(plan(&p, Chain::Adaptive, 1024, 64.0)[0].sigma_mm.is_some());
    }
}
