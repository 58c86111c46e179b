//! SH projection on the GPU against the CPU reference (light::sh::project), on the
//! CC0 maps, the built-in sky (a sun disk ~1e6 bright) and with rotation.

use crate::common;

use dermis::light::{sh, sh_pass};
use dermis::scene::env::{self as envmap, sky, EnvMap};
use glam::Vec3;

fn compare(name: &str, env: &EnvMap, rotation: f32, intensity: f32) {
    let want = sh::rotate_y(&sh::project(env), rotation).map(|c| c * intensity);
    let (got, report) =
        common::with_gpu(|ctx| sh_pass::project(ctx, env, rotation, intensity).unwrap());
    let scale = want[0].max_element();
    let worst = got
        .iter()
        .zip(&want)
        .map(|(g, w)| ((*g - *w).abs() / scale).max_element())
        .fold(0.0f32, f32::max);
    println!(
        "{name}: max |GPU - CPU| / L00 = {worst:.2e}; sh_project {:.2} ms, sh_reduce {:.2} ms",
        report.pass_ns("sh_project").unwrap_or(0.0) / 1e6,
        report.pass_ns("sh_reduce").unwrap_or(0.0) / 1e6
    );
    assert!(worst < 1e-4, "{name}: {worst}");
}

#[test]
fn gpu_projection_matches_the_cpu_reference() {
    let sky_map = sky::render_sky(&sky::SkyParams::default(), 1024, 512);
    compare("sky", &sky_map, 0.0, 1.0);
    compare("sky rotated 37.5°, intensity 2", &sky_map, 37.5, 2.0);
    let uniform = EnvMap::uniform(Vec3::new(0.25, 0.5, 1.0), 256, 128);
    compare("uniform", &uniform, 0.0, 1.0);
    for name in dermis::assets::ENV_MAPS {
        let (env, _) = envmap::load(&dermis::assets::path(&format!("env/{name}"))).unwrap();
        compare(name, &env, -120.0, 1.0);
    }
}
