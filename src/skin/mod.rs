//! The paper's skin model on the render graph: texture-space diffusion (stretch
//! map, irradiance, the six-Gaussian blur chain, final shading; GPU Gems 3 ch. 14
//! and the paper's section II.B) and the Kelemen/Szirmay-Kalos specular term.

pub mod blur;
pub mod chain;
pub mod falloff;
pub mod fit;
pub mod fold;
pub mod irradiance;
pub mod medium;
pub mod medium_tables;
pub mod profile;
pub mod reference;
pub mod shade;
pub mod specular;
pub mod stretch;
pub mod tables;
pub mod translucent;
pub mod walk;

use crate::error::{Error, Result};
use crate::frame_inputs::Vertex;
use crate::gpu::{GraphicsDesc, Pipeline, Pipelines};
use crate::scene::file::{
    Chain, Kernel as KernelChoice, Render, Skin, SpecularRegion, SpecularRule,
};
use crate::scene::mesh::Mesh;
use crate::scene::texture::{Encoding, Texture};
use crate::scene::Scene;
use ash::vk;
use blur::BlurKernel;
use falloff::Falloff;
use glam::Vec3;
use medium::Medium;
use medium_tables::MediumTables;
use profile::{Gaussian, Kernel, Profile};
use std::sync::Arc;

/// Format of every UV-space target (irradiance, stretch, blur levels):
/// coverage-premultiplied RGBA16F, as the design card fixes for the 4096² chain.
pub const UV_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// The tag of the diffusion chain's passes: the stretch levels and the blurs
/// (what `dermis sweep` sums as the chain).
pub const TAG: &str = "diffusion";

/// Settings of the skin model, resolved once from the scene's `[skin]` and
/// `[render]`: defaults filled in, checked against what the passes support.
#[derive(Clone, Debug)]
pub struct SkinSettings {
    /// The diffusion profile with `skin.blur_width` applied to its variances
    /// (the paper's "blurring width"; all 0: no blur).
    pub profile: Profile,
    /// Share of the blurred irradiance in the diffuse term, the rest unblurred
    /// (the paper's "blurring amount").
    pub blur_amount: f32,
    /// KS parameters of the ten face regions (specular::REGION_NAMES order).
    pub regions: Vec<SpecularRegion>,
    /// The specular lobe: a medium's boundary (a rough dielectric of its
    /// `ior`), else the paper's KS lobe at d'Eon's F0 0.028. The lobe, its
    /// albedo table (what the boundary takes from the light entering) and the
    /// prefiltered environment follow it.
    pub lobe: specular::Lobe,
    pub kernel: BlurKernel,
    /// Resolutions of the blur levels (skin::chain).
    pub chain: Chain,
    /// Pre-scatter share of the albedo (d'Eon & Luebke §14.5: 0.5).
    pub mix: f32,
    /// Side of the UV-space targets (power of two, 256..=8192).
    pub resolution: u32,
    /// Scale tap spacing by the per-texel stretch map; off: one constant
    /// texels-per-mm for the whole mesh.
    pub stretch_correction: bool,
    /// Scale on the light transmitted through thin skin from shadowed lights
    /// behind it (`skin.transmission`, ≥ 0; 0: the final pass is built without
    /// the term). The profile's weights and variances give its transmittance
    /// ([`profile::Profile::transmittance`]).
    pub transmission: f32,
    /// Store the UV shear in the stretch maps and blur along the surface
    /// perpendicular of ∂P/∂u (skin::stretch::StretchTensor); off: the diagonal
    /// only, u then v.
    pub shear_correction: bool,
    /// Correct the chain's levels where the skin comes back within the
    /// profile's reach through the tissue (skin::fold).
    pub fold_correction: bool,
    /// The medium the profile was fitted to, and its tables; `None` for
    /// `deon2007` (the paper's Gaussians).
    pub medium: Option<MediumSkin>,
    /// The profile the exact-diffusion reference convolves with: a medium's
    /// dense fit of its R(r) (skin::fit::fit_reference), else `profile`;
    /// `skin.blur_width` applied.
    pub reference_profile: Profile,
}

/// A medium's share of the settings (`[skin.medium]`).
#[derive(Clone, Debug)]
pub struct MediumSkin {
    pub medium: Medium,
    pub tables: MediumTables,
    /// The specular lobe: the medium's boundary, or the paper's regions.
    pub specular: SpecularRule,
}

impl SkinSettings {
    /// What light through thin skin falls off by: the medium's slab
    /// transmission, else the profile (light::transmission).
    pub fn falloff(&self) -> Falloff<'_> {
        match &self.medium {
            Some(m) => Falloff::slab(
                &m.tables.transmittance_over_albedo(),
                m.tables.max_thickness_mm,
            ),
            None => Falloff::Profile(&self.profile),
        }
    }

    pub fn resolve(skin: &Skin, render: &Render) -> Result<Self> {
        let medium = medium_skin(skin);
        let profile = match (&medium, &skin.profile) {
            (Some(m), _) => m.tables.profile(),
            (None, Some(p)) => Profile {
                gaussians: p
                    .iter()
                    .map(|g| Gaussian {
                        variance_mm2: g.variance_mm2,
                        weights: Vec3::from(g.weights),
                    })
                    .collect(),
            },
            (None, None) => Profile::skin(),
        };
        if profile.gaussians.len() != 6 {
            return Err(Error::Input(format!(
                "skin.profile has {} Gaussians; the blur chain and final shading use six",
                profile.gaussians.len()
            )));
        }
        profile
            .validate()
            .map_err(|e| Error::Input(format!("skin profile: {e}")))?;
        let widen = |mut p: Profile| {
            for g in &mut p.gaussians {
                g.variance_mm2 *= skin.blur_width;
            }
            p
        };
        let profile = widen(profile);
        let reference_profile = match &medium {
            Some(m) => widen(m.tables.reference_profile()),
            None => profile.clone(),
        };
        let mut regions = skin.regions.clone().unwrap_or_else(|| {
            specular::default_regions()
                .iter()
                .map(|r| SpecularRegion {
                    name: r.name.into(),
                    rho_s: r.rho_s,
                    m: r.m,
                })
                .collect()
        });
        let lobe = match &medium {
            Some(m) if m.boundary_specular() => specular::Lobe::Dielectric { ior: m.medium.ior },
            _ => specular::Lobe::PAPER,
        };
        if let specular::Lobe::Dielectric { .. } = lobe {
            for r in &mut regions {
                r.rho_s = specular::DIELECTRIC_RHO_S;
            }
        }
        Ok(Self {
            profile,
            blur_amount: skin.blur_amount,
            regions,
            lobe,
            kernel: match skin.kernel {
                KernelChoice::Deon7 => BlurKernel::Fixed(Kernel::deon7()),
                KernelChoice::Accurate => BlurKernel::Accurate,
            },
            chain: skin.chain,
            mix: skin.mix,
            resolution: render.irradiance_resolution,
            stretch_correction: skin.stretch_correction,
            transmission: skin.transmission,
            shear_correction: skin.shear_correction,
            fold_correction: skin.fold_correction,
            medium,
            reference_profile,
        })
    }

    /// The specular map raises ρs (d'Eon's rule) only with the regions' lobe:
    /// a medium's boundary has one ρs.
    pub fn specular_map_applies(&self) -> bool {
        !self
            .medium
            .as_ref()
            .is_some_and(MediumSkin::boundary_specular)
    }
}

impl MediumSkin {
    pub fn boundary_specular(&self) -> bool {
        self.specular == SpecularRule::Boundary
    }
}

/// The scene's medium and its tables (walked and fitted, or from the cache);
/// `None` for `deon2007`.
fn medium_skin(skin: &Skin) -> Option<MediumSkin> {
    let medium = Medium::from_spec(&skin.medium)?;
    let tables = MediumTables::load_or_compute(&medium, &crate::cache::default_cache_dir());
    log::info!(
        "medium {}: albedo {:.3?}, fit error {:.3?} (walks {:.2} s, fits {:.2} s)",
        medium.key(),
        tables.albedo,
        tables.fit_error,
        tables.walk_seconds,
        tables.fit_seconds
    );
    Some(MediumSkin {
        medium,
        tables,
        specular: skin.medium.specular.unwrap_or(SpecularRule::Boundary),
    })
}

/// `scene` with its skin's colour: where the scene names a medium and no
/// albedo map (nor the test texture), the medium's own albedo, uniform; else
/// unchanged (the map's colour with the medium's profile).
pub fn with_medium_albedo(mut scene: Scene) -> Scene {
    let t = &scene.file.textures;
    if t.albedo.is_some() || t.test_texture {
        return scene;
    }
    if let Some(medium) = Medium::from_spec(&scene.file.skin.medium) {
        let tables = MediumTables::load_or_compute(&medium, &crate::cache::default_cache_dir());
        let srgb = tables.albedo.map(crate::scene::texture::linear_to_srgb8);
        scene.albedo = Texture::solid([srgb[0], srgb[1], srgb[2], 255], Encoding::Srgb);
    }
    scene
}

/// Texels per millimetre of the whole atlas: √(UV area in texels² / surface
/// area in mm²), the constant used when stretch correction is off.
pub fn mean_stretch(mesh: &Mesh, resolution: u32) -> f32 {
    let (mut uv_area, mut area) = (0.0f64, 0.0f64);
    for t in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
        let p = |i: usize| mesh.positions[i];
        area += 0.5 * (p(b) - p(a)).cross(p(c) - p(a)).length() as f64;
        let (ua, ub, uc) = (mesh.uvs[a], mesh.uvs[b], mesh.uvs[c]);
        uv_area += 0.5 * ((ub - ua).perp_dot(uc - ua)).abs() as f64;
    }
    let texels = uv_area * (resolution as f64).powi(2);
    if area > 0.0 {
        (texels / area).sqrt() as f32
    } else {
        1.0
    }
}

/// A pipeline that rasterises the mesh in UV space into targets of
/// `color_formats`.
pub(crate) fn uv_pipeline(
    pipelines: &Pipelines,
    (vertex, fragment): (&str, &str),
    color_formats: &[vk::Format],
    specialization: &[u32],
) -> Result<Arc<Pipeline>> {
    pipelines.graphics(&GraphicsDesc {
        vertex,
        fragment,
        color_formats,
        depth_format: None,
        depth_write: true,
        vertex_layout: Some(Vertex::layout()),
        // UV charts may be mirrored: both windings are surface.
        cull_mode: vk::CullModeFlags::NONE,
        specialization,
        alpha_blend: false,
    })
}
