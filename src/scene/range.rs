//! What the half-float (RGBA16F) targets can hold: a scene whose lighting would
//! overflow them renders a wrong image, so it is refused at load, naming the
//! largest intensity that works.
//!
//! The bound: the irradiance any surface can receive is at most the map's
//! largest cosine-weighted irradiance over all normals, × `environment.intensity`,
//! plus every light's irradiance (a point light's at its nearest vertex). The
//! targets hold about that irradiance at most, so it × [`SHADING_HEADROOM`]
//! must stay within [`HALF_MAX`]. The skybox shows the map's radiance ×
//! intensity as it is: texels beyond [`HALF_MAX`] (the built-in sky's sun)
//! saturate there, as a sun should; `-v` logs it.

use super::env::{texel_solid_angle_f64, EnvMap, HALF_MAX};
use super::file::SceneFile;
use super::mesh::Mesh;
use super::{Light, LightSource, POINT_LIGHT_REFERENCE_MM};

/// Factor between the irradiance bound and what the targets may hold: the
/// irradiance texture and the blur levels hold E × albedo^mix ≤ E, the screen
/// radiance E/π × albedo plus the specular term, whose KS lobe can rise above
/// E/π at grazing angles; 2 leaves room for it.
pub const SHADING_HEADROOM: f64 = 2.0;

/// Cells of the grid the map is binned into for [`env_peaks`], and normals tried.
const GRID: (usize, usize) = (64, 32);
const NORMALS: usize = 1024;
/// For normals between those tried (≤ 3.5° from one: cos ≥ 0.998) and texels
/// within half a cell (≤ 2.9°) of their cell's centre.
const MARGIN: f64 = 1.01;

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

/// Refuses a scene whose lighting may overflow the half-float targets (module
/// doc); logs (info) when the skybox's brightest texel would.
pub fn check(file: &SceneFile, env: &EnvMap, lights: &[Light], mesh: &Mesh) -> Result<(), String> {
    let budget = f64::from(HALF_MAX) / SHADING_HEADROOM;
    let intensity = f64::from(file.environment.intensity);
    let (peak, env_irradiance) = env_peaks(env);
    let per_light: Vec<f64> = lights.iter().map(|l| light_peak(l, mesh)).collect();
    let from_lights: f64 = per_light.iter().sum();
    let total = intensity * env_irradiance + from_lights;
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
    let largest = if intensity * env_irradiance >= from_lights {
        let rest = budget - from_lights;
        format!(
            "environment {} is too bright: its radiance reaches {} and gives at most {} of \
             irradiance, × environment.intensity = {intensity}; at most environment.intensity \
             = {} works with it (or a source {}× as bright)",
            file.environment.source,
            fmt(peak),
            fmt(env_irradiance),
            fmt(rest / env_irradiance),
            match rest / (intensity * env_irradiance) {
                r if r >= 1e-3 => format!("{r:.3}"),
                r => format!("{:.3e}", r.max(0.0)),
            }
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
         {HALF_MAX} (half-float targets) / {SHADING_HEADROOM} (headroom for the specular term)",
        fmt(total)
    ))
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

        // (π × 1.01 × intensity + 1) × 2 > 65504 from intensity ≈ 1.032e4.
        file.environment.intensity = 3e4;
        let e = check(&file, &env, &sun, &mesh).unwrap_err();
        assert!(
            e.starts_with("environment sky:")
                && e.contains("is too bright")
                && e.contains("or a source 0.344× as bright")
                && e.contains("environment.intensity = 30000")
                && e.contains("at most environment.intensity = 1.03"),
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
            e.starts_with("lights[0].intensity = 1000000") && e.contains("at most 3.27"),
            "{e}"
        );

        // A point light 10 mm from the mesh delivers 10⁴ × its intensity.
        file.lights[0].intensity = 10.0;
        let near = [light(LightSource::Point(Vec3::new(0.0, 10.0, 0.0)), 10.0)];
        let e = check(&file, &env, &near, &mesh).unwrap_err();
        assert!(e.starts_with("lights[0].intensity = 10:"), "{e}");
    }
}
