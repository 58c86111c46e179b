//! The reference of `--view direct`: `albedo/π · E` on the mesh, seen through
//! the scene's camera, with the environment (or transparent black) behind.
//!
//! Mirrors the GPU's conventions:
//! - pixel `(i, j)` (row 0 at the top) samples NDC `((i + ½)/W·2 − 1, (j + ½)/H·2 − 1)`
//!   of `Camera::view_projection(W/H)`, Vulkan's clip space with +y down and a
//!   viewport of the whole target (`graph/execute.rs`); its ray runs from the
//!   near plane (depth 0) to the far plane (depth 1), so clipping matches too;
//! - on the mesh (`mesh_lit.vert`, `forward.frag`): the closest hit's
//!   barycentrics interpolate position, vertex normal, UV and tangent (rays give
//!   the perspective-correct weights); the shading normal is the vertex normal,
//!   or (`Settings::normal_map`) the normal map decoded as
//!   `common/normal_map.glsl` does, flipped when the interpolated vertex normal
//!   lies on the far side of the triangle from the camera; alpha 1;
//! - behind it (`background.frag`, `light/skybox.rs`) with `render.skybox`: the
//!   environment bilinearly sampled along the ray through the far plane,
//!   `env_dir`-rotated, × intensity, alpha 0 (alpha is the coverage); without:
//!   (0, 0, 0, 0);
//! - the first `frame_inputs::MAX_LIGHTS` lights, as the GPU uploads.
//!
//! The albedo is read at mip level 0 where the GPU filters trilinearly across
//! its mips, so pixels covering many texels differ by that filtering.

use std::f32::consts::PI;
use std::time::Instant;

use glam::{Vec2, Vec3, Vec4, Vec4Swizzles};
use rayon::prelude::*;

use super::integrate::{Integrator, Settings};
use super::texture;
use crate::error::{Error, Result};
use crate::frame_inputs::MAX_LIGHTS;
use crate::light::occlusion::Hit;
use crate::scene::env::direction_to_uv;
use crate::scene::texture::Texture;
use crate::scene::Scene;

/// A reference image and how well it converged.
#[derive(Clone, Debug)]
pub struct ReferenceImage {
    pub width: u32,
    pub height: u32,
    /// Linear RGBA, row-major, top row first (the layout of the GPU's HDR readback).
    pub rgba: Vec<f32>,
    /// Pixels the mesh covers.
    pub mesh_pixels: u32,
    /// Fraction of mesh pixels whose estimate reached `Settings::target_rel_err`.
    pub converged: f32,
    /// Mean relative standard error over mesh pixels.
    pub mean_rel_std_err: f32,
    /// Directions sampled over all mesh pixels.
    pub samples: u64,
    /// Wall-clock time of the call (BVH and sampler construction included).
    pub seconds: f64,
}

/// One row's pixels and statistics.
struct Row {
    rgba: Vec<f32>,
    mesh_pixels: u32,
    converged: u32,
    rel_sum: f64,
    samples: u64,
}

/// The reference of `--view direct` for `scene` at `width × height` (module
/// doc): one BVH and one environment distribution for the call, rows in
/// parallel, pixel `k = j·W + i` with its own random stream. Input error for an
/// empty size or an invalid mesh.
pub fn render_view(
    scene: &Scene,
    width: u32,
    height: u32,
    settings: &Settings,
) -> Result<ReferenceImage> {
    render_view_with(scene, width, height, settings, &|| {})
}

/// [`render_view`], calling `row_done` as each row completes (from any thread).
pub fn render_view_with(
    scene: &Scene,
    width: u32,
    height: u32,
    settings: &Settings,
    row_done: &(dyn Fn() + Sync),
) -> Result<ReferenceImage> {
    let started = Instant::now();
    if width == 0 || height == 0 {
        return Err(Error::Input(format!(
            "reference image size {width}×{height}"
        )));
    }
    scene.mesh.validate().map_err(Error::Input)?;
    let environment = &scene.file.environment;
    let lights = &scene.lights[..scene.lights.len().min(MAX_LIGHTS)];
    let integrator = Integrator::new(
        &scene.mesh,
        &scene.env,
        environment.rotation_deg,
        environment.intensity,
        lights,
        settings,
    );
    let inv_view_proj = scene
        .camera
        .view_projection(width as f32 / height as f32)
        .inverse();
    let rows: Vec<Row> = (0..height)
        .into_par_iter()
        .map(|j| {
            let mut row = Row {
                rgba: Vec::with_capacity(4 * width as usize),
                mesh_pixels: 0,
                converged: 0,
                rel_sum: 0.0,
                samples: 0,
            };
            for i in 0..width {
                let ndc = Vec2::new(
                    (i as f32 + 0.5) / width as f32 * 2.0 - 1.0,
                    (j as f32 + 0.5) / height as f32 * 2.0 - 1.0,
                );
                let near = inv_view_proj.project_point3(ndc.extend(0.0));
                let far = inv_view_proj.project_point3(ndc.extend(1.0));
                let colour = match integrator.bvh().closest_hit(near, far - near, 1.0) {
                    Some(hit) => {
                        let index = u64::from(j) * u64::from(width) + u64::from(i);
                        let (colour, rel, samples) =
                            shade(scene, &integrator, settings, &hit, index);
                        row.mesh_pixels += 1;
                        row.converged += u32::from(rel <= settings.target_rel_err);
                        row.rel_sum += f64::from(rel);
                        row.samples += u64::from(samples);
                        colour
                    }
                    None if scene.file.render.skybox => {
                        let d = integrator.to_env(far - scene.camera.position);
                        let radiance = texture::env(&scene.env, direction_to_uv(d));
                        (radiance * environment.intensity).extend(0.0)
                    }
                    None => Vec4::ZERO,
                };
                row.rgba.extend(colour.to_array());
            }
            row_done();
            row
        })
        .collect();
    let mesh_pixels: u32 = rows.iter().map(|r| r.mesh_pixels).sum();
    let per_pixel = |v: f64| (v / f64::from(mesh_pixels.max(1))) as f32;
    Ok(ReferenceImage {
        width,
        height,
        mesh_pixels,
        converged: per_pixel(rows.iter().map(|r| f64::from(r.converged)).sum()),
        mean_rel_std_err: per_pixel(rows.iter().map(|r| r.rel_sum).sum()),
        samples: rows.iter().map(|r| r.samples).sum(),
        rgba: rows.into_iter().flat_map(|r| r.rgba).collect(),
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// `albedo/π · E` at a hit (alpha 1), the estimate's relative error and samples.
fn shade(
    scene: &Scene,
    integrator: &Integrator,
    settings: &Settings,
    hit: &Hit,
    index: u64,
) -> (Vec4, f32, u32) {
    let mesh = &scene.mesh;
    let k = 3 * hit.triangle as usize;
    let [i0, i1, i2] = [0, 1, 2].map(|c| mesh.indices[k + c] as usize);
    let b = hit.barycentric;
    let x = mesh.positions[i0] * b.x + mesh.positions[i1] * b.y + mesh.positions[i2] * b.z;
    let normal = mesh.normals[i0] * b.x + mesh.normals[i1] * b.y + mesh.normals[i2] * b.z;
    let uv = mesh.uvs[i0] * b.x + mesh.uvs[i1] * b.y + mesh.uvs[i2] * b.z;
    let tangent = mesh.tangents[i0] * b.x + mesh.tangents[i1] * b.y + mesh.tangents[i2] * b.z;
    let edges = (
        mesh.positions[i1] - mesh.positions[i0],
        mesh.positions[i2] - mesh.positions[i0],
    );
    let geometric = edges.0.cross(edges.1).normalize();
    let mut n = if settings.normal_map {
        map_normal(&scene.normal, uv, normal, tangent)
    } else {
        normal.normalize_or(geometric)
    };
    // Two-sided, as forward.frag: the back is seen where the interpolated
    // vertex normal lies on the far side of the hit triangle's plane. (Not
    // where it faces away from the camera: at a closed surface's silhouette
    // it may, on the front.)
    let toward_camera = geometric * geometric.dot(scene.camera.position - x).signum();
    let side = if normal.dot(toward_camera) < 0.0 {
        n = -n;
        -1.0
    } else {
        1.0
    };
    // Shadow rays leave from the smooth surface the vertex normals describe,
    // not the flat triangle, else smooth shading shows the facets where a
    // light grazes them (the shadow terminator; Hanika 2021, "Hacking the
    // shadow terminator"): x is lifted to each corner's tangent plane where it
    // lies below it, blended barycentrically.
    let lift: Vec3 = [(i0, b.x), (i1, b.y), (i2, b.z)]
        .iter()
        .map(|&(i, w)| {
            let ni = mesh.normals[i].normalize_or_zero() * side;
            -w * (x - mesh.positions[i]).dot(ni).min(0.0) * ni
        })
        .sum();
    let e = integrator.irradiance(x + lift, n, geometric, index);
    let albedo = texture::rgba8(&scene.albedo, uv).xyz();
    (
        (albedo / PI * e.value).extend(1.0),
        e.rel_std_err,
        e.samples,
    )
}

/// `map_normal` of `common/normal_map.glsl`: x, y decode as (255·c − 128)/127
/// (128 is flat), z as 2c − 1, in the frame of the tangent orthogonalised
/// against the normal and the bitangent `cross(n, t)·w`.
fn map_normal(map: &Texture, uv: Vec2, normal: Vec3, tangent: Vec4) -> Vec3 {
    let n = normal.normalize_or_zero();
    let t = (tangent.xyz() - n * n.dot(tangent.xyz())).normalize_or_zero();
    let b = n.cross(t) * tangent.w;
    let c = texture::rgba8(map, uv);
    let m = Vec3::new(
        (c.x * 255.0 - 128.0) / 127.0,
        (c.y * 255.0 - 128.0) / 127.0,
        c.z * 2.0 - 1.0,
    );
    (m.x * t + m.y * b + m.z * n).normalize_or(n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::reference::test_meshes::sphere;
    use crate::scene::camera::Camera;
    use crate::scene::env::EnvMap;
    use crate::scene::file::SceneFile;
    use crate::scene::texture::{Encoding, FLAT_NORMAL};

    const SKY: Vec3 = Vec3::new(0.2, 0.5, 1.0);

    /// A 50 mm sphere of `rings` × `segments` above the camera's target under
    /// a uniform sky, grey albedo.
    fn sphere_scene(skybox: bool, rings: u32, segments: u32) -> Scene {
        let mut mesh = sphere(50.0, rings, segments);
        for p in &mut mesh.positions {
            *p += Vec3::Y * 60.0;
        }
        let solid = |rgba, encoding| Texture::solid(rgba, encoding);
        let mut file = SceneFile::default();
        file.render.skybox = skybox;
        Scene {
            mesh,
            albedo: solid([188, 188, 188, 255], Encoding::Srgb),
            normal: solid(FLAT_NORMAL, Encoding::Linear),
            specular: solid([255; 4], Encoding::Linear),
            roughness: solid([77, 77, 77, 255], Encoding::Linear),
            regions: solid([0, 0, 0, 255], Encoding::Linear),
            env: EnvMap::uniform(SKY, 64, 32),
            camera: Camera {
                position: Vec3::new(0.0, 0.0, 400.0),
                target: Vec3::ZERO,
                up: Vec3::Y,
                fov_y_deg: 30.0,
                near_mm: 1.0,
                far_mm: 5000.0,
            },
            lights: Vec::new(),
            pre_exposure: crate::scene::range::PreExposure::NONE,
            file,
        }
    }

    /// Whether the ray through the centre of pixel (i, j) of a `w × h` image
    /// meets the sphere of `sphere_scene`, worked out from the camera's
    /// definition (row 0 at the top, vertical field of view, square pixels)
    /// rather than from its matrices; `None` within `margin` of the silhouette.
    fn sees_sphere(i: u32, j: u32, w: u32, h: u32, margin: f32) -> Option<bool> {
        let tan = 15f32.to_radians().tan();
        let x = ((i as f32 + 0.5) / w as f32 * 2.0 - 1.0) * tan * w as f32 / h as f32;
        let y = (1.0 - (j as f32 + 0.5) / h as f32 * 2.0) * tan;
        let dir = Vec3::new(x, y, -1.0).normalize();
        let to_centre = Vec3::new(0.0, 60.0, -400.0);
        let angle = dir.angle_between(to_centre);
        let radius = (50.0 / to_centre.length()).asin();
        if (angle - radius).abs() < margin * radius {
            None
        } else {
            Some(angle < radius)
        }
    }

    #[test]
    fn sphere_under_a_uniform_sky() {
        let (w, h) = (64, 48);
        let albedo = Vec3::splat(((188.0 / 255.0 + 0.055) / 1.055f32).powf(2.4));
        for skybox in [true, false] {
            let scene = sphere_scene(skybox, 24, 48);
            let image = render_view(&scene, w, h, &Settings::default()).unwrap();
            let (mut worst, mut sum_sq, mut checked) = (0.0f32, 0.0f32, 0);
            for j in 0..h {
                for i in 0..w {
                    let p = Vec4::from_slice(&image.rgba[4 * (j * w + i) as usize..]);
                    // Polygon edges lie inside the sphere: 3 % margin at the silhouette.
                    match sees_sphere(i, j, w, h, 0.03) {
                        // Every point of the convex sphere sees the whole sky.
                        Some(true) => {
                            let err = ((p.xyz() - albedo * SKY) / (albedo * SKY))
                                .abs()
                                .max_element();
                            worst = worst.max(err);
                            sum_sq += err * err;
                            assert_eq!(p.w, 1.0);
                            checked += 1;
                        }
                        Some(false) if skybox => {
                            assert!((p - SKY.extend(0.0)).abs().max_element() < 1e-6, "{p}")
                        }
                        Some(false) => assert_eq!(p, Vec4::ZERO),
                        None => {}
                    }
                }
            }
            let rms = (sum_sq / checked as f32).sqrt();
            println!(
                "sphere, skybox {skybox}: {checked} mesh pixels off albedo·L by {:.3} % rms, \
                 {:.3} % at worst; {} mesh pixels, {:.0} % converged, mean reported {:.3} %, {:.2} s",
                100.0 * rms,
                100.0 * worst,
                image.mesh_pixels,
                100.0 * image.converged,
                100.0 * image.mean_rel_std_err,
                image.seconds
            );
            // Each pixel's standard error is ≤ 0.5 %; the worst of ~400 lies a
            // few of those out.
            assert!(
                checked > 200 && rms < 0.005 && worst < 0.015,
                "{rms} {worst}"
            );
            assert_eq!(image.converged, 1.0);
        }
    }

    #[test]
    fn a_polyhedrons_silhouette_is_its_front() {
        // Near a polyhedron's silhouette the interpolated vertex normal may face
        // away from the camera on a face that faces it: the front, which sees
        // the whole sky. Taken for the back, its hemisphere would lie inside.
        let scene = sphere_scene(false, 4, 8);
        let (w, h) = (96, 72);
        let image = render_view(&scene, w, h, &Settings::default()).unwrap();
        let integrator =
            Integrator::new(&scene.mesh, &scene.env, 0.0, 1.0, &[], &Settings::default());
        let inv = scene.camera.view_projection(w as f32 / h as f32).inverse();
        let albedo = Vec3::splat(((188.0 / 255.0 + 0.055) / 1.055f32).powf(2.4));
        let (mut leaning_away, mut darkest) = (0, f32::INFINITY);
        for j in 0..h {
            for i in 0..w {
                let p = Vec4::from_slice(&image.rgba[4 * (j * w + i) as usize..]);
                if p.w == 0.0 {
                    continue;
                }
                darkest = darkest.min((p.xyz() / (albedo * SKY)).min_element());
                let ndc = Vec2::new(
                    (i as f32 + 0.5) / w as f32 * 2.0 - 1.0,
                    (j as f32 + 0.5) / h as f32 * 2.0 - 1.0,
                );
                let near = inv.project_point3(ndc.extend(0.0));
                let far = inv.project_point3(ndc.extend(1.0));
                let hit = integrator.bvh().closest_hit(near, far - near, 1.0).unwrap();
                let m = &scene.mesh;
                let k = 3 * hit.triangle as usize;
                let b = hit.barycentric;
                let [n0, n1, n2] = [0, 1, 2].map(|c| m.normals[m.indices[k + c] as usize]);
                let normal = n0 * b.x + n1 * b.y + n2 * b.z;
                leaning_away += usize::from(normal.dot(near - far) < 0.0);
            }
        }
        println!("{leaning_away} pixels whose vertex normal faces away; darkest {darkest:.3} of albedo·L");
        assert!(leaning_away >= 10, "{leaning_away}");
        // The lift to the corners' planes leaves the front all its sky.
        assert!(darkest > 0.9, "{darkest}");
    }

    #[test]
    fn normal_map_decodes_as_the_shader() {
        let (n, t) = (Vec3::Z, Vec4::new(1.0, 0.0, 0.3, -1.0));
        let texel = |rgba| Texture::solid(rgba, Encoding::Linear);
        // 128 is exactly flat; the tangent need not be orthogonal to n.
        assert_eq!(map_normal(&texel(FLAT_NORMAL), Vec2::ZERO, n * 2.0, t), n);
        // x = (255·1 − 128)/127 = 1, z = 2·(191/255) − 1 = 0.498: toward the tangent.
        let m = map_normal(&texel([255, 128, 191, 255]), Vec2::ZERO, n, t);
        let want = Vec3::new(1.0, 0.0, 2.0 * 191.0 / 255.0 - 1.0).normalize();
        assert!((m - want).length() < 1e-5, "{m}");
        // y = (0 − 128)/127 along the bitangent cross(n, t)·w = −Y: toward +Y.
        let m = map_normal(&texel([128, 0, 255, 255]), Vec2::ZERO, n, t);
        let want = Vec3::new(0.0, 128.0 / 127.0, 1.0).normalize();
        assert!((m - want).length() < 1e-5, "{m}");
    }
}
