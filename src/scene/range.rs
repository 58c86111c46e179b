//! What the half-float (RGBA16F) targets can hold: a scene whose lighting would
//! overflow them renders a wrong image, so it is refused at load, naming the
//! largest intensity that works.
//!
//! The bound: the irradiance any surface can receive is at most the map's
//! radiance integrated over the whole sphere, × `environment.intensity`, plus
//! every light's irradiance (a point light's at its nearest vertex). The
//! shading's targets hold sums of such terms (diffuse and specular, a highlight
//! that exceeds its light's irradiance), so the bound × [`SHADING_HEADROOM`]
//! must stay within [`HALF_MAX`]. The skybox shows the map's radiance ×
//! intensity as it is: texels beyond [`HALF_MAX`] (the built-in sky's sun)
//! saturate there, as a sun should; `-v` logs it.

use super::env::{texel_solid_angle_f64, EnvMap, HALF_MAX};
use super::file::SceneFile;
use super::mesh::Mesh;
use super::{Light, LightSource, POINT_LIGHT_REFERENCE_MM};

/// Factor between the irradiance bound and what the shading may write: diffuse
/// plus specular, and a specular peak of up to about twice the irradiance
/// (KS lobe at the skin's roughness), with room to spare.
pub const SHADING_HEADROOM: f64 = 4.0;

/// The map's brightest channel value and its radiance integrated over the
/// sphere (largest channel), before `environment.intensity`.
pub fn env_peaks(env: &EnvMap) -> (f64, f64) {
    let (mut peak, mut sum) = (0.0f64, [0.0f64; 3]);
    for y in 0..env.height {
        let sr = texel_solid_angle_f64(y, env.width, env.height);
        let row = &env.texels[(y * env.width) as usize..((y + 1) * env.width) as usize];
        for t in row {
            peak = peak.max(f64::from(t.max_element()));
            for (s, c) in sum.iter_mut().zip(t.to_array()) {
                *s += f64::from(c) * sr;
            }
        }
    }
    (peak, sum.into_iter().fold(0.0, f64::max))
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

/// Refuses a scene whose lighting may overflow the half-float targets (module
/// doc); logs (info) when the skybox's brightest texel would.
pub fn check(file: &SceneFile, env: &EnvMap, lights: &[Light], mesh: &Mesh) -> Result<(), String> {
    let budget = f64::from(HALF_MAX) / SHADING_HEADROOM;
    let intensity = f64::from(file.environment.intensity);
    let (peak, integral) = env_peaks(env);
    let per_light: Vec<f64> = lights.iter().map(|l| light_peak(l, mesh)).collect();
    let from_lights: f64 = per_light.iter().sum();
    let total = intensity * integral + from_lights;
    if file.render.skybox && intensity * peak > f64::from(HALF_MAX) {
        log::info!(
            "environment: its brightest texel ({peak:.4e}) × environment.intensity ({intensity}) \
             exceeds half-float's {HALF_MAX}: the skybox saturates there"
        );
    }
    if total <= budget && total.is_finite() {
        return Ok(());
    }
    let fmt = |v: f64| format!("{:.4e}", v.max(0.0));
    let largest = if intensity * integral >= from_lights {
        let rest = budget - from_lights;
        format!(
            "environment.intensity = {intensity} (the map integrates to {}): at most {} works",
            fmt(integral),
            fmt(rest / integral)
        )
    } else {
        let (i, own) =
            per_light
                .iter()
                .enumerate()
                .fold((0, 0.0), |a, (i, &v)| if v > a.1 { (i, v) } else { a });
        let rest = budget - (total - own);
        let intensity = f64::from(file.lights[i].intensity);
        format!(
            "lights[{i}].intensity = {intensity}: at most {} works",
            fmt(intensity * rest / own)
        )
    };
    Err(format!(
        "{largest}; the lighting would reach an irradiance of {} on the mesh, beyond \
         {HALF_MAX} (half-float targets) / {SHADING_HEADROOM} (headroom for the shading's sums)",
        fmt(total)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn a_uniform_map_integrates_to_four_pi() {
        let (peak, integral) = env_peaks(&EnvMap::uniform(Vec3::new(2.0, 1.0, 0.5), 64, 32));
        assert_eq!(peak, 2.0);
        assert!(
            (integral - 8.0 * std::f64::consts::PI).abs() < 1e-9,
            "{integral}"
        );
    }

    fn light(source: LightSource, irradiance: f32) -> Light {
        Light {
            source,
            irradiance: Vec3::splat(irradiance),
            shadow: true,
            angular_radius: 0.0,
        }
    }

    #[test]
    fn intensities_beyond_half_float_are_refused_naming_what_works() {
        let mesh = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X],
            ..Mesh::default()
        };
        let env = EnvMap::uniform(Vec3::ONE, 64, 32);
        let mut file = SceneFile {
            lights: vec![toml::from_str("kind = \"directional\"\ndirection = [0, -1, 0]").unwrap()],
            ..SceneFile::default()
        };
        let sun = [light(LightSource::Directional(Vec3::Y), 1.0)];
        assert!(check(&file, &env, &sun, &mesh).is_ok());

        // 4π × intensity × 4 > 65504 from intensity ≈ 1303.
        file.environment.intensity = 2000.0;
        let e = check(&file, &env, &sun, &mesh).unwrap_err();
        assert!(
            e.starts_with("environment.intensity = 2000") && e.contains("at most 1.30"),
            "{e}"
        );
        file.environment.intensity = 1.0;

        file.lights[0].intensity = 1e6;
        let e = check(
            &file,
            &env,
            &[light(LightSource::Directional(Vec3::Y), 1e6)],
            &mesh,
        )
        .unwrap_err();
        assert!(
            e.starts_with("lights[0].intensity = 1000000") && e.contains("at most 1.63"),
            "{e}"
        );

        // A point light 10 mm from the mesh delivers 10⁴ × its intensity.
        file.lights[0].intensity = 10.0;
        let near = [light(LightSource::Point(Vec3::new(0.0, 10.0, 0.0)), 10.0)];
        let e = check(&file, &env, &near, &mesh).unwrap_err();
        assert!(e.starts_with("lights[0].intensity = 10:"), "{e}");
    }
}
