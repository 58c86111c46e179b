//! The GPU specular term against the CPU implementation of the KS BRDF
//! (skin::specular::ks_brdf, the paper's eq. 1): a sphere under one directional
//! light, `--view specular`, pixel by pixel.

mod common;

use dermis::light::envmap::EnvMap;
use dermis::render::{render_scene, RenderOptions, View};
use dermis::scene::camera::Camera;
use dermis::scene::file::{Occlusion, SceneFile};
use dermis::scene::mesh::Mesh;
use dermis::scene::texture::{Encoding, Texture};
use dermis::scene::{DirectionalLight, Scene};
use dermis::skin::specular::{ks_brdf, DEFAULT_M, DEFAULT_RHO_S};
use glam::{Vec2, Vec3, Vec4};

const R: f32 = 60.0; // mm
const SIZE: u32 = 256;

fn sphere(slices: u32, stacks: u32) -> Mesh {
    let mut m = Mesh {
        name: "sphere".into(),
        ..Mesh::default()
    };
    for j in 0..=stacks {
        for i in 0..=slices {
            let (u, v) = (i as f32 / slices as f32, j as f32 / stacks as f32);
            let (phi, theta) = (u * std::f32::consts::TAU, v * std::f32::consts::PI);
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            m.positions.push(n * R);
            m.normals.push(n);
            m.uvs.push(Vec2::new(u, v));
            m.tangents.push(Vec4::new(-phi.sin(), 0.0, phi.cos(), 1.0));
        }
    }
    let row = slices + 1;
    for j in 0..stacks {
        for i in 0..slices {
            let (a, b) = (j * row + i, (j + 1) * row + i);
            m.indices.extend([a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    m
}

#[test]
fn specular_matches_the_cpu_brdf_on_a_sphere() {
    let light = DirectionalLight {
        direction: Vec3::new(0.4, 0.5, 1.0).normalize(),
        // Bright enough that the lobe's tails stay above f16's smallest normal
        // (6.1e-5), which the RGBA16F target would flush to zero.
        irradiance: Vec3::splat(200.0),
    };
    let mut file = SceneFile::default();
    file.skin.occlusion = Occlusion::Off;
    file.render.width = SIZE;
    file.render.height = SIZE;
    file.render.irradiance_resolution = 256;
    file.render.exposure = Some(0.0);
    let grey = |v: u8| Texture::solid([v, v, v, 255], Encoding::Linear);
    let camera = Camera::orbit_at(Vec3::ZERO, 0.0, 0.0, 400.0, 30.0);
    let scene = Scene {
        mesh: sphere(192, 96),
        albedo: Texture::solid([128, 128, 128, 255], Encoding::Srgb),
        normal: Texture::solid([128, 128, 255, 255], Encoding::Linear),
        specular: grey(255),
        roughness: grey(77),
        regions: grey(0),
        env: EnvMap::uniform(Vec3::ZERO, 64, 32),
        camera,
        lights: vec![light],
        file,
    };
    let img = common::with_gpu(|ctx| {
        let opts = RenderOptions {
            view: View::Specular,
            hdr: true,
            ..RenderOptions::default()
        };
        render_scene(ctx, &scene, &opts).unwrap().hdr.unwrap()
    });
    // The CPU reference: intersect each pixel's ray with the analytic sphere.
    let inv = camera.view_projection(1.0).inverse();
    let mut expected = vec![None; (SIZE * SIZE) as usize];
    for y in 0..SIZE {
        for x in 0..SIZE {
            let ndc = |z| {
                let p = Vec2::new(
                    (x as f32 + 0.5) / SIZE as f32,
                    (y as f32 + 0.5) / SIZE as f32,
                ) * 2.0
                    - 1.0;
                inv.project_point3(Vec3::new(p.x, p.y, z))
            };
            let (o, d) = (camera.position, (ndc(1.0) - ndc(0.0)).normalize());
            let b = o.dot(d);
            let disc = b * b - (o.length_squared() - R * R);
            if disc <= 0.0 {
                continue;
            }
            let p = o + d * (-b - disc.sqrt());
            let (n, v) = (p.normalize(), (o - p).normalize());
            if n.dot(v) < 0.3 {
                continue; // stay away from the silhouette
            }
            let f = ks_brdf(n, light.direction, v, DEFAULT_M, DEFAULT_RHO_S) * light.irradiance.x;
            expected[(y * SIZE + x) as usize] = Some(f);
        }
    }
    let peak = expected.iter().flatten().fold(0.0f32, |a, &b| a.max(b));
    let (mut worst, mut n) = (0.0f32, 0);
    for (i, e) in expected.iter().enumerate() {
        let Some(e) = *e else { continue };
        let got = img[i * 4];
        // 1 % relative plus one 8-bit step of the peak (the allowance for 8-bit output).
        let excess = (got - e).abs() - (0.01 * e + peak / 255.0);
        worst = worst.max((got - e).abs() / peak);
        assert!(
            excess <= 0.0,
            "pixel {i}: GPU {got} vs CPU {e} (peak {peak})"
        );
        n += 1;
    }
    println!("{n} pixels: peak {peak:.4}, max |GPU - CPU| / peak {worst:.4}");
    assert!(n > 10_000 && peak > 0.0);
}
