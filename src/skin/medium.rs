//! The skin as a physical medium: absorption and scattering coefficients, phase
//! anisotropy and the boundary's index of refraction, from the scene's
//! `[skin.medium]` (a preset, explicit coefficients, or the artists' albedo and
//! mean free path through a named inversion), and the closed forms of diffusion
//! theory the Monte Carlo reference (skin::walk) is checked against.
//!
//! Units: mm⁻¹ and mm.

use crate::scene::file::{Inversion, Medium as MediumSpec, MediumPreset};
use glam::Vec3;

/// A homogeneous medium behind a dielectric boundary.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Medium {
    /// Absorption coefficient σa, mm⁻¹ (R, G, B).
    pub sigma_a: Vec3,
    /// Reduced scattering coefficient σs′ = σs(1 − g), mm⁻¹.
    pub sigma_s_prime: Vec3,
    /// Henyey–Greenstein anisotropy g.
    pub g: f32,
    /// Index of refraction inside, air (1) outside.
    pub ior: f32,
}

/// Jensen, Marschner, Levoy & Hanrahan 2001, "A Practical Model for Subsurface
/// Light Transport", Fig. 5: (σs′, σa) in mm⁻¹, R G B (as tabulated in pbrt's
/// `GetMediumScatteringProperties`).
const JENSEN_2001: [(MediumPreset, [f32; 3], [f32; 3]); 7] = [
    (
        MediumPreset::JensenSkin1,
        [0.74, 0.88, 1.01],
        [0.032, 0.17, 0.48],
    ),
    (
        MediumPreset::JensenSkin2,
        [1.09, 1.59, 1.79],
        [0.013, 0.070, 0.145],
    ),
    (
        MediumPreset::JensenMarble,
        [2.19, 2.62, 3.00],
        [0.0021, 0.0041, 0.0071],
    ),
    (
        MediumPreset::JensenSkimmilk,
        [0.70, 1.22, 1.90],
        [0.0014, 0.0025, 0.0142],
    ),
    (
        MediumPreset::JensenPotato,
        [0.68, 0.70, 0.55],
        [0.0024, 0.0090, 0.12],
    ),
    (
        MediumPreset::JensenApple,
        [2.29, 2.39, 1.97],
        [0.0030, 0.0034, 0.046],
    ),
    (
        MediumPreset::JensenKetchup,
        [0.18, 0.07, 0.03],
        [0.061, 0.97, 1.45],
    ),
];

impl Medium {
    /// The scene's medium; `None` for `deon2007` (no medium: the paper's
    /// Gaussians). Assumes the spec passed `validate`.
    pub fn from_spec(spec: &MediumSpec) -> Option<Medium> {
        if spec.is_deon2007() {
            return None;
        }
        let (g, ior) = (spec.g, spec.ior);
        if let Some(preset) = spec.preset {
            let &(_, s, a) = JENSEN_2001.iter().find(|(p, ..)| *p == preset)?;
            return Some(Medium::new(Vec3::from(a), Vec3::from(s), g, ior));
        }
        if let (Some(a), Some(s)) = (spec.sigma_a, spec.sigma_s_prime) {
            return Some(Medium::new(Vec3::from(a), Vec3::from(s), g, ior));
        }
        let albedo = Vec3::from(spec.albedo?);
        let m = match (spec.mfp, spec.dmfp) {
            (Some(l), _) => {
                let inversion = spec.inversion.unwrap_or(Inversion::VanDeHulst);
                Medium::from_albedo_mfp(albedo, Vec3::from(l), inversion, g, ior)
            }
            (None, Some(d)) => {
                let inversion = spec.inversion.unwrap_or(Inversion::Dipole);
                Medium::from_albedo_dmfp(albedo, Vec3::from(d), inversion, g, ior)
            }
            (None, None) => return None,
        };
        Some(m)
    }

    pub fn new(sigma_a: Vec3, sigma_s_prime: Vec3, g: f32, ior: f32) -> Medium {
        Medium {
            sigma_a,
            sigma_s_prime,
            g,
            ior,
        }
    }

    /// σs = σs′/(1 − g).
    pub fn sigma_s(&self) -> Vec3 {
        self.sigma_s_prime / (1.0 - self.g)
    }

    /// Reduced extinction σt′ = σa + σs′.
    pub fn sigma_t_prime(&self) -> Vec3 {
        self.sigma_a + self.sigma_s_prime
    }

    /// Reduced single-scattering albedo α′ = σs′/σt′.
    pub fn reduced_albedo(&self) -> Vec3 {
        self.sigma_s_prime / self.sigma_t_prime()
    }

    /// Effective transport coefficient σtr = √(3σa σt′) (Jensen et al. 2001, eq. 5).
    pub fn sigma_tr(&self) -> Vec3 {
        (3.0 * self.sigma_a * self.sigma_t_prime()).map(f32::sqrt)
    }

    /// Diffuse mean free path 1/σtr, mm (skin1: 3.67, 1.37, 0.68 mm).
    pub fn dmfp(&self) -> Vec3 {
        self.sigma_tr().recip()
    }

    /// Channel `c`'s coefficients in f64 for the walk: (σa, σs, g).
    pub fn channel(&self, c: usize) -> (f64, f64, f64) {
        (
            f64::from(self.sigma_a[c]),
            f64::from(self.sigma_s()[c]),
            f64::from(self.g),
        )
    }

    /// The artists' (albedo, mean free path ℓ = 1/σt′) through `inversion`.
    pub fn from_albedo_mfp(
        albedo: Vec3,
        mfp: Vec3,
        inversion: Inversion,
        g: f32,
        ior: f32,
    ) -> Medium {
        let alpha = albedo.map(|a| single_albedo(f64::from(a), inversion, ior) as f32);
        let sigma_t = mfp.recip();
        Medium::new(sigma_t * (1.0 - alpha), sigma_t * alpha, g, ior)
    }

    /// The artists' (albedo, diffuse mean free path d = 1/σtr): σt′ =
    /// σtr/√(3(1 − α′)), since σtr = √(3σa σt′) = σt′√(3(1 − α′)).
    pub fn from_albedo_dmfp(
        albedo: Vec3,
        dmfp: Vec3,
        inversion: Inversion,
        g: f32,
        ior: f32,
    ) -> Medium {
        let alpha = albedo.map(|a| single_albedo(f64::from(a), inversion, ior) as f32);
        let sigma_t = dmfp.recip() / (3.0 * (1.0 - alpha)).map(f32::sqrt);
        Medium::new(sigma_t * (1.0 - alpha), sigma_t * alpha, g, ior)
    }

    /// A stable text of the coefficients, for cache keys.
    pub fn key(&self) -> String {
        let v = |v: Vec3| format!("{:e},{:e},{:e}", v.x, v.y, v.z);
        format!(
            "sa={};ssp={};g={:e};ior={:e}",
            v(self.sigma_a),
            v(self.sigma_s_prime),
            self.g,
            self.ior
        )
    }
}

/// The reduced single-scattering albedo α′ whose semi-infinite medium reflects
/// the multiple-scattering albedo `a`.
pub fn single_albedo(a: f64, inversion: Inversion, ior: f32) -> f64 {
    match inversion {
        Inversion::VanDeHulst => van_de_hulst_inverse(a),
        Inversion::Dipole => {
            let bound = internal_reflection_a(f64::from(ior));
            // Rd(α′) increases with α′ (Jensen et al. 2001, eq. 8): bisect.
            let (mut lo, mut hi) = (0.0, 1.0);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if dipole_total_reflectance(mid, bound) < a {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            0.5 * (lo + hi)
        }
    }
}

/// Christensen & Burley 2015, eq. 9 (their fit to van de Hulst's tables of an
/// index-matched semi-infinite medium lit from above): α = 1 − (4.09712 +
/// 4.20863A − √(9.59217 + 41.6808A + 17.7126A²))².
pub fn van_de_hulst_inverse(a: f64) -> f64 {
    let t = 4.09712 + 4.20863 * a - (9.59217 + 41.6808 * a + 17.7126 * a * a).sqrt();
    1.0 - t * t
}

/// Diffuse Fresnel reflectance of the boundary seen from inside, Egan &
/// Hilgeman's fit as Jensen et al. 2001 give it (eq. 6): F_dr = −1.440/η² +
/// 0.710/η + 0.668 + 0.0636η; and A = (1 + F_dr)/(1 − F_dr).
pub fn internal_reflection_a(eta: f64) -> f64 {
    let f_dr = -1.440 / (eta * eta) + 0.710 / eta + 0.668 + 0.0636 * eta;
    (1.0 + f_dr) / (1.0 - f_dr)
}

/// The dipole's total diffuse reflectance (Jensen et al. 2001, eq. 8; Jensen &
/// Buhler 2002, eq. 2): Rd = α′/2 (1 + e^(−4/3·A√(3(1−α′)))) e^(−√(3(1−α′))).
pub fn dipole_total_reflectance(alpha: f64, a: f64) -> f64 {
    let s = (3.0 * (1.0 - alpha)).sqrt();
    0.5 * alpha * (1.0 + (-4.0 / 3.0 * a * s).exp()) * (-s).exp()
}

/// The dipole's radial reflectance Rd(r), mm⁻², of one channel (Jensen et al.
/// 2001, eq. 4): the real source at z_r = 1/σt′, the virtual one at z_v = z_r +
/// 4A·D, D = 1/(3σt′).
pub fn dipole_radial(sigma_a: f64, sigma_s_prime: f64, eta: f64, r: f64) -> f64 {
    let st = sigma_a + sigma_s_prime;
    let alpha = sigma_s_prime / st;
    let tr = (3.0 * sigma_a * st).sqrt();
    let zr = 1.0 / st;
    let zv = zr + 4.0 * internal_reflection_a(eta) / (3.0 * st);
    let (dr, dv) = ((r * r + zr * zr).sqrt(), (r * r + zv * zv).sqrt());
    let term = |z: f64, d: f64| z * (tr * d + 1.0) * (-tr * d).exp() / (d * d * d);
    alpha / (4.0 * std::f64::consts::PI) * (term(zr, dr) + term(zv, dv))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::file::Medium as Spec;

    #[test]
    fn skin1_has_jensens_diffuse_mean_free_paths() {
        let spec = Spec {
            preset: Some(MediumPreset::JensenSkin1),
            ..Spec::default()
        };
        let m = Medium::from_spec(&spec).unwrap();
        // The architecture guide's figures: 1/σtr = 3.67, 1.37, 0.68 mm.
        for (got, want) in m.dmfp().to_array().iter().zip([3.67, 1.37, 0.68]) {
            assert!((got - want).abs() < 0.01, "{got} against {want}");
        }
        assert!(Medium::from_spec(&Spec::default()).is_none());
    }

    #[test]
    fn artists_parameters_invert_to_what_they_came_from() {
        let m = Medium::new(
            Vec3::new(0.032, 0.17, 0.48),
            Vec3::new(0.74, 0.88, 1.01),
            0.0,
            1.4,
        );
        let bound = internal_reflection_a(1.4);
        // Dipole: Rd(α′) and 1/σtr give back σa and σs′.
        let albedo = m
            .reduced_albedo()
            .map(|a| dipole_total_reflectance(f64::from(a), bound) as f32);
        let back = Medium::from_albedo_dmfp(albedo, m.dmfp(), Inversion::Dipole, 0.0, 1.4);
        assert!(
            (back.sigma_a - m.sigma_a).abs().max_element() < 1e-4,
            "{back:?}"
        );
        assert!((back.sigma_s_prime - m.sigma_s_prime).abs().max_element() < 1e-3);
        // Van de Hulst: the fit's inverse at its own forward values.
        for a in [0.1, 0.4, 0.8, 0.95] {
            let alpha = van_de_hulst_inverse(a);
            assert!((0.0..=1.0).contains(&alpha), "{a} -> {alpha}");
        }
        let m2 = Medium::from_albedo_mfp(
            Vec3::splat(0.5),
            Vec3::splat(2.0),
            Inversion::VanDeHulst,
            0.0,
            1.0,
        );
        assert!((m2.sigma_t_prime() - Vec3::splat(0.5)).abs().max_element() < 1e-6);
    }

    #[test]
    fn dipole_reflectance_integrates_to_its_total() {
        // ∫ 2πr Rd(r) dr of eq. 4 equals eq. 8's total.
        let (sa, ssp, eta) = (0.032, 0.74, 1.4);
        let (mut sum, dr) = (0.0, 1e-4);
        let mut r = 0.5 * dr;
        while r < 80.0 {
            sum += 2.0 * std::f64::consts::PI * r * dipole_radial(sa, ssp, eta, r) * dr;
            r += dr;
        }
        let total = dipole_total_reflectance(ssp / (sa + ssp), internal_reflection_a(eta));
        assert!((sum - total).abs() < 1e-3 * total, "{sum} against {total}");
    }
}
