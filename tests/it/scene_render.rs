//! Scenes render as users run them: the built-in head and the Lee Perry-Smith
//! scan produce a sane image (the head covers the middle of the frame, nothing is
//! NaN or black), and EXR output is the linear image behind the PNG.

use crate::common;

use dermis::render::{render_scene, RenderOptions, RenderOutput};
use dermis::scene::file::{load_scene, SceneFile};
use dermis::scene::texture::LUMINANCE;
use dermis::scene::Scene;
use glam::Vec3;
use std::path::Path;

const SIZE: u32 = 128;

/// Renders `file` under a uniform grey environment, so that every pixel that
/// differs from the background belongs to the mesh.
fn render(mut file: SceneFile) -> RenderOutput {
    file.environment.source = "uniform:0.5,0.5,0.5".parse().unwrap();
    file.render.width = SIZE;
    file.render.height = SIZE;
    file.render.exposure = Some(0.0);
    file.render.irradiance_resolution = 512;
    common::with_gpu(|ctx| {
        let scene = Scene::load(file).unwrap();
        let opts = RenderOptions {
            hdr: true,
            ..RenderOptions::default()
        };
        render_scene(ctx, &scene, &opts).unwrap()
    })
}

struct Coverage {
    fraction: f32,
    centroid: (f32, f32),
    mean_mesh_luma: f32,
}

fn coverage(out: &RenderOutput) -> Coverage {
    let hdr = out.hdr.as_ref().unwrap();
    assert!(hdr.iter().all(|v| v.is_finite()), "NaN or Inf in the image");
    let (w, h) = (out.width as usize, out.height as usize);
    let (mut n, mut sx, mut sy, mut luma) = (0usize, 0.0, 0.0, 0.0);
    for y in 0..h {
        for x in 0..w {
            let p = &hdr[(y * w + x) * 4..][..3];
            // The background is exactly the environment radiance, 0.5.
            if p.iter().any(|c| (c - 0.5).abs() > 1e-3) {
                n += 1;
                sx += x as f32;
                sy += y as f32;
                luma += Vec3::from_slice(&p[..3]).dot(LUMINANCE);
            }
        }
    }
    let n = n.max(1);
    Coverage {
        fraction: n as f32 / (w * h) as f32,
        centroid: (sx / n as f32 / w as f32, sy / n as f32 / h as f32),
        mean_mesh_luma: luma / n as f32,
    }
}

fn assert_sane(c: &Coverage, what: &str) {
    println!(
        "{what}: coverage {:.2}, centroid ({:.2}, {:.2}), mean luminance {:.3}",
        c.fraction, c.centroid.0, c.centroid.1, c.mean_mesh_luma
    );
    assert!(
        (0.15..0.85).contains(&c.fraction),
        "{what}: coverage {}",
        c.fraction
    );
    assert!(
        (c.centroid.0 - 0.5).abs() < 0.15,
        "{what}: centroid {:?}",
        c.centroid
    );
    assert!(
        (c.centroid.1 - 0.5).abs() < 0.2,
        "{what}: centroid {:?}",
        c.centroid
    );
    // Albedo ~0.3-0.6 under a uniform radiance of 0.5: the mesh is lit, not black.
    assert!(
        c.mean_mesh_luma > 0.05,
        "{what}: too dark: {}",
        c.mean_mesh_luma
    );
}

#[test]
fn builtin_head_renders_in_the_middle_of_the_frame() {
    let out = render(SceneFile::default());
    assert_sane(&coverage(&out), "built-in head");
}

#[test]
fn lee_perry_smith_scan_renders() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scenes/lee-perry-smith.toml");
    let out = render(load_scene(&path).unwrap());
    assert_sane(&coverage(&out), "Lee Perry-Smith");
}

#[test]
fn exr_is_the_linear_image_behind_the_png() {
    let out = render(SceneFile::default());
    let hdr = out.hdr.as_ref().unwrap();
    let srgb = |c: f32| {
        let c = c.clamp(0.0, 1.0);
        if c <= 0.0031308 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        }
    };
    let worst = hdr
        .chunks_exact(4)
        .zip(out.rgba8.chunks_exact(4))
        .flat_map(|(h, l)| (0..3).map(move |c| (srgb(h[c]) * 255.0 - l[c] as f32).abs()))
        .fold(0.0f32, f32::max);
    // One 8-bit step of rounding plus f16 storage of the HDR target.
    assert!(worst <= 1.5, "PNG and EXR disagree by {worst} / 255");
    let path = std::env::temp_dir().join(format!("dermis-{}.exr", std::process::id()));
    dermis::render::output::write(&path, &out).unwrap();
    let read = exr::prelude::read_first_rgba_layer_from_file(
        &path,
        |res, _| vec![0.0f32; res.width() * res.height() * 4],
        |px, pos, (r, g, b, a): (f32, f32, f32, f32)| {
            let i = (pos.y() * SIZE as usize + pos.x()) * 4;
            px[i..i + 4].copy_from_slice(&[r, g, b, a]);
        },
    )
    .unwrap();
    assert_eq!(read.layer_data.channel_data.pixels, *hdr);
}

/// Median of a list (sorted copy).
fn median(mut v: Vec<f32>) -> f32 {
    v.sort_by(f32::total_cmp);
    v[v.len() / 2]
}

/// Renders `file` close up and compares the luminance gradient across visible UV
/// seams (mesh edges whose positions recur with other UVs) with the gradient a
/// few pixels beside them. Returns (seam samples, median across, median beside).
fn seam_gradients(mut file: SceneFile, distance_mm: f32) -> (usize, f32, f32) {
    // Close on the face, so the widest Gaussians span several pixels.
    let (w, h) = (512u32, 512u32);
    file.render.width = w;
    file.render.height = h;
    file.render.irradiance_resolution = 2048;
    file.camera.orbit = Some(dermis::scene::file::Orbit {
        yaw_deg: 20.0,
        pitch_deg: 5.0,
        distance_mm,
    });
    file.render.exposure = Some(0.0);
    let scene = Scene::load(file).unwrap();
    let out = common::with_gpu(|ctx| {
        let opts = RenderOptions {
            hdr: true,
            ..RenderOptions::default()
        };
        render_scene(ctx, &scene, &opts).unwrap()
    });
    let img = out.hdr.unwrap();
    let luma = |x: i32, y: i32| -> Option<f32> {
        if x < 0 || y < 0 || x >= w as i32 || y >= h as i32 {
            return None;
        }
        let p = &img[((y as u32 * w + x as u32) * 4) as usize..][..3];
        Some(Vec3::from_slice(&p[..3]).dot(LUMINANCE))
    };
    // Seam edges: triangle edges whose positions recur elsewhere with other UVs.
    let mesh = &scene.mesh;
    let key = |i: u32| mesh.positions[i as usize].to_array().map(f32::to_bits);
    let mut edges: std::collections::HashMap<_, Vec<(u32, u32)>> = Default::default();
    for t in mesh.indices.chunks_exact(3) {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let k = if key(a) < key(b) {
                (key(a), key(b))
            } else {
                (key(b), key(a))
            };
            edges.entry(k).or_default().push((a, b));
        }
    }
    let vp = scene.camera.view_projection(w as f32 / h as f32);
    let to_screen = |p: glam::Vec3| {
        let c = vp.project_point3(p);
        glam::Vec2::new((c.x * 0.5 + 0.5) * w as f32, (c.y * 0.5 + 0.5) * h as f32)
    };
    let (mut across, mut beside) = (Vec::new(), Vec::new());
    for uses in edges.values() {
        let uv = |(a, b): (u32, u32)| (mesh.uvs[a as usize], mesh.uvs[b as usize]);
        let (a, b) = uses[0];
        let is_seam = uses.iter().any(|&e| {
            let (p, q) = uv(e);
            let (r, s) = uv((a, b));
            (p.distance(r) > 1e-4 || q.distance(s) > 1e-4)
                && (p.distance(s) > 1e-4 || q.distance(r) > 1e-4)
        });
        let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        let n = (mesh.normals[a as usize] + mesh.normals[b as usize]).normalize();
        let mid = 0.5 * (pa + pb);
        // Only seams on surfaces facing the camera squarely (visible, not grazing).
        if !is_seam || n.dot((scene.camera.position - mid).normalize()) < 0.6 {
            continue;
        }
        let (sa, sb) = (to_screen(pa), to_screen(pb));
        let m = 0.5 * (sa + sb);
        let perp = (sb - sa).perp().normalize_or_zero();
        let grad = |c: glam::Vec2| -> Option<f32> {
            let (p, q) = (c + perp * 1.5, c - perp * 1.5);
            Some(
                (luma(p.x.round() as i32, p.y.round() as i32)?
                    - luma(q.x.round() as i32, q.y.round() as i32)?)
                .abs(),
            )
        };
        if let (Some(g0), Some(g1), Some(g2)) =
            (grad(m), grad(m + perp * 6.0), grad(m - perp * 6.0))
        {
            across.push(g0);
            beside.push(0.5 * (g1 + g2));
        }
    }
    let n = across.len();
    if n == 0 {
        return (0, 0.0, 0.0);
    }
    (n, median(across), median(beside))
}

fn assert_no_seams(what: &str, (n, seam, skin): (usize, f32, f32)) {
    println!(
        "{what}: {n} seam samples, median gradient across seams {seam:.4}, beside them {skin:.4}"
    );
    assert!(n > 20, "{what}: too few visible seam samples: {n}");
    assert!(
        seam < 1.5 * skin + 1e-3,
        "{what}: seams stand out: {seam} vs {skin}"
    );
}

#[test]
fn texture_space_diffusion_leaves_no_seam_lines() {
    // The built-in head's atlas has charts meeting on the face and the sides.
    assert_no_seams("built-in head", seam_gradients(SceneFile::default(), 350.0));
    // The scan's atlas is one cylindrical chart (seam at the back) plus small
    // charts for the eyes and mouth: few of its seams face the camera.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scenes/lee-perry-smith.toml");
    assert_no_seams(
        "Lee Perry-Smith",
        seam_gradients(load_scene(&path).unwrap(), 450.0),
    );
}

/// Mean red irradiance per face region of the built-in head (UV-space view),
/// under a uniform red environment (the paper's Fig. 6), with or without the
/// light the skin reflects onto itself and the sky's light through thin skin
/// (`transmission`: skin.transmission).
fn region_irradiance(
    occlusion: dermis::scene::file::Occlusion,
    interreflection: bool,
    transmission: f32,
) -> [f32; 10] {
    use dermis::render::View;
    let mut file = SceneFile::default();
    file.environment.source = "uniform:1,0,0".parse().unwrap();
    file.skin.occlusion = occlusion;
    file.skin.interreflection = interreflection;
    file.skin.transmission = transmission;
    file.render.irradiance_resolution = 512;
    file.render.width = 64;
    file.render.height = 64;
    let scene = Scene::load(file).unwrap();
    let out = common::with_gpu(|ctx| {
        let opts = RenderOptions {
            view: View::named("irradiance"),
            ..RenderOptions::default()
        };
        render_scene(ctx, &scene, &opts).unwrap()
    });
    let irr = out.hdr.unwrap();
    let (n, regions) = (out.width as usize, &scene.regions);
    let (mut sum, mut count) = ([0.0f64; 10], [0usize; 10]);
    for y in 0..n {
        for x in 0..n {
            let p = &irr[(y * n + x) * 4..][..4];
            if p[3] < 0.999 {
                continue;
            }
            let (rx, ry) = (
                x * regions.width as usize / n,
                y * regions.height as usize / n,
            );
            let id = regions.rgba8[(ry * regions.width as usize + rx) * 4] as usize;
            if id < 10 {
                sum[id] += (p[0] / p[3]) as f64;
                count[id] += 1;
            }
        }
    }
    std::array::from_fn(|i| (sum[i] / count[i].max(1) as f64) as f32)
}

/// Per region, `on / off`, printed with both under `what`.
fn region_gains(what: &str, on: [f32; 10], off: [f32; 10]) -> [f32; 10] {
    use dermis::scene::head::REGION_NAMES;
    for i in 0..10 {
        println!(
            "{:<14} {what} on {:.3} off {:.3} ratio {:.4}",
            REGION_NAMES[i],
            on[i],
            off[i],
            on[i] / off[i]
        );
    }
    std::array::from_fn(|i| on[i] / off[i])
}

#[test]
fn occlusion_darkens_the_concavities_under_a_uniform_red_sky() {
    use dermis::scene::file::Occlusion;
    use dermis::scene::head::{REGION_EARS, REGION_EYES, REGION_FOREHEAD, REGION_NOSE};
    let gains = region_gains(
        "occlusion",
        region_irradiance(Occlusion::Raytrace, false, 0.0),
        region_irradiance(Occlusion::Off, false, 0.0),
    );
    let ratio = |r: u8| gains[r as usize];
    // Without occlusion a uniform sky gives E = π·L everywhere (the albedo^mix aside).
    assert!(
        ratio(REGION_EYES) < 0.8,
        "eye sockets: {}",
        ratio(REGION_EYES)
    );
    assert!(ratio(REGION_EARS) < 0.85, "ears: {}", ratio(REGION_EARS));
    assert!(
        ratio(REGION_NOSE) < 0.95,
        "nose (nostrils): {}",
        ratio(REGION_NOSE)
    );
    assert!(
        ratio(REGION_FOREHEAD) > ratio(REGION_EYES) + 0.1,
        "the open forehead stays brighter"
    );
}

/// The light the skin reflects onto itself (light::interreflection) adds to
/// every region, most where the sky is most occluded: the eye sockets and
/// the ears gain more than the open forehead. Under a red sky on the
/// built-in head's skin (red albedo ≈ 0.6) a crease that sees skin over a
/// third of its hemisphere gains ≳ 0.6·⅓ of what the sky gives it.
#[test]
fn interreflection_brightens_the_concavities_most() {
    use dermis::scene::file::Occlusion;
    use dermis::scene::head::{REGION_EARS, REGION_EYES, REGION_FOREHEAD, REGION_NAMES};
    let gains = region_gains(
        "interreflection",
        region_irradiance(Occlusion::Raytrace, true, 0.0),
        region_irradiance(Occlusion::Raytrace, false, 0.0),
    );
    let gain = |r: u8| gains[r as usize];
    for i in 0..10u8 {
        assert!(gain(i) >= 1.0, "{}: {}", REGION_NAMES[i as usize], gain(i));
    }
    assert!(
        gain(REGION_EYES) > 1.05,
        "eye sockets: {}",
        gain(REGION_EYES)
    );
    assert!(gain(REGION_EARS) > 1.03, "ears: {}", gain(REGION_EARS));
    assert!(
        gain(REGION_FOREHEAD) < gain(REGION_EYES) - 0.03,
        "the open forehead gains less: {} vs {}",
        gain(REGION_FOREHEAD),
        gain(REGION_EYES)
    );
}

/// The sky's light through thin skin (light::transmission) reaches the ears
/// and nothing thick: the forehead and cheeks are unchanged.
#[test]
fn the_sky_shines_through_the_ears_only() {
    use dermis::scene::file::Occlusion;
    use dermis::scene::head::{
        REGION_EARS, REGION_FOREHEAD, REGION_LEFT_CHEEK, REGION_NAMES, REGION_RIGHT_CHEEK,
    };
    let gains = region_gains(
        "transmission",
        region_irradiance(Occlusion::Raytrace, false, 1.0),
        region_irradiance(Occlusion::Raytrace, false, 0.0),
    );
    // Measured: ears +0.4 %, nose (nostrils) +0.4 %, forehead and cheeks 0.
    let gain = |r: u8| gains[r as usize];
    assert!(gain(REGION_EARS) > 1.002, "ears: {}", gain(REGION_EARS));
    for r in [REGION_FOREHEAD, REGION_LEFT_CHEEK, REGION_RIGHT_CHEEK] {
        assert!(
            (gain(r) - 1.0).abs() < 1e-4,
            "{}: {}",
            REGION_NAMES[r as usize],
            gain(r)
        );
    }
}

#[test]
fn raster_and_raytraced_occlusion_agree_on_the_scan() {
    use dermis::light::occlusion::raster::{raster_vertices, RasterOptions};
    use dermis::light::occlusion::{raytrace, RayOptions};
    let mesh = dermis::scene::gltf::load_mesh(
        &dermis::assets::scan().join("LeePerrySmith.glb"),
        Some(50.3),
    )
    .unwrap();
    // Every 8th vertex: a 1,160-vertex sample of the whole head.
    let sample: Vec<u32> = (0..mesh.vertex_count() as u32).step_by(8).collect();
    let cpu = raytrace(&mesh, &RayOptions::default(), false);
    let gpu = common::with_gpu(|ctx| {
        raster_vertices(ctx, &mesh, &sample, &RasterOptions::default(), false).unwrap()
    });
    let dc_cpu: Vec<f32> = sample.iter().map(|&v| cpu.coeffs[v as usize][0]).collect();
    let dc_gpu: Vec<f32> = gpu.coeffs.iter().map(|t| t[0]).collect();
    let mean = dc_cpu.iter().sum::<f32>() / dc_cpu.len() as f32;
    let mad = dc_cpu
        .iter()
        .zip(&dc_gpu)
        .map(|(a, b)| (a - b).abs())
        .sum::<f32>()
        / dc_cpu.len() as f32;
    println!(
        "{} vertices: mean DC {mean:.4}, mean |raster - raytrace| {mad:.5} ({:.2} % of the mean)",
        sample.len(),
        100.0 * mad / mean
    );
    assert!(mad < 0.02 * mean, "methods disagree: {mad} vs mean {mean}");
}

#[test]
fn scattering_bleeds_red_into_the_shadow_edge() {
    use dermis::render::View;
    use dermis::scene::file::{Light, LightKind, Occlusion};
    let mut file = SceneFile::default();
    file.environment.source = "uniform:0,0,0".parse().unwrap();
    file.skin.occlusion = Occlusion::Off;
    file.lights = vec![Light {
        kind: LightKind::Directional,
        direction: Some([1.0, 0.0, -0.3]),
        position: None,
        color: [1.0, 1.0, 1.0],
        intensity: 3.0,
        shadow: false,
        angular_diameter_deg: 0.0,
    }];
    file.render.width = 256;
    file.render.height = 256;
    file.render.irradiance_resolution = 1024;
    file.render.exposure = Some(0.0);
    let scene = Scene::load(file).unwrap();
    let [direct, skin] = [View::named("direct"), View::FINAL].map(|view| {
        common::with_gpu(|ctx| {
            let opts = RenderOptions {
                view,
                hdr: true,
                ..RenderOptions::default()
            };
            render_scene(ctx, &scene, &opts).unwrap().hdr.unwrap()
        })
    });
    let luma = |p: &[f32]| Vec3::from_slice(&p[..3]).dot(LUMINANCE);
    let max = direct.chunks_exact(4).map(luma).fold(0.0f32, f32::max);
    let smax = skin.chunks_exact(4).map(luma).fold(0.0f32, f32::max);
    // Lit skin (direct above 30 % of its peak) against the shadow edge: pixels the
    // direct shading leaves black (< 0.5 %) that scattering lights (> 0.5 %).
    let (mut lit, mut edge) = ((0.0f64, 0usize), (0.0f64, 0usize));
    for (d, s) in direct.chunks_exact(4).zip(skin.chunks_exact(4)) {
        let rg = (s[0] / s[1].max(1e-6)) as f64;
        if luma(d) > 0.3 * max {
            lit = (lit.0 + rg, lit.1 + 1);
        } else if luma(d) < 0.005 * max && luma(s) > 0.005 * smax {
            edge = (edge.0 + rg, edge.1 + 1);
        }
    }
    let (rl, re) = (lit.0 / lit.1.max(1) as f64, edge.0 / edge.1.max(1) as f64);
    println!(
        "red/green of the scattered image: lit skin {rl:.3} ({} px), shadow edge {re:.3} ({} px)",
        lit.1, edge.1
    );
    assert!(
        lit.1 > 100 && edge.1 > 50,
        "too few pixels: {} lit, {} edge",
        lit.1,
        edge.1
    );
    assert!(re > 1.3 * rl, "no red bleeding: {re} vs {rl}");
}

#[test]
fn an_unblurred_profile_is_shaded_per_pixel() {
    // With the profile at zero width every level is the irradiance itself,
    // which the final pass evaluates at the pixel as the irradiance pass does
    // at a texel (skin::chain::unblurred_levels). Without the specular (ρs = 0),
    // the light the skin reflects onto itself and transmission, its diffuse view
    // is then albedo/π·E at the pixel: the direct view's, whatever the
    // irradiance resolution (here 256², texels of ~2.5 mm).
    use dermis::render::View;
    use dermis::scene::file::{scene_by_name, SpecularRegion};
    let mut file = scene_by_name(None).unwrap();
    (file.render.width, file.render.height) = (96, 120);
    file.render.skybox = false;
    file.render.irradiance_resolution = 256;
    file.skin.blur_width = 0.0;
    file.skin.interreflection = false;
    file.skin.transmission = 0.0;
    file.skin.regions = Some(
        dermis::skin::specular::default_regions()
            .iter()
            .map(|r| SpecularRegion {
                name: r.name.into(),
                rho_s: 0.0,
                m: r.m,
            })
            .collect(),
    );
    let scene = Scene::load(file).unwrap();
    let [diffuse, direct] = common::with_gpu(|ctx| {
        ["diffuse", "direct"].map(|view| {
            let opts = RenderOptions {
                hdr: true,
                view: View::named(view),
                ..RenderOptions::default()
            };
            render_scene(ctx, &scene, &opts).unwrap().hdr.unwrap()
        })
    });
    let mut errors: Vec<f32> = diffuse
        .chunks_exact(4)
        .zip(direct.chunks_exact(4))
        .filter(|(a, b)| a[3] > 0.5 && b[3] > 0.5)
        .map(|(a, b)| {
            let (la, lb) = (a[0] + a[1] + a[2], b[0] + b[1] + b[2]);
            (la - lb).abs() / lb.max(1e-3)
        })
        .collect();
    errors.sort_by(f32::total_cmp);
    let at = |q: f32| errors[((errors.len() - 1) as f32 * q) as usize];
    println!(
        "{} pixels: diffuse against direct, median {:.2e}, p90 {:.2e}, p99 {:.2e}, worst {:.2e}",
        errors.len(),
        at(0.5),
        at(0.9),
        at(0.99),
        at(1.0)
    );
    assert!(errors.len() > 3000, "{}", errors.len());
    // Measured: bit for bit at the median and the 99th percentile; under 1 %
    // of the pixels differ.
    assert!(at(0.99) < 1e-5, "p99 {}", at(0.99));
}
