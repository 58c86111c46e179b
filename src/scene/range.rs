//! Pre-exposure: the lighting scaled by a power of two before it reaches the
//! half-float (RGBA16F) targets, so that any finite intensity renders right
//! (the pre-exposed lights of Filament's PBR notes and of Lagarde & de
//! Rousiers 2014, "Moving Frostbite to PBR").
//!
//! The bound: the irradiance any surface can receive is at most the map's
//! largest cosine-weighted irradiance over all normals, × `environment.intensity`,
//! plus every light's irradiance (a point light's at its nearest vertex). Where
//! that bound lies within [[`LOW`], [`HIGH`]] the targets hold the light as it
//! is (P = 1: every such scene renders as before); elsewhere every light, the
//! environment and the skybox are × P = 2^k, the power of two that brings the
//! bound nearest [`TARGET`], and the results are read back ÷ P and the exposure
//! applied as EV − k, all exact in binary floating point. The map's own texels
//! get the same rule (its prefiltered copy is half float too): they are
//! uploaded × M and the environment's factor on the GPU is intensity·P/M.

use super::env::{texel_solid_angle_f64, EnvMap, HALF_MAX};
use super::file::SceneFile;
use super::mesh::Mesh;
use super::{Light, LightSource, POINT_LIGHT_REFERENCE_MM};

/// Factor between the irradiance bound and what the targets may hold: the
/// irradiance texture and the blur levels hold E × albedo^mix ≤ E, the screen
/// radiance E/π × albedo plus the specular term, whose KS lobe can rise above
/// E/π at grazing angles; 2 leaves room for it.
pub const SHADING_HEADROOM: f64 = 2.0;
/// The largest irradiance bound the targets hold as it is: [`HALF_MAX`] /
/// [`SHADING_HEADROOM`].
pub const HIGH: f64 = HALF_MAX as f64 / SHADING_HEADROOM;
/// The smallest: at 1/16 a pixel 2^-10 of the brightest still has a normal half
/// float (≥ 2^-14), so the 8-bit image keeps its levels.
pub const LOW: f64 = 1.0 / 16.0;
/// Where a pre-exposed bound lands: 16, 2^4 above [`LOW`] and 2^11 below [`HIGH`]
/// (dark pixels matter more than the specular's headroom).
pub const TARGET: f64 = 16.0;
/// The largest |exposure − log2 P| in EV: the targets' values × 2^±100 stay
/// finite and non-zero in f32 (65504 × 2^100 ≈ 8.3e34 < 3.4e38; 2^-24 × 2^-100
/// = 2^-124 is still a normal f32).
pub const MAX_EXPOSURE_EV: f32 = 100.0;

/// Cells of the grid the map is binned into for [`env_peaks`], and normals tried.
const GRID: (usize, usize) = (64, 32);
const NORMALS: usize = 1024;
/// For normals between those tried (≤ 3.5° from one: cos ≥ 0.998) and texels
/// within half a cell (≤ 2.9°) of their cell's centre.
const MARGIN: f64 = 1.01;

/// The scales a scene's light is rendered at (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PreExposure {
    /// P: the lights and the environment × P on the GPU, read back ÷ P.
    pub lighting: f32,
    /// M: the map's texels × M when uploaded.
    pub map: f32,
}

impl PreExposure {
    /// Light as it is.
    pub const NONE: PreExposure = PreExposure {
        lighting: 1.0,
        map: 1.0,
    };

    /// log2 P: the EV the targets are exposed by already.
    pub fn ev(&self) -> f32 {
        self.lighting.log2()
    }
}

/// 1 when `bound` lies within [LOW, HIGH] (or is 0), else the power of two that
/// brings it nearest TARGET; `None` when that is not a normal f32.
fn power_of_two_for(bound: f64) -> Option<f32> {
    if bound == 0.0 || (LOW..=HIGH).contains(&bound) {
        return Some(1.0);
    }
    let k = (TARGET / bound).log2().round();
    (k.abs() <= 126.0).then(|| (k as f32).exp2())
}

/// The map's brightest channel value, and the largest irradiance (channel) it
/// gives any surface, before `environment.intensity`: the largest over normals
/// n of ∫ L(ω) max(0, n·ω) dω, the map binned into a grid of cells and n tried
/// over a Fibonacci sphere, plus [`MARGIN`].
pub fn env_peaks(env: &EnvMap) -> (f64, f64) {
    let (gw, gh) = GRID;
    let mut cells = vec![[0.0f64; 3]; gw * gh];
    let mut peak = 0.0f64;
    for y in 0..env.height {
        let sr = texel_solid_angle_f64(y, env.width, env.height);
        let cy = y as usize * gh / env.height as usize;
        for x in 0..env.width {
            let t = env.texels[(y * env.width + x) as usize];
            peak = peak.max(f64::from(t.max_element()));
            let cell = &mut cells[cy * gw + x as usize * gw / env.width as usize];
            for (s, c) in cell.iter_mut().zip(t.to_array()) {
                *s += f64::from(c) * sr;
            }
        }
    }
    let centre = |i: usize| {
        let (u, v) = ((i % gw) as f32 + 0.5, (i / gw) as f32 + 0.5);
        super::env::direction(u / gw as f32, v / gh as f32)
    };
    let dirs: Vec<glam::Vec3> = (0..cells.len()).map(centre).collect();
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let mut most = 0.0f64;
    for k in 0..NORMALS {
        let z = 1.0 - 2.0 * (k as f64 + 0.5) / NORMALS as f64;
        let (r, phi) = ((1.0 - z * z).sqrt(), golden * k as f64);
        let n = glam::DVec3::new(r * phi.cos(), z, r * phi.sin());
        let mut e = [0.0f64; 3];
        for (cell, d) in cells.iter().zip(&dirs) {
            let c = n.dot(d.as_dvec3());
            if c > 0.0 {
                for (e, v) in e.iter_mut().zip(cell) {
                    *e += v * c;
                }
            }
        }
        most = most.max(e.into_iter().fold(0.0, f64::max));
    }
    (peak, most * MARGIN)
}

/// A light's largest irradiance channel on the mesh (unshadowed, a point light
/// at its nearest vertex, 1 mm at least).
fn light_peak(light: &Light, mesh: &Mesh) -> f64 {
    let scale = match light.source {
        LightSource::Directional(_) => 1.0,
        LightSource::Point(p) => {
            let d2 = mesh
                .positions
                .iter()
                .map(|x| f64::from(x.distance_squared(p)))
                .fold(f64::INFINITY, f64::min)
                .max(1.0);
            f64::from(POINT_LIGHT_REFERENCE_MM).powi(2) / d2
        }
    };
    f64::from(light.irradiance.max_element()) * scale
}

/// The pre-exposure of a scene (module doc). Refuses, naming the key, only a
/// scene whose light no normal f32 power of two brings into range, or an
/// exposure beyond [`MAX_EXPOSURE_EV`] of it; logs (info) when the skybox's
/// brightest texel saturates.
pub fn pre_exposure(
    file: &SceneFile,
    env: &EnvMap,
    lights: &[Light],
    mesh: &Mesh,
) -> Result<PreExposure, String> {
    let intensity = f64::from(file.environment.intensity);
    let (peak, env_irradiance) = env_peaks(env);
    let total =
        intensity * env_irradiance + lights.iter().map(|l| light_peak(l, mesh)).sum::<f64>();
    let fmt = |v: f64| format!("{v:.4e}");
    let lighting = power_of_two_for(total).ok_or_else(|| {
        format!(
            "the lighting reaches an irradiance of {} on the mesh (environment {} × \
             environment.intensity = {:e}, and the lights): no power of two within \
             2^±126 brings it into what half floats hold",
            fmt(total),
            file.environment.source,
            file.environment.intensity
        )
    })?;
    let map = power_of_two_for(env_irradiance).ok_or_else(|| {
        format!(
            "environment {}: its irradiance {} is beyond what half floats hold by more than 2^±126",
            file.environment.source,
            fmt(env_irradiance)
        )
    })?;
    let p = PreExposure { lighting, map };
    if file.render.skybox && intensity * peak * f64::from(lighting) > f64::from(HALF_MAX) {
        log::info!(
            "environment: its brightest texel ({peak:.4e}) × environment.intensity ({}) \
             × pre-exposure {lighting} exceeds half-float's {HALF_MAX}: the skybox saturates there",
            file.environment.intensity
        );
    }
    if lighting != 1.0 || map != 1.0 {
        log::info!(
            "pre-exposure: the lighting's bound {} × {lighting} (2^{}), the map × {map}",
            fmt(total),
            p.ev()
        );
    }
    if let Some(e) = file.render.exposure {
        let applied = e - p.ev();
        if applied.abs() > MAX_EXPOSURE_EV {
            return Err(format!(
                "render.exposure = {e}: must be in {}..={} EV for this scene's light (an \
                 irradiance of {}, pre-exposed by 2^{}); beyond, what the half-float targets \
                 hold becomes inf or 0 in 32-bit floats",
                p.ev() - MAX_EXPOSURE_EV,
                p.ev() + MAX_EXPOSURE_EV,
                fmt(total),
                p.ev()
            ));
        }
    }
    Ok(p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn a_uniform_map_gives_pi_times_its_radiance() {
        // ∫ L max(0, n·ω) dω = π L for a uniform map, whatever the normal.
        let (peak, e) = env_peaks(&EnvMap::uniform(Vec3::new(2.0, 1.0, 0.5), 64, 32));
        assert_eq!(peak, 2.0);
        let want = 2.0 * std::f64::consts::PI * MARGIN;
        assert!((e - want).abs() < 0.01 * want, "{e} against {want}");
    }

    fn light(source: LightSource, irradiance: f32) -> Light {
        Light {
            source,
            irradiance: Vec3::splat(irradiance),
            shadow: true,
            angular_radius: 0.0,
        }
    }

    fn file_with_a_sun() -> SceneFile {
        SceneFile {
            lights: vec![toml::from_str("kind = \"directional\"\ndirection = [0, -1, 0]").unwrap()],
            ..SceneFile::default()
        }
    }

    #[test]
    fn light_within_what_half_floats_hold_is_not_pre_exposed() {
        let mesh = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X],
            ..Mesh::default()
        };
        let mut file = file_with_a_sun();
        let sun = [light(LightSource::Directional(Vec3::Y), 1.0)];
        for (map, intensity) in [(1.0, 1.0), (1.0, 0.02), (1e3, 10.0)] {
            file.environment.intensity = intensity;
            let env = EnvMap::uniform(Vec3::splat(map), 64, 32);
            assert_eq!(
                pre_exposure(&file, &env, &sun, &mesh),
                Ok(PreExposure::NONE),
                "{map} × {intensity}"
            );
        }
    }

    #[test]
    fn light_beyond_it_is_brought_to_the_target_by_a_power_of_two() {
        let mesh = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X],
            ..Mesh::default()
        };
        let env = EnvMap::uniform(Vec3::ONE, 64, 32);
        let mut file = file_with_a_sun();
        let sun = |e: f32| [light(LightSource::Directional(Vec3::Y), e)];
        // The bound is π·1.01·intensity + the sun's irradiance.
        let bound = |i: f64, s: f64| std::f64::consts::PI * MARGIN * i + s;
        for (intensity, s) in [
            (3e4, 1.0),
            (1e-30, 0.0),
            (1e30, 0.0),
            (1e-6, 0.0),
            (1.0, 1e6),
        ] {
            file.environment.intensity = intensity as f32;
            let p = pre_exposure(&file, &env, &sun(s as f32), &mesh).unwrap();
            let k = p.ev();
            assert_eq!(k, k.round(), "{intensity}: P = 2^{k}");
            let pre = bound(f64::from(intensity as f32), s) * f64::from(p.lighting);
            assert!(
                pre > TARGET / 2f64.sqrt() && pre < TARGET * 2f64.sqrt(),
                "{intensity}, {s}: {pre} against {TARGET}"
            );
            assert_eq!(p.map, 1.0);
        }
        // The map's own scale: uniform:1e5 is uploaded × 2^-14.
        let bright = EnvMap::uniform(Vec3::splat(1e5), 64, 32);
        file.environment.intensity = 1.0;
        let p = pre_exposure(&file, &bright, &[], &mesh).unwrap();
        assert_eq!((p.map, p.lighting), (2f32.powi(-14), 2f32.powi(-14)));
    }

    #[test]
    fn an_exposure_beyond_floats_of_the_pre_exposed_light_is_refused() {
        let mesh = Mesh {
            positions: vec![Vec3::ZERO],
            ..Mesh::default()
        };
        let env = EnvMap::uniform(Vec3::ONE, 64, 32);
        let mut file = SceneFile::default();
        file.render.exposure = Some(150.0);
        let e = pre_exposure(&file, &env, &[], &mesh).unwrap_err();
        assert!(
            e.starts_with("render.exposure = 150: must be in -100..=100 EV"),
            "{e}"
        );
        // At 1e-30 the light is pre-exposed by 2^102, and 150 EV is within 100 of it.
        file.environment.intensity = 1e-30;
        let p = pre_exposure(&file, &env, &[], &mesh).unwrap();
        assert_eq!(p.ev(), 102.0);
    }

    #[test]
    fn light_no_normal_power_of_two_brings_into_range_is_refused_naming_it() {
        let mesh = Mesh {
            positions: vec![Vec3::ZERO],
            ..Mesh::default()
        };
        let env = EnvMap::uniform(Vec3::ONE, 64, 32);
        let mut file = SceneFile::default();
        // π·1.01·1e-38 ≈ 3.2e-38: 16 over it is 2^129, past f32's 2^127.
        file.environment.intensity = 1e-38;
        let e = pre_exposure(&file, &env, &[], &mesh).unwrap_err();
        assert!(
            e.starts_with("the lighting reaches an irradiance of 3.1751e-38")
                && e.contains("environment.intensity = 1e-38")
                && e.contains("no power of two within 2^±126"),
            "{e}"
        );
        // The map's own texels: 1e-38 of radiance, × an intensity that brings
        // the lighting into range.
        file.environment.intensity = 1e30;
        let faint = EnvMap::uniform(Vec3::splat(1e-38), 64, 32);
        let e = pre_exposure(&file, &faint, &[], &mesh).unwrap_err();
        assert!(e.starts_with("environment sky"), "{e}");
    }
}
