//! Environment specular by split sum (Karis 2013), with the Kelemen/Szirmay-Kalos
//! lobe: the specular of an environment is approximated as ρs·A(N·V, m) × the
//! environment averaged over the KS lobe around the reflected direction, where A
//! is the KS directional albedo table (skin::specular::specular_albedo_lut) and
//! the average is this module's prefiltered environment (shaders-glsl/
//! env_prefilter.comp). Both factors are exact for a constant environment; the
//! split is exact at normal incidence for any environment.
//!
//! The environment is fixed for a render, so the pass runs in its first frame
//! only, into an image that outlives the frames; later frames read it.

use crate::error::Result;
use crate::gpu::{Image, ImageDesc, Pipeline, Pipelines, Sampler};
use crate::graph::{Access, Graph, ImageHandle, Imported};
use crate::scene::env::EnvMap;
use crate::skin::specular::ks_brdf;
use ash::vk;
use glam::Vec3;
use std::sync::Arc;

/// Size of one roughness level, and the levels' roughness m = M0 + k·DM
/// (shaders-glsl/common/env_specular.glsl). 128×64 resolves the narrowest lobe
/// (m = 0.1: tan α = m puts its 1/e point 5.7° off the half vector, 11° off the
/// reflected direction) with 2.8° texels. The range holds d'Eon's default
/// m = 0.3 (GPU Gems 3 §14.3) with wide margins; other roughness is clamped to it.
pub const WIDTH: u32 = 128;
pub const HEIGHT: u32 = 64;
pub const LEVELS: u32 = 8;
pub const M0: f32 = 0.1;
pub const DM: f32 = 0.1;
pub const FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

pub struct PrefilterPass {
    /// Built for one F0 (env_prefilter.comp's `LOBE_F0`).
    pipeline: Arc<Pipeline>,
    sampler: Arc<Sampler>,
    image: Arc<Image>,
}

impl PrefilterPass {
    /// `sampler`: trilinear where the device filters the environment's format;
    /// `f0`: the lobe's Schlick F0 (skin::specular::Lobe::schlick_f0), a specialization
    /// constant: the environment is prefiltered once per render.
    pub fn new(pipelines: &Pipelines, sampler: Arc<Sampler>, f0: f32) -> Result<Self> {
        let ctx = pipelines.ctx();
        Ok(Self {
            pipeline: pipelines.compute("env_prefilter.comp", &[f0.to_bits()])?,
            sampler,
            image: Arc::new(Image::new(
                ctx,
                "specular environment",
                ImageDesc::new(WIDTH, HEIGHT * LEVELS, FORMAT),
                vk::ImageUsageFlags::STORAGE
                    | vk::ImageUsageFlags::SAMPLED
                    | vk::ImageUsageFlags::TRANSFER_SRC,
            )?),
        })
    }

    /// The prefiltered environment of `env` (with its mip chain), `WIDTH` ×
    /// `HEIGHT·LEVELS`, level k in rows [k·HEIGHT, (k+1)·HEIGHT), kept: the
    /// environment is fixed for a render, so the `env_prefilter` pass fills it
    /// once, in the first frame that needs it.
    pub fn pass(&self, g: &mut Graph, env: &Arc<Image>) -> ImageHandle {
        let (mut out, first) = g.import_kept_image(
            "prefiltered",
            Imported::Image(self.image.clone()),
            Access::ShaderSampled,
            0,
        );
        if first {
            g.simple_pass("env_prefilter", &self.pipeline)
                .tag(super::TAG)
                .texture(env, &self.sampler)
                .store(&mut out)
                .dispatch([WIDTH, HEIGHT * LEVELS, 1]);
        }
        out
    }
}

/// The direction of texel (x, y) of one level (y within the level), as the shader
/// computes it.
pub fn texel_direction(x: u32, y: u32) -> Vec3 {
    crate::scene::env::direction(
        (x as f32 + 0.5) / WIDTH as f32,
        (y as f32 + 0.5) / HEIGHT as f32,
    )
}

/// Roughness of level `k`.
pub fn level_m(k: u32) -> f32 {
    M0 + k as f32 * DM
}

/// CPU reference of one prefiltered value: Σ L(l)·w(l)·dω / Σ w(l)·dω over every
/// texel of `env`, with w = the KS lobe ks_brdf(r, l, r, m, 1, f0) (N·L
/// included) — brute force, no sampling.
pub fn reference(env: &EnvMap, r: Vec3, m: f32, f0: f32) -> Vec3 {
    let (mut acc, mut total) = (Vec3::ZERO, 0.0f64);
    for y in 0..env.height {
        let d_omega = crate::scene::env::texel_solid_angle(y, env.width, env.height);
        for x in 0..env.width {
            let l = env.texel_direction(x, y);
            let w = ks_brdf(r, l, r, m, 1.0, f0) * d_omega;
            if w > 0.0 {
                acc += env.texel(x, y) * w;
                total += f64::from(w);
            }
        }
    }
    acc / total.max(1e-30) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skin::specular::F0_SKIN;

    #[test]
    fn a_constant_environment_prefilters_to_itself() {
        let env = EnvMap::uniform(Vec3::new(0.2, 0.5, 1.5), 256, 128);
        let v = reference(&env, Vec3::new(0.3, 0.4, -0.2).normalize(), 0.3, F0_SKIN);
        assert!(
            (v - Vec3::new(0.2, 0.5, 1.5)).abs().max_element() < 1e-4,
            "{v}"
        );
    }

    #[test]
    fn the_reference_narrows_with_roughness() {
        // A bright cap of 10° radius around +Z: a smooth lobe centred on it sees
        // more of it than a rough one, and a lobe pointing away sees almost none.
        let env = EnvMap::from_fn(512, 256, |d| {
            Vec3::splat(if d.z > 10f32.to_radians().cos() {
                1.0
            } else {
                0.0
            })
        });
        let smooth = reference(&env, Vec3::Z, 0.1, F0_SKIN).x;
        let rough = reference(&env, Vec3::Z, 0.5, F0_SKIN).x;
        let away = reference(&env, -Vec3::Z, 0.3, F0_SKIN).x;
        assert!(smooth > 0.5 && smooth < 1.0, "{smooth}");
        assert!(rough < 0.5 * smooth, "{rough} vs {smooth}");
        assert!(away < 1e-3, "{away}");
    }
}
