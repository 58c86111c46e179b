//! Analytic sun and sky: Preetham, Shirley & Smits, "A Practical Analytic Model
//! for Daylight" (SIGGRAPH 1999), rendered into an equirect [`EnvMap`].
//!
//! * Sky: Perez et al. luminance/chromaticity distribution with Preetham's
//!   turbidity-dependent coefficients (paper, appendix A.2) and zenith luminance
//!   and chromaticity formulas, converted xyY → XYZ → linear sRGB (D65).
//! * Sun: a disk of 0.53° apparent diameter whose irradiance at normal incidence
//!   is the luminous solar constant attenuated by Rayleigh and aerosol optical
//!   depth along the relative air mass (the transmittance formulas of Preetham's
//!   appendix A.2, evaluated at one wavelength per sRGB channel). Nothing is
//!   tuned: at the defaults (35°, T = 3) the sun gives 80 klux at normal
//!   incidence against 26 klux of sky on a horizontal surface (30 klux on a
//!   sun-facing one), i.e. direct-normal / diffuse-horizontal ≈ 3.1 and a
//!   diffuse fraction of global horizontal of 0.36 (T = 2: 3.8 / 0.31; T = 6:
//!   1.2 / 0.59; see the `sun_sky_ratio_and_scale` test). Measured clear skies
//!   are somewhat sunnier (diffuse fraction ≈ 0.17 for clear sky, Erbs, Klein &
//!   Duffie, Solar Energy 28, 1982), consistent with the known over-bright
//!   Preetham dome (Zotti, Wilkie & Purgathofer, "A Critical Review of the
//!   Preetham Skylight Model", WSCG 2007); scale `intensity` or pick a lower
//!   turbidity for a harder key light.
//! * Ground (below the horizon): constant, Lambertian with albedo 0.3 lit by the
//!   whole sky *and* the sun: `L = 0.3 · (E_sky,h + E_sun · sin(elevation)) / π`.
//!   (Including the sun is the physically consistent choice; a ground lit by the
//!   sky alone would be ≈ 2.7× too dark at the defaults.)
//!
//! # Units and scale
//! Radiance is in kcd/m² (Preetham's zenith luminance unit) times `intensity`;
//! irradiance then comes out in klux. A clear sky is ≈ 1–15, the ground ≈ 3–10.
//! The sun disk is ≈ 10⁶ (it is 10⁵× brighter than the sky per steradian); that
//! exceeds the half-float range, so keep sky maps in f32 (or project to SH on the
//! CPU) — the sun is spread over the texels it covers so that its *energy* is
//! exact at any resolution.
//!
//! # Sun position
//! `elevation_deg` above the horizon (0–90). `azimuth_deg` is measured about +Y
//! from +Z toward +X: the sun direction is
//! `(cos e · sin a, sin e, cos e · cos a)`. The face looks toward +Z, so the
//! default azimuth 315° puts the sun in front of the face and toward −X, i.e. on
//! the left as seen by a camera in front of the face (the subject's right).

use glam::Vec3;

use super::map::{direction, direction_to_uv, texel_solid_angle_f64, EnvMap};

/// Apparent angular diameter of the sun (degrees), mean value.
pub const SUN_ANGULAR_DIAMETER_DEG: f32 = 0.53;
/// Ground albedo below the horizon.
pub const GROUND_ALBEDO: f32 = 0.3;
/// Luminous solar constant, klux (Darula, Kittler & Gueymard, "Reference
/// luminous solar constant and solar luminance for illuminance calculations",
/// Solar Energy 79, 2005: 133.8 klux).
pub const SOLAR_ILLUMINANCE_KLUX: f32 = 133.8;

/// Parameters of the analytic sky.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyParams {
    /// Sun elevation above the horizon, degrees, [0, 90].
    pub elevation_deg: f32,
    /// Sun azimuth about +Y from +Z toward +X, degrees (any finite value).
    pub azimuth_deg: f32,
    /// Atmospheric turbidity, [1.7, 10] (Preetham's fitted range).
    pub turbidity: f32,
    /// Overall scale of the result (finite, ≥ 0).
    pub intensity: f32,
}

impl Default for SkyParams {
    fn default() -> Self {
        SkyParams {
            // 65° to the face's right (−X) and 30° up: side light that models
            // the face and leaves a shadow edge for subsurface scattering to soften.
            elevation_deg: 30.0,
            azimuth_deg: 295.0,
            turbidity: 3.0,
            intensity: 1.0,
        }
    }
}

/// Invalid sky parameters.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SkyError {
    #[error("elevation {0}° is outside [0, 90]")]
    Elevation(f32),
    #[error("turbidity {0} is outside [1.7, 10] (Preetham's fitted range)")]
    Turbidity(f32),
    #[error("azimuth {0}° is not finite")]
    Azimuth(f32),
    #[error("intensity {0} must be finite and >= 0")]
    Intensity(f32),
}

impl SkyParams {
    /// Check the ranges documented on the fields.
    pub fn validate(&self) -> Result<(), SkyError> {
        if !(0.0..=90.0).contains(&self.elevation_deg) {
            return Err(SkyError::Elevation(self.elevation_deg));
        }
        if !(1.7..=10.0).contains(&self.turbidity) {
            return Err(SkyError::Turbidity(self.turbidity));
        }
        if !self.azimuth_deg.is_finite() {
            return Err(SkyError::Azimuth(self.azimuth_deg));
        }
        if !(self.intensity.is_finite() && self.intensity >= 0.0) {
            return Err(SkyError::Intensity(self.intensity));
        }
        Ok(())
    }

    /// The parameters forced into their valid ranges (NaN → default).
    pub fn clamped(&self) -> SkyParams {
        let d = SkyParams::default();
        let fix = |v: f32, lo: f32, hi: f32, def: f32| {
            if v.is_nan() {
                def
            } else {
                v.clamp(lo, hi)
            }
        };
        SkyParams {
            elevation_deg: fix(self.elevation_deg, 0.0, 90.0, d.elevation_deg),
            azimuth_deg: if self.azimuth_deg.is_finite() {
                self.azimuth_deg
            } else {
                d.azimuth_deg
            },
            turbidity: fix(self.turbidity, 1.7, 10.0, d.turbidity),
            intensity: fix(self.intensity, 0.0, f32::MAX, d.intensity),
        }
    }

    /// Unit vector toward the sun (see the module doc).
    pub fn sun_direction(&self) -> Vec3 {
        let e = self.elevation_deg.to_radians();
        let a = self.azimuth_deg.to_radians();
        Vec3::new(e.cos() * a.sin(), e.sin(), e.cos() * a.cos()).normalize_or(Vec3::Y)
    }
}

/// Perez et al. distribution coefficients A..E for one quantity.
#[derive(Clone, Copy, Debug)]
struct Perez([f64; 5]);

impl Perez {
    /// F(θ, γ) = (1 + A·e^(B/cos θ)) · (1 + C·e^(D·γ) + E·cos²γ).
    fn eval(&self, cos_theta: f64, gamma: f64) -> f64 {
        let [a, b, c, d, e] = self.0;
        let ct = cos_theta.max(1e-4); // the horizon limit: e^(B/0⁺) → 0 since B < 0
        (1.0 + a * (b / ct).exp()) * (1.0 + c * (d * gamma).exp() + e * gamma.cos().powi(2))
    }
}

/// Preetham sky for one sun position and turbidity (sky dome only).
#[derive(Clone, Copy, Debug)]
struct Preetham {
    sun: Vec3,
    coef: [Perez; 3], // Y, x, y
    zenith: [f64; 3], // Y_z (kcd/m²), x_z, y_z
    norm: [f64; 3],   // F(0, θs) for Y, x, y
}

impl Preetham {
    fn new(p: &SkyParams) -> Preetham {
        let t = f64::from(p.turbidity);
        let sun = p.sun_direction();
        let theta_s = f64::from(sun.y.clamp(-1.0, 1.0)).acos();
        // Preetham et al. 1999, appendix A.2: distribution coefficients.
        let coef = [
            Perez([
                0.1787 * t - 1.4630,
                -0.3554 * t + 0.4275,
                -0.0227 * t + 5.3251,
                0.1206 * t - 2.5771,
                -0.0670 * t + 0.3703,
            ]),
            Perez([
                -0.0193 * t - 0.2592,
                -0.0665 * t + 0.0008,
                -0.0004 * t + 0.2125,
                -0.0641 * t - 0.8989,
                -0.0033 * t + 0.0452,
            ]),
            Perez([
                -0.0167 * t - 0.2608,
                -0.0950 * t + 0.0092,
                -0.0079 * t + 0.2102,
                -0.0441 * t - 1.6537,
                -0.0109 * t + 0.0529,
            ]),
        ];
        // Zenith luminance (kcd/m²), appendix A.2.
        let chi = (4.0 / 9.0 - t / 120.0) * (std::f64::consts::PI - 2.0 * theta_s);
        let y_z = (4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192;
        // Zenith chromaticity: [T² T 1] · M · [θs³ θs² θs 1]ᵀ, appendix A.2.
        let th = [theta_s.powi(3), theta_s.powi(2), theta_s, 1.0];
        let tt = [t * t, t, 1.0];
        let chroma = |m: [[f64; 4]; 3]| -> f64 {
            (0..3)
                .map(|i| tt[i] * (0..4).map(|j| m[i][j] * th[j]).sum::<f64>())
                .sum()
        };
        let x_z = chroma([
            [0.00166, -0.00375, 0.00209, 0.0],
            [-0.02903, 0.06377, -0.03202, 0.00394],
            [0.11693, -0.21196, 0.06052, 0.25886],
        ]);
        let yy_z = chroma([
            [0.00275, -0.00610, 0.00317, 0.0],
            [-0.04214, 0.08970, -0.04153, 0.00516],
            [0.15346, -0.26756, 0.06670, 0.26688],
        ]);
        let norm = coef.map(|c| c.eval(1.0, theta_s));
        Preetham {
            sun,
            coef,
            zenith: [y_z.max(0.0), x_z, yy_z],
            norm,
        }
    }

    /// Sky radiance (kcd/m², linear sRGB) toward `d` (upper hemisphere).
    fn radiance(&self, d: Vec3) -> Vec3 {
        let cos_theta = f64::from(d.y.max(0.0));
        let gamma = f64::from(d.dot(self.sun).clamp(-1.0, 1.0)).acos();
        let f = |i: usize| {
            let n = self.norm[i];
            if n.abs() < 1e-12 {
                self.zenith[i]
            } else {
                self.zenith[i] * self.coef[i].eval(cos_theta, gamma) / n
            }
        };
        xyy_to_linear_srgb(f(1), f(2), f(0)).max(Vec3::ZERO)
    }
}

/// CIE xyY → linear sRGB (D65). XYZ → sRGB matrix from IEC 61966-2-1:1999.
pub fn xyy_to_linear_srgb(x: f64, y: f64, lum: f64) -> Vec3 {
    if y.is_nan() || y <= 1e-9 || !lum.is_finite() {
        return Vec3::ZERO;
    }
    let cx = x * lum / y;
    let cy = lum;
    let cz = (1.0 - x - y) * lum / y;
    Vec3::new(
        (3.2406 * cx - 1.5372 * cy - 0.4986 * cz) as f32,
        (-0.9689 * cx + 1.8758 * cy + 0.0415 * cz) as f32,
        (0.0557 * cx - 0.2040 * cy + 1.0570 * cz) as f32,
    )
}

/// Sky radiance (no sun disk, no ground) toward `d`, kcd/m² × intensity; zero
/// below the horizon. Parameters are clamped into range.
pub fn sky_radiance(p: &SkyParams, d: Vec3) -> Vec3 {
    let p = p.clamped();
    let d = d.normalize_or_zero();
    if d.y < 0.0 {
        return Vec3::ZERO;
    }
    Preetham::new(&p).radiance(d) * p.intensity
}

/// Sun irradiance on a surface facing the sun (klux × intensity, per sRGB
/// channel): `E0 · exp(−m·(τ_R(λ) + τ_a(λ)))` with, from Preetham et al.
/// appendix A.2, relative air mass `m = 1/(cos θs + 0.15·(93.885 − θs°)^−1.253)`
/// (Kasten 1966), Rayleigh `τ_R = 0.008735·λ^−4.08` (λ in µm) and aerosol
/// `τ_a = β·λ^−1.3`, `β = 0.04608·T − 0.04586`. One wavelength per channel:
/// 0.61, 0.55, 0.465 µm (approximate dominant wavelengths of the sRGB
/// primaries). Ozone, water and mixed-gas absorption are ignored.
pub fn sun_irradiance(p: &SkyParams) -> Vec3 {
    let p = p.clamped();
    let theta_deg = 90.0 - f64::from(p.elevation_deg);
    let theta = theta_deg.to_radians();
    let m = 1.0 / (theta.cos() + 0.15 * (93.885 - theta_deg).powf(-1.253));
    let beta = 0.04608 * f64::from(p.turbidity) - 0.04586;
    let e0 = f64::from(SOLAR_ILLUMINANCE_KLUX);
    let ch = |lambda: f64| {
        let tau = 0.008735 * lambda.powf(-4.08) + beta * lambda.powf(-1.3);
        (e0 * (-m * tau).exp()) as f32
    };
    Vec3::new(ch(0.61), ch(0.55), ch(0.465)) * p.intensity
}

/// Render sky + sun + ground into a `width × height` equirect map (sizes
/// clamped like [`EnvMap::uniform`], parameters clamped into range; call
/// [`SkyParams::validate`] first to reject bad input).
pub fn render_sky(p: &SkyParams, width: u32, height: u32) -> EnvMap {
    render_sky_impl(p, width, height, true)
}

/// [`render_sky`], with or without the sun disk (the sky alone is what tests
/// of the disk and of `light::extract` compare with).
pub(crate) fn render_sky_impl(p: &SkyParams, width: u32, height: u32, with_sun: bool) -> EnvMap {
    let p = p.clamped();
    let model = Preetham::new(&p);
    let mut env = EnvMap::from_fn(width, height, |d| {
        if d.y >= 0.0 {
            model.radiance(d)
        } else {
            Vec3::ZERO
        }
    });
    let (w, h) = (env.width, env.height);

    // Sky irradiance on a horizontal surface (ground lighting).
    let mut e_sky = [0.0f64; 3];
    for y in 0..h {
        let dw = texel_solid_angle_f64(y, w, h);
        for x in 0..w {
            let d = env.texel_direction(x, y);
            if d.y > 0.0 {
                let l = env.texel(x, y);
                let k = f64::from(d.y) * dw;
                e_sky[0] += f64::from(l.x) * k;
                e_sky[1] += f64::from(l.y) * k;
                e_sky[2] += f64::from(l.z) * k;
            }
        }
    }
    let e_sun = sun_irradiance(&SkyParams {
        intensity: 1.0,
        ..p
    });
    let sun = model.sun;
    let e_h = Vec3::new(e_sky[0] as f32, e_sky[1] as f32, e_sky[2] as f32) + e_sun * sun.y.max(0.0);
    let ground = e_h * (GROUND_ALBEDO / std::f32::consts::PI);
    for y in 0..h {
        for x in 0..w {
            if env.texel_direction(x, y).y < 0.0 {
                if let Some(t) = env.texels.get_mut(y as usize * w as usize + x as usize) {
                    *t = ground;
                }
            }
        }
    }

    if with_sun {
        add_sun_disk(&mut env, sun, e_sun);
    }
    if p.intensity != 1.0 {
        for t in env.texels.iter_mut() {
            *t *= p.intensity;
        }
    }
    env
}

/// Add a sun disk (angular diameter [`SUN_ANGULAR_DIAMETER_DEG`]) carrying
/// exactly `e_sun` of irradiance at normal incidence: each covered texel gets
/// `e_sun · c / Σ(c·dω)` where `c` is its covered fraction (8×8 supersamples).
/// When the disk falls between supersamples (tiny maps), the texel containing
/// the sun centre gets all of it.
fn add_sun_disk(env: &mut EnvMap, sun: Vec3, e_sun: Vec3) {
    const N: u32 = 8;
    let (w, h) = (env.width, env.height);
    if w == 0 || h == 0 {
        return;
    }
    let r = f64::from(SUN_ANGULAR_DIAMETER_DEG).to_radians() * 0.5;
    let cos_r = r.cos() as f32;
    // Any point of a texel is within π/H + 2π/W of its centre (conservative).
    let pi = std::f64::consts::PI;
    let reach = r + pi / f64::from(h) + 2.0 * pi / f64::from(w);
    let cos_reach = if reach >= pi {
        -1.0
    } else {
        reach.cos() as f32
    };
    let mut covered: Vec<(usize, f64)> = Vec::new();
    let mut total = 0.0f64;
    for y in 0..h {
        let dw = texel_solid_angle_f64(y, w, h);
        for x in 0..w {
            if env.texel_direction(x, y).dot(sun) < cos_reach {
                continue;
            }
            let mut hits = 0u32;
            for j in 0..N {
                for i in 0..N {
                    let u = (x as f32 + (i as f32 + 0.5) / N as f32) / w as f32;
                    let v = (y as f32 + (j as f32 + 0.5) / N as f32) / h as f32;
                    if direction(u, v).dot(sun) >= cos_r {
                        hits += 1;
                    }
                }
            }
            if hits > 0 {
                let c = f64::from(hits) / f64::from(N * N);
                covered.push((y as usize * w as usize + x as usize, c));
                total += c * dw;
            }
        }
    }
    if covered.is_empty() {
        let uv = direction_to_uv(sun);
        let x = ((uv.x * w as f32) as u32).min(w - 1);
        let y = ((uv.y * h as f32) as u32).min(h - 1);
        let dw = texel_solid_angle_f64(y, w, h);
        covered.push((y as usize * w as usize + x as usize, 1.0));
        total = dw;
    }
    if total.is_nan() || total <= 0.0 {
        return;
    }
    for (i, c) in covered {
        if let Some(t) = env.texels.get_mut(i) {
            *t += e_sun * (c / total) as f32;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn irradiance(env: &EnvMap, n: Vec3) -> Vec3 {
        let mut acc = Vec3::ZERO;
        for y in 0..env.height {
            let dw = texel_solid_angle_f64(y, env.width, env.height) as f32;
            for x in 0..env.width {
                let c = env.texel_direction(x, y).dot(n).max(0.0);
                acc += env.texel(x, y) * c * dw;
            }
        }
        acc
    }

    #[test]
    fn d65_white_maps_to_rgb_one() {
        // D65 white point (x, y) = (0.3127, 0.3290), Y = 1 → sRGB (1, 1, 1).
        let c = xyy_to_linear_srgb(0.3127, 0.3290, 1.0);
        assert!((c - Vec3::ONE).abs().max_element() < 2e-3, "{c}");
    }

    #[test]
    fn validation() {
        assert!(SkyParams::default().validate().is_ok());
        let bad = [
            SkyParams {
                turbidity: 1.5,
                ..Default::default()
            },
            SkyParams {
                turbidity: 11.0,
                ..Default::default()
            },
            SkyParams {
                elevation_deg: -1.0,
                ..Default::default()
            },
            SkyParams {
                elevation_deg: 91.0,
                ..Default::default()
            },
            SkyParams {
                elevation_deg: f32::NAN,
                ..Default::default()
            },
            SkyParams {
                azimuth_deg: f32::INFINITY,
                ..Default::default()
            },
            SkyParams {
                intensity: -1.0,
                ..Default::default()
            },
        ];
        for p in bad {
            assert!(p.validate().is_err(), "{p:?}");
            // Rendering clamps instead of failing.
            let env = render_sky(&p, 16, 8);
            assert!(env.texels.iter().all(|t| t.is_finite()));
        }
        // Default sun: in front of the face (+Z), mostly toward −X, 30° up.
        let s = SkyParams::default().sun_direction();
        assert!(s.z > 0.3 && s.x < -0.7 && (s.y - 30f32.to_radians().sin()).abs() < 1e-6);
    }

    fn luminance(c: Vec3) -> f32 {
        c.dot(crate::scene::texture::LUMINANCE)
    }

    #[test]
    fn sun_is_brightest_and_values_positive() {
        let cases = [
            (SkyParams::default(), true),
            (
                SkyParams {
                    elevation_deg: 10.0,
                    azimuth_deg: 120.0,
                    turbidity: 6.0,
                    intensity: 1.0,
                },
                true,
            ),
            (
                SkyParams {
                    elevation_deg: 90.0,
                    azimuth_deg: 0.0,
                    turbidity: 2.0,
                    intensity: 2.0,
                },
                true,
            ),
            // Sun on the horizon in a very hazy sky: physically invisible
            // (air mass 36), so only check the values.
            (
                SkyParams {
                    elevation_deg: 0.0,
                    azimuth_deg: 200.0,
                    turbidity: 10.0,
                    intensity: 1.0,
                },
                false,
            ),
        ];
        let (w, h) = (512, 256);
        for (p, visible_sun) in cases {
            let env = render_sky(&p, w, h);
            assert!(
                env.texels
                    .iter()
                    .all(|t| t.is_finite() && t.min_element() > 0.0),
                "{p:?}"
            );
            if !visible_sun {
                continue;
            }
            let (mut best, mut bi) = (0.0, 0);
            for (i, t) in env.texels.iter().enumerate() {
                if luminance(*t) > best {
                    (best, bi) = (luminance(*t), i);
                }
            }
            let d = env.texel_direction(bi as u32 % w, bi as u32 / w);
            let ang = d
                .dot(p.sun_direction())
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees();
            assert!(ang < 1.0, "{p:?}: brightest texel {ang}° from the sun");
            // The disk carries exactly E_sun: (with sun − without) summed
            // over a 2° cone, weighted by solid angle and cosine to the sun.
            let base = render_sky_impl(&p, w, h, false);
            let mut disk = Vec3::ZERO;
            for y in 0..h {
                let dw = texel_solid_angle_f64(y, w, h) as f32;
                for x in 0..w {
                    let c = env.texel_direction(x, y).dot(p.sun_direction());
                    if c > 2f32.to_radians().cos() {
                        disk += (env.texel(x, y) - base.texel(x, y)) * dw * c;
                    }
                }
            }
            let e_sun = sun_irradiance(&p);
            let rel = ((disk - e_sun) / e_sun).abs().max_element();
            assert!(rel < 1e-3, "{p:?}: {disk} vs {e_sun}");
        }
    }

    #[test]
    fn preetham_behaviour() {
        // θs = 55° (elevation 35°), the case worked by hand below.
        let p = SkyParams {
            elevation_deg: 35.0,
            ..SkyParams::default()
        };
        let s = p.sun_direction();
        // Brighter near the sun than 90° away at the same elevation.
        let near = luminance(sky_radiance(
            &p,
            glam::Mat3::from_rotation_y(10f32.to_radians()) * s,
        ));
        let far = luminance(sky_radiance(
            &p,
            glam::Mat3::from_rotation_y(90f32.to_radians()) * s,
        ));
        assert!(near > 2.0 * far, "near {near} far {far}");
        // Clear sky: zenith bluish.
        let z = sky_radiance(
            &SkyParams {
                turbidity: 2.0,
                ..p
            },
            Vec3::Y,
        );
        assert!(z.z > z.x, "zenith {z}");
        // Horizon brightening from the Perez gradation term 1 + A·e^(B/cos θ)
        // (A < 0): sun on the horizon, zenith vs horizon 90° from the sun (both
        // at γ = 90°). Expected luminance ratio 1/(1 + A·e^B): strong for clear
        // skies, weak for hazy ones.
        let mut ratios = Vec::new();
        for t in [2.0f32, 3.0, 6.0] {
            let q = SkyParams {
                elevation_deg: 0.0,
                azimuth_deg: 0.0,
                turbidity: t,
                intensity: 1.0,
            };
            let zen = luminance(sky_radiance(&q, Vec3::Y));
            let hor = luminance(sky_radiance(&q, Vec3::new(1.0, 1e-4, 0.0)));
            let (a, b) = (0.1787 * t as f64 - 1.4630, -0.3554 * t as f64 + 0.4275);
            let want = 1.0 / (1.0 + a * b.exp());
            println!(
                "T={t}: horizon/zenith luminance {:.3} (Perez gradation alone {want:.3})",
                hor / zen
            );
            assert!(((hor / zen) as f64 - want).abs() / want < 0.02, "T={t}");
            ratios.push(hor / zen);
        }
        assert!(ratios[0] > ratios[1] && ratios[1] > ratios[2] && ratios[2] > 1.0);
        // Hazier sky: brighter zenith, whiter (less blue) zenith colour.
        let clear = sky_radiance(
            &SkyParams {
                turbidity: 2.0,
                ..p
            },
            Vec3::Y,
        );
        let hazy = sky_radiance(
            &SkyParams {
                turbidity: 8.0,
                ..p
            },
            Vec3::Y,
        );
        assert!(luminance(hazy) > luminance(clear));
        assert!(hazy.z / hazy.x < clear.z / clear.x);
        // Zenith luminance for T = 3, θs = 55° from the paper's formula, by hand:
        // χ = (4/9 − 3/120)(π − 2·0.95993) = 0.51316, tan χ = 0.56287,
        // Y_z = (4.0453·3 − 4.9710)·0.56287 − 0.2155·3 + 2.4192 = 5.8029 kcd/m².
        let model = Preetham::new(&p);
        assert!(
            (model.zenith[0] - 5.8029).abs() < 2e-3,
            "{}",
            model.zenith[0]
        );
        assert!((luminance(sky_radiance(&p, Vec3::Y)) as f64 - 5.8029).abs() < 0.01);
        // Sun lower → redder and dimmer sun.
        let hi = sun_irradiance(&SkyParams {
            elevation_deg: 60.0,
            ..p
        });
        let lo = sun_irradiance(&SkyParams {
            elevation_deg: 5.0,
            ..p
        });
        assert!(lo.x / lo.z > hi.x / hi.z && lo.y < hi.y);
    }

    #[test]
    fn sun_sky_ratio_and_scale() {
        for t in [2.0, 3.0, 6.0] {
            for e in [10.0, 35.0, 60.0] {
                let q = SkyParams {
                    elevation_deg: e,
                    turbidity: t,
                    ..Default::default()
                };
                let sky_only = EnvMap::from_fn(256, 128, |d| sky_radiance(&q, d));
                let e_sky_h = luminance(irradiance(&sky_only, Vec3::Y));
                let e_sun = luminance(sun_irradiance(&q));
                println!(
                    "T={t} elevation {e}°: sun normal {e_sun:.1} klux, sky horizontal {e_sky_h:.1} klux, \
                     direct-normal/diffuse-horizontal {:.2}, diffuse fraction {:.2}",
                    e_sun / e_sky_h,
                    e_sky_h / (e_sky_h + e_sun * q.sun_direction().y)
                );
            }
        }
        let p = SkyParams::default();
        let env = render_sky(&p, 256, 128);
        let sky_only = EnvMap::from_fn(256, 128, |d| sky_radiance(&p, d));
        let e_sky_h = luminance(irradiance(&sky_only, Vec3::Y));
        let e_sun = luminance(sun_irradiance(&p));
        let e_sky_facing = luminance(irradiance(&sky_only, p.sun_direction()));
        println!(
            "defaults: sun on a sun-facing surface {e_sun:.1} klux vs sky on it {e_sky_facing:.1} klux (ratio {:.2}); \
             zenith {:.2} kcd/m², ground {:.2}",
            e_sun / e_sky_facing,
            luminance(sky_radiance(&p, Vec3::Y)),
            luminance(env.sample_dir(Vec3::NEG_Y))
        );
        // Plausible daylight: direct-normal / diffuse-horizontal between 2
        // (hazy) and 10 (very clear).
        let ratio = e_sun / e_sky_h;
        assert!((2.0..10.0).contains(&ratio), "{ratio}");
        // Ground = 0.3·(E_sky,h + E_sun·sin e)/π.
        let want = 0.3 * (e_sky_h + e_sun * p.sun_direction().y) / std::f32::consts::PI;
        let g = luminance(env.sample_dir(Vec3::NEG_Y));
        assert!((g - want).abs() / want < 0.01, "{g} vs {want}");
        // Scale: sky and ground values O(1..10) kcd/m².
        let z = luminance(sky_radiance(&p, Vec3::Y));
        assert!((0.5..20.0).contains(&z) && (0.5..20.0).contains(&g));
        // Intensity scales linearly.
        let env2 = render_sky(
            &SkyParams {
                intensity: 2.0,
                ..p
            },
            256,
            128,
        );
        let (a, b) = (env.mean(), env2.mean());
        assert!((b / a - Vec3::splat(2.0)).abs().max_element() < 1e-4);
    }

    #[test]
    fn tiny_maps_keep_sun_energy() {
        let p = SkyParams::default();
        let env = render_sky(&p, 8, 4);
        assert!(env.texels.iter().all(|t| t.is_finite()));
        let e = irradiance(&env, p.sun_direction());
        assert!(e.y > sun_irradiance(&p).y * 0.8, "{e}");
        let one = render_sky(&p, 0, 0);
        assert_eq!((one.width, one.height, one.texels.len()), (1, 1, 1));
    }
}
