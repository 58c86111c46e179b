//! The GPU lighting against CPU references on spheres, pixel by pixel:
//! - the KS specular of directional and point lights against the CPU BRDF
//!   (skin::specular::ks_brdf, the paper's eq. 1);
//! - shadow maps: a small sphere shadowing a large one, against analytic ray
//!   casting, in the screen-space direct view and in the UV-space irradiance;
//! - environment specular: exact under a constant environment, and the
//!   prefiltered environment against brute-force integration of a CC0 map.
//! - the furnace: a white and a grey sphere under a uniform sky, the whole
//!   frame against the closed form.

use crate::common;

use dermis::light::extract::extract;
use dermis::light::prefilter;
use dermis::render::{render_scene, RenderOptions, View};
use dermis::scene::camera::Camera;
use dermis::scene::env::{self as envmap, EnvMap};
use dermis::scene::file::{IrradianceShading, LightsMode, Occlusion, SceneFile};
use dermis::scene::mesh::Mesh;
use dermis::scene::texture::{Encoding, Texture};
use dermis::scene::{Light, LightSource, Scene};
use dermis::skin::specular::{
    f0_from_ior, hemispherical_albedo, ks_brdf, map_rho_s, specular_albedo, Lobe, DEFAULT_M,
    DEFAULT_RHO_S, DIELECTRIC_RHO_S, F0_SKIN,
};
use glam::{Vec2, Vec3, Vec4};

const R: f32 = 60.0; // mm
const SIZE: u32 = 256;
/// Linear value of the sRGB grey 128 the spheres are painted with.
const ALBEDO: f32 = 0.215_861;

/// A UV sphere: u = φ/2π, v = θ/π, θ from +Y; u is then mapped onto `u_range`
/// of the texture.
fn sphere(centre: Vec3, radius: f32, slices: u32, stacks: u32, u_range: (f32, f32)) -> Mesh {
    let mut m = Mesh {
        name: "sphere".into(),
        ..Mesh::default()
    };
    for j in 0..=stacks {
        for i in 0..=slices {
            let uv = Vec2::new(i as f32 / slices as f32, j as f32 / stacks as f32);
            let n = on_sphere(uv);
            let phi = uv.x * std::f32::consts::TAU;
            m.positions.push(centre + n * radius);
            m.normals.push(n);
            m.uvs
                .push(Vec2::new(u_range.0 + uv.x * (u_range.1 - u_range.0), uv.y));
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

/// The unit normal at `uv` of [`sphere`].
fn on_sphere(uv: Vec2) -> Vec3 {
    let (phi, theta) = (uv.x * std::f32::consts::TAU, uv.y * std::f32::consts::PI);
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.cos(),
        theta.sin() * phi.sin(),
    )
}

/// Several meshes as one.
fn merge(meshes: &[Mesh]) -> Mesh {
    let mut out = Mesh {
        name: "spheres".into(),
        ..Mesh::default()
    };
    for m in meshes {
        let base = out.positions.len() as u32;
        out.positions.extend(&m.positions);
        out.normals.extend(&m.normals);
        out.uvs.extend(&m.uvs);
        out.tangents.extend(&m.tangents);
        out.indices.extend(m.indices.iter().map(|i| i + base));
    }
    out
}

/// ρs of these scenes: d'Eon's default under a uniform specular map, raised to
/// the middle of his range (skin::specular::map_rho_s).
fn rho_s() -> f32 {
    map_rho_s(DEFAULT_RHO_S, 1.0, 1.0)
}

fn scene(mesh: Mesh, lights: Vec<Light>, env: EnvMap) -> Scene {
    let mut file = SceneFile::default();
    file.skin.occlusion = Occlusion::Off;
    file.render.width = SIZE;
    file.render.height = SIZE;
    file.render.irradiance_resolution = 512;
    file.render.exposure = Some(0.0);
    let grey = |v: u8| Texture::solid([v, v, v, 255], Encoding::Linear);
    Scene {
        mesh,
        albedo: Texture::solid([128, 128, 128, 255], Encoding::Srgb),
        normal: Texture::solid([128, 128, 255, 255], Encoding::Linear),
        specular: grey(255),
        roughness: grey(77),
        regions: grey(0),
        env,
        camera: Camera::orbit_at(Vec3::ZERO, 0.0, 0.0, 400.0, 30.0),
        lights,
        pre_exposure: dermis::scene::range::PreExposure::NONE,
        file,
    }
}

/// Linear RGBA of `view` (screen views: radiance, exposure 0).
fn render(scene: &Scene, view: View) -> Vec<f32> {
    common::with_gpu(|ctx| {
        let opts = RenderOptions {
            view,
            hdr: true,
            ..RenderOptions::default()
        };
        render_scene(ctx, scene, &opts).unwrap().hdr.unwrap()
    })
}

/// Nearest intersection distance of the ray o + t·d (d unit) with a sphere.
fn hit(o: Vec3, d: Vec3, (c, r): (Vec3, f32)) -> Option<f32> {
    let oc = o - c;
    let b = oc.dot(d);
    let disc = b * b - (oc.length_squared() - r * r);
    (disc > 0.0).then(|| -b - disc.sqrt()).filter(|&t| t > 0.0)
}

/// For each screen pixel of `scene`'s camera, the first point hit on `spheres`
/// with the index of the sphere, or `None`.
fn pixel_hits(camera: &Camera, spheres: &[(Vec3, f32)]) -> Vec<Option<(usize, Vec3)>> {
    let mut out = Vec::new();
    for y in 0..SIZE {
        for x in 0..SIZE {
            let (o, d) = (camera.position, pixel_ray(camera, x, y));
            let nearest = spheres
                .iter()
                .enumerate()
                .filter_map(|(i, &s)| hit(o, d, s).map(|t| (t, i)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            out.push(nearest.map(|(t, i)| (i, o + d * t)));
        }
    }
    out
}

/// The unit direction of the ray through the centre of screen pixel (x, y).
fn pixel_ray(camera: &Camera, x: u32, y: u32) -> Vec3 {
    let inv = camera.view_projection(1.0).inverse();
    let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) / SIZE as f32 * 2.0 - 1.0;
    let ndc = |z| inv.project_point3(Vec3::new(p.x, p.y, z));
    (ndc(1.0) - ndc(0.0)).normalize()
}

/// Compares `got` (one channel per pixel) to `expected` where it is `Some`:
/// within 1 % plus one 8-bit step of the peak. Returns (pixels, worst |Δ|/peak).
fn compare(what: &str, got: impl Fn(usize) -> f32, expected: &[Option<f32>]) -> (usize, f32) {
    let peak = expected.iter().flatten().fold(0.0f32, |a, &b| a.max(b));
    assert!(peak > 0.0, "{what}: nothing to compare");
    let (mut worst, mut n) = (0.0f32, 0);
    let mut failures = Vec::new();
    for (i, e) in expected.iter().enumerate() {
        let Some(e) = *e else { continue };
        let g = got(i);
        worst = worst.max((g - e).abs() / peak);
        if (g - e).abs() > 0.01 * e + peak / 255.0 {
            failures.push(format!("texel {i}: GPU {g} vs CPU {e}"));
        }
        n += 1;
    }
    println!("{what}: {n} texels, peak {peak:.4}, max |GPU - CPU| / peak {worst:.4}");
    assert!(
        failures.is_empty(),
        "{what}: {} of {n} texels beyond 1 % + 1/255 of the peak ({peak}), e.g.\n{}",
        failures.len(),
        failures[..failures.len().min(8)].join("\n")
    );
    (n, worst)
}

#[test]
fn specular_of_directional_and_point_lights_matches_the_cpu_brdf() {
    // Bright enough that the lobe's tails stay above f16's smallest normal
    // (6.1e-5), which the RGBA16F target would flush to zero.
    let lights = [
        Light {
            source: LightSource::Directional(Vec3::new(0.4, 0.5, 1.0).normalize()),
            irradiance: Vec3::splat(200.0),
            shadow: true,
            angular_radius: 0.0,
        },
        Light {
            source: LightSource::Point(Vec3::new(-150.0, -60.0, 180.0)),
            irradiance: Vec3::splat(20.0),
            shadow: false,
            angular_radius: 0.0,
        },
    ];
    for light in lights {
        let s = scene(
            sphere(Vec3::ZERO, R, 192, 96, (0.0, 1.0)),
            vec![light],
            EnvMap::uniform(Vec3::ZERO, 64, 32),
        );
        let img = render(&s, View::named("specular"));
        let expected: Vec<Option<f32>> = pixel_hits(&s.camera, &[(Vec3::ZERO, R)])
            .into_iter()
            .map(|h| {
                let (_, p) = h?;
                let (n, v) = (p.normalize(), (s.camera.position - p).normalize());
                // Stay away from the silhouette.
                (n.dot(v) >= 0.3).then(|| {
                    let (l, e) = light.at(p);
                    ks_brdf(n, l, v, DEFAULT_M, rho_s(), F0_SKIN) * e.x
                })
            })
            .collect();
        let (n, _) = compare(&format!("{:?}", light.source), |i| img[i * 4], &expected);
        assert!(n > 10_000);
    }
}

/// With a medium the specular is its boundary, a rough dielectric of its
/// `ior` (skin::specular::Lobe::Dielectric: Smith's G₂, the exact Fresnel,
/// ρs = 1/π). A sphere of Jensen's skin1 at ior 1.33 and 1.55 under one
/// directional light 110° from the view, the specular view: each against the
/// CPU lobe pixel by pixel (1 % + 1/255 of the peak; Schlick's Fresnel at the
/// ior's F0 is about a fifth under the exact one at these angles), and the 1.55
/// sphere's specular over the 1.33 one's, summed over the pixels compared,
/// against the CPU's ratio, the Fresnel ratio at the pixels' angles: 2.32 at
/// H·V = 1, about 1.6 at this light's H·V ≈ 0.57. The tolerance is a tenth of
/// what the ior adds to the ratio over 1, so a lobe that ignored the ior misses
/// by ten tolerances, and so does the bare F0 ratio (the angles matter).
#[test]
fn a_mediums_ior_sets_the_boundarys_fresnel() {
    use dermis::scene::file::MediumPreset;
    let light = Light {
        // From the side and a little behind: 110° from the camera (on +Z).
        source: LightSource::Directional(Vec3::new(0.94, 0.15, -0.342).normalize()),
        irradiance: Vec3::splat(200.0),
        shadow: false,
        angular_radius: 0.0,
    };
    let (low, high) = (1.33f32, 1.55f32);
    let (f0_low, f0_high) = (f0_from_ior(low), f0_from_ior(high));
    // Per ior: (GPU, CPU) specular at each pixel compared, None elsewhere.
    let run = |ior: f32| {
        let mut s = scene(
            sphere(Vec3::ZERO, R, 192, 96, (0.0, 1.0)),
            vec![light],
            EnvMap::uniform(Vec3::ZERO, 64, 32),
        );
        s.file.skin.medium.preset = Some(MediumPreset::JensenSkin1);
        s.file.skin.medium.ior = ior;
        let lobe = Lobe::Dielectric { ior };
        let img = render(&s, View::named("specular"));
        let expected: Vec<Option<f32>> = pixel_hits(&s.camera, &[(Vec3::ZERO, R)])
            .into_iter()
            .map(|h| {
                let (_, p) = h?;
                let (n, v) = (p.normalize(), (s.camera.position - p).normalize());
                (n.dot(v) >= 0.3).then(|| {
                    let (l, e) = light.at(p);
                    lobe.eval(n, l, v, DEFAULT_M, DIELECTRIC_RHO_S) * e.x
                })
            })
            .collect();
        let (n, _) = compare(&format!("medium, ior {ior}"), |i| img[i * 4], &expected);
        assert!(n > 10_000);
        (img, expected, s.camera)
    };
    let (img_low, cpu_low, camera) = run(low);
    let (img_high, cpu_high, _) = run(high);
    // What a lobe that ignored the ior would give.
    let constant = 1.0f32;
    // Sums over the pixels where both lobes are above a thousandth of their
    // peak, and the range of the per-pixel Fresnel ratios there.
    let peak = cpu_low.iter().flatten().fold(0.0f32, |a, &b| a.max(b));
    let hits = pixel_hits(&camera, &[(Vec3::ZERO, R)]);
    let l = match light.source {
        LightSource::Directional(d) => d,
        LightSource::Point(_) => unreachable!(),
    };
    let (mut gpu, mut cpu) = ([0.0f64; 2], [0.0f64; 2]);
    // The Fresnel ratio's range over those pixels (printed).
    let (mut lo, mut hi) = (f32::MAX, 0.0f32);
    for (i, h) in hits.iter().enumerate() {
        let (Some(a), Some(b), Some((_, p))) = (cpu_low[i], cpu_high[i], h) else {
            continue;
        };
        if a < 1e-3 * peak {
            continue;
        }
        gpu[0] += f64::from(img_low[i * 4]);
        gpu[1] += f64::from(img_high[i * 4]);
        cpu[0] += f64::from(a);
        cpu[1] += f64::from(b);
        let v = (camera.position - *p).normalize();
        let h_dot_v = (l + v).normalize().dot(v);
        let fresnel = |ior| Lobe::Dielectric { ior }.fresnel(f64::from(h_dot_v)) as f32;
        let r = fresnel(high) / fresnel(low);
        (lo, hi) = (lo.min(r), hi.max(r));
    }
    let (got, want) = ((gpu[1] / gpu[0]) as f32, (cpu[1] / cpu[0]) as f32);
    let tolerance = 0.1 * (want - constant);
    let bare = f0_high / f0_low;
    println!(
        "specular, ior {high} over ior {low}: GPU {got:.4}, CPU {want:.4} (± {tolerance:.4}); \
         per-pixel Fresnel ratios {lo:.3}..{hi:.3}; the bare F0 ratio {bare:.3}"
    );
    assert!(want - constant > 0.5, "the view sees the ior: {want}");
    assert!(
        (bare - want).abs() > 3.0 * tolerance,
        "the angles matter: {want}"
    );
    assert!((got - want).abs() <= tolerance, "{got} against {want}");
}

/// Whether the segment from `p` towards the light (`l`, up to `t_max`) misses
/// `occluder`; `None` within `margin` mm of the shadow's edge (the PCF penumbra).
fn lit(p: Vec3, l: Vec3, t_max: f32, (c, r): (Vec3, f32), margin: f32) -> Option<bool> {
    let t = (c - p).dot(l);
    if t <= 0.0 || t >= t_max {
        return Some(true);
    }
    let miss = (c - p - t * l).length();
    ((miss - r).abs() > margin).then_some(miss > r)
}

/// A large sphere at the origin, a small one between it and both lights (a
/// directional light and a point light, each with a shadow map).
struct ShadowScene {
    scene: Scene,
    big: (Vec3, f32),
    small: (Vec3, f32),
}

impl ShadowScene {
    fn new() -> Self {
        let dir = Vec3::new(0.3, 0.4, 1.0).normalize();
        let point = Vec3::new(-200.0, 60.0, 300.0);
        let big = (Vec3::ZERO, R);
        // Between the sphere and the point light, off the directional light's axis.
        let small = (point.normalize() * 100.0 + Vec3::new(0.0, -5.0, 0.0), 15.0);
        let lights = vec![
            Light {
                source: LightSource::Directional(dir),
                irradiance: Vec3::splat(3.0),
                shadow: true,
                angular_radius: 0.0,
            },
            Light {
                source: LightSource::Point(point),
                irradiance: Vec3::splat(0.6),
                shadow: true,
                angular_radius: 0.0,
            },
        ];
        let mesh = merge(&[
            // Disjoint halves of the texture, for the UV-space test.
            sphere(big.0, big.1, 192, 96, (0.0, 0.5)),
            sphere(small.0, small.1, 96, 48, (0.5, 1.0)),
        ]);
        let mut scene = scene(mesh, lights, EnvMap::uniform(Vec3::ZERO, 64, 32));
        scene.file.render.shadow_resolution = 2048;
        Self { scene, big, small }
    }

    /// Irradiance at `p` (normal `n`) on a surface facing each light, times
    /// N·L and its visibility; `None` near a shadow edge or the terminator.
    fn irradiance(&self, p: Vec3, n: Vec3, weight: impl Fn(f32) -> f32) -> Option<f32> {
        let mut total = 0.0;
        for light in &self.scene.lights {
            let (l, e) = light.at(p);
            let t_max = match light.source {
                LightSource::Point(q) => (q - p).length(),
                LightSource::Directional(_) => f32::INFINITY,
            };
            let n_dot_l = n.dot(l);
            if n_dot_l.abs() < 0.15 {
                return None; // self-shadowing at the terminator: biased by design
            }
            if n_dot_l > 0.0 && lit(p, l, t_max, self.small, 1.5)? {
                total += e.x * n_dot_l * weight(n_dot_l);
            }
        }
        Some(total)
    }

    /// How many points of `expected` are in at least one shadow: the test must
    /// look at shadowed points, not only lit ones.
    fn shadowed(&self, points: impl Iterator<Item = Vec3>) -> usize {
        points
            .filter(|&p| {
                self.scene.lights.iter().any(|light| {
                    let (l, _) = light.at(p);
                    p.dot(l) > 0.2 * R && lit(p, l, f32::INFINITY, self.small, 0.0) == Some(false)
                })
            })
            .count()
    }
}

#[test]
fn shadow_maps_match_analytic_shadows_in_screen_space() {
    let s = ShadowScene::new();
    let img = render(&s.scene, View::named("direct"));
    let hits = pixel_hits(&s.scene.camera, &[s.big, s.small]);
    let expected: Vec<Option<f32>> = hits
        .iter()
        .map(|h| {
            let (i, p) = (*h)?;
            let n = p.normalize();
            (i == 0 && n.dot((s.scene.camera.position - p).normalize()) > 0.3)
                .then(|| s.irradiance(p, n, |_| 1.0))
                .flatten()
                .map(|e| ALBEDO / std::f32::consts::PI * e)
        })
        .collect();
    let (n, _) = compare("direct view", |i| img[i * 4], &expected);
    let in_shadow = s.shadowed(
        hits.iter()
            .zip(&expected)
            .filter_map(|(h, e)| e.and(*h).map(|(_, p)| p)),
    );
    println!("{in_shadow} compared pixels lie in a shadow");
    assert!(
        n > 10_000 && in_shadow > 500,
        "{n} pixels, {in_shadow} shadowed"
    );
}

/// Fraction of a source of angular radius `alpha` around `l` that `p` sees
/// past `occluder`: the source's cap sampled at `n` points (a Fibonacci
/// spiral, uniform in solid angle), a ray to each.
fn source_visible(p: Vec3, l: Vec3, alpha: f32, (c, r): (Vec3, f32), n: usize) -> f32 {
    let (t, b) = l.any_orthonormal_pair();
    let visible = (0..n)
        .filter(|&k| {
            let cos = 1.0 - (1.0 - alpha.cos()) * (k as f32 + 0.5) / n as f32;
            let sin = (1.0 - cos * cos).max(0.0).sqrt();
            let phi = k as f32 * 2.399_963;
            let d = cos * l + sin * (phi.cos() * t + phi.sin() * b);
            let tc = (c - p).dot(d);
            tc <= 0.0 || (c - p - tc * d).length() > r
        })
        .count();
    visible as f32 / n as f32
}

#[test]
fn soft_shadows_follow_the_source_size() {
    // A 4°-radius source (a softbox) over the big sphere, the small one between:
    // a penumbra a few mm wide. Reference: the source's visible fraction by ray
    // casting (1024 directions) × N·L at its centre. The soft shadows turn their
    // taps per pixel, which is noise, so both images are compared after a 5 × 5
    // box filter: the penumbra's place, width and profile, not its grain.
    let alpha = 4f32.to_radians();
    let s = ShadowScene::new();
    let mut scene = s.scene;
    // The visibility texture is half the irradiance resolution; the big sphere
    // has half of it: 512 texels around its 377 mm equator.
    scene.file.render.irradiance_resolution = 2048;
    let dir = (s.small.0 - s.big.0)
        .normalize()
        .lerp(Vec3::Y, 0.15)
        .normalize();
    scene.lights = vec![Light {
        source: LightSource::Directional(dir),
        irradiance: Vec3::splat(3.0),
        shadow: true,
        angular_radius: alpha,
    }];
    let img = render(&scene, View::named("direct"));
    let hits = pixel_hits(&scene.camera, &[s.big, s.small]);
    let peak = ALBEDO / std::f32::consts::PI * 3.0;
    // Per compared pixel: (GPU, ray-cast reference, a hard shadow), / peak.
    let values: Vec<Option<[f32; 3]>> = hits
        .iter()
        .enumerate()
        .map(|(i, h)| {
            let (k, p) = (*h)?;
            let n = p.normalize();
            let n_dot_l = n.dot(dir);
            if k != 0 || n.dot((scene.camera.position - p).normalize()) < 0.3 || n_dot_l < 0.15 {
                return None;
            }
            let v = source_visible(p, dir, alpha, s.small, 1024);
            let hard = source_visible(p, dir, 0.0, s.small, 1);
            Some([img[i * 4] / peak, n_dot_l * v, n_dot_l * hard])
        })
        .collect();
    let size = SIZE as usize;
    let (mut count, mut soft_err, mut hard_err) = (0usize, 0.0f32, 0.0f32);
    for y in 2..size - 2 {
        for x in 2..size - 2 {
            let window: Option<Vec<[f32; 3]>> = (0..25)
                .map(|k| values[(y + k / 5 - 2) * size + x + k % 5 - 2])
                .collect();
            let Some(window) = window else { continue };
            let mean = |c: usize| window.iter().map(|w| w[c]).sum::<f32>() / 25.0;
            let (gpu, reference, hard) = (mean(0), mean(1), mean(2));
            // The penumbra: the source partly visible at this pixel.
            let p = hits[y * size + x].unwrap().1;
            let v = source_visible(p, dir, alpha, s.small, 1024);
            if v > 0.02 && v < 0.98 {
                count += 1;
                soft_err += (gpu - reference).abs();
                hard_err += (hard - reference).abs();
            }
        }
    }
    let (soft_err, hard_err) = (
        soft_err / count.max(1) as f32,
        hard_err / count.max(1) as f32,
    );
    println!(
        "soft shadow, 4° source: {count} penumbra pixels, mean |GPU − ray cast| {:.2} % of the \
         peak after a 5×5 box filter (a hard shadow: {:.2} %)",
        100.0 * soft_err,
        100.0 * hard_err
    );
    assert!(count > 300, "{count} penumbra pixels");
    assert!(soft_err < 0.03, "mean penumbra error {soft_err}");
    assert!(
        hard_err > 2.0 * soft_err,
        "a hard shadow would pass: {hard_err}"
    );
}

/// The lobe's A(cos θ, m) by the CPU quadrature at 257 angles, interpolated
/// linearly: A is smooth in cos θ, and the quadrature is too slow to call per
/// texel.
fn specular_albedo_table(lobe: Lobe) -> impl Fn(f32) -> f32 {
    let table: Vec<f32> = (0..=256)
        .map(|i| lobe.albedo(i as f32 / 256.0, DEFAULT_M))
        .collect();
    move |c: f32| {
        let x = c.clamp(0.0, 1.0) * 256.0;
        let i = (x as usize).min(255);
        table[i] + (table[i + 1] - table[i]) * (x - i as f32)
    }
}

#[test]
fn shadow_maps_shadow_the_texture_space_irradiance() {
    let s = ShadowScene::new();
    let img = render(&s.scene, View::named("irradiance"));
    let res = s.scene.file.render.irradiance_resolution as usize;
    let mix = s.scene.file.skin.mix;
    let albedo = specular_albedo_table(Lobe::PAPER);
    // The big sphere covers the left half of the texture.
    let mut points = Vec::new();
    let expected: Vec<Option<f32>> = (0..res * res)
        .map(|i| {
            let uv = Vec2::new((i % res) as f32 + 0.5, (i / res) as f32 + 0.5) / res as f32;
            let uv = Vec2::new(2.0 * uv.x, uv.y);
            // Away from the poles and the u seam, where the tessellation's chords
            // and the coverage edge differ from the analytic sphere.
            if !(0.1..0.9).contains(&uv.y) || !(0.02..0.98).contains(&uv.x) {
                return None;
            }
            let n = on_sphere(uv);
            let p = n * R;
            // Energy conservation on entry: 1 − ρs·A(N·L, m).
            let e = s.irradiance(p, n, |c| 1.0 - rho_s() * albedo(c))?;
            points.push(p);
            Some(e * ALBEDO.powf(mix))
        })
        .collect();
    let (n, _) = compare("irradiance texture", |i| img[i * 4], &expected);
    let in_shadow = s.shadowed(points.into_iter());
    assert!(
        n > 10_000 && in_shadow > 500,
        "{n} texels, {in_shadow} shadowed"
    );
}

/// Both formulations of the irradiance pass (`render.irradiance_shading`: the
/// mesh rasterised by its UVs every frame, or a compute pass over a texel map
/// and per-vertex values) light each texel at the point a raster of the mesh by
/// its UVs puts there: a coarse sphere near an unshadowed point light, whose
/// light changes across a triangle, against the same mesh rasterised by its UVs
/// on the CPU (barycentric weights at each texel's centre, the position and
/// normal interpolated).
#[test]
fn the_irradiance_texture_lights_the_point_its_uv_raster_holds() {
    for shading in [IrradianceShading::Raster, IrradianceShading::Compute] {
        irradiance_at_the_uv_raster(shading);
    }
}

fn irradiance_at_the_uv_raster(shading: IrradianceShading) {
    let light = Light {
        source: LightSource::Point(Vec3::new(0.0, 20.0, R + 25.0)),
        irradiance: Vec3::splat(0.01),
        shadow: false,
        angular_radius: 0.0,
    };
    let mesh = sphere(Vec3::ZERO, R, 24, 12, (0.0, 1.0));
    let mut s = scene(mesh, vec![light], EnvMap::uniform(Vec3::ZERO, 64, 32));
    s.file.render.irradiance_shading = shading;
    let img = render(&s, View::named("irradiance"));
    let res = s.file.render.irradiance_resolution as usize;
    let (albedo, mix) = (specular_albedo_table(Lobe::PAPER), s.file.skin.mix);
    let m = &s.mesh;
    let mut expected = vec![None; res * res];
    for t in m.indices.chunks_exact(3) {
        let [a, b, c] = [0, 1, 2].map(|k| t[k] as usize);
        let uv = [a, b, c].map(|v| m.uvs[v] * res as f32);
        let area = (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]);
        if area.abs() < 1e-9 {
            continue;
        }
        let lo = uv[0].min(uv[1]).min(uv[2]).floor().max(Vec2::ZERO);
        let hi = uv[0]
            .max(uv[1])
            .max(uv[2])
            .ceil()
            .min(Vec2::splat(res as f32));
        for y in lo.y as usize..hi.y as usize {
            for x in lo.x as usize..hi.x as usize {
                let q = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let w = [(1, 2), (2, 0), (0, 1)]
                    .map(|(i, j)| (uv[j] - uv[i]).perp_dot(q - uv[i]) / area);
                if w.iter().any(|&w| w < 1e-4) {
                    continue; // on or near an edge: either triangle's raster
                }
                let p = m.positions[a] * w[0] + m.positions[b] * w[1] + m.positions[c] * w[2];
                let n =
                    (m.normals[a] * w[0] + m.normals[b] * w[1] + m.normals[c] * w[2]).normalize();
                let (l, e) = light.at(p);
                let cos = n.dot(l);
                // Away from the terminator, where the flat normal map's 8-bit
                // tilt (0.4 %) is a large share of N·L.
                expected[y * res + x] = (cos >= 0.5)
                    .then(|| e.x * cos * (1.0 - rho_s() * albedo(cos)) * ALBEDO.powf(mix));
            }
        }
    }
    let what = format!("{shading:?}: irradiance at the UV raster's points");
    let (n, _) = compare(&what, |i| img[i * 4], &expected);
    assert!(n > 5_000, "{n} texels");
}

#[test]
fn environment_specular_is_exact_under_a_constant_environment() {
    // Split sum with a constant L: ρs·A(N·V, m)·L, A the KS directional albedo.
    let radiance = 100.0;
    let s = scene(
        sphere(Vec3::ZERO, R, 192, 96, (0.0, 1.0)),
        Vec::new(),
        EnvMap::uniform(Vec3::splat(radiance), 64, 32),
    );
    let img = render(&s, View::named("specular"));
    let expected: Vec<Option<f32>> = pixel_hits(&s.camera, &[(Vec3::ZERO, R)])
        .into_iter()
        .map(|h| {
            let (_, p) = h?;
            let cos = p.normalize().dot((s.camera.position - p).normalize());
            (cos >= 0.3).then(|| rho_s() * specular_albedo(cos, DEFAULT_M, F0_SKIN) * radiance)
        })
        .collect();
    let (n, _) = compare("constant environment", |i| img[i * 4], &expected);
    assert!(n > 10_000);
}

#[test]
fn environment_enters_the_skin_less_what_the_specular_reflects() {
    // Uniform L, no occlusion: E = π·L, of which ρs·Ā(m) is reflected
    // (Ā = 2∫A(μ)μ dμ, the CPU quadrature), in every texel of the irradiance
    // texture, times albedo^mix.
    let radiance = 2.0;
    let s = scene(
        sphere(Vec3::ZERO, R, 96, 48, (0.0, 1.0)),
        Vec::new(),
        EnvMap::uniform(Vec3::splat(radiance), 64, 32),
    );
    let img = render(&s, View::named("irradiance"));
    let want = std::f32::consts::PI
        * radiance
        * (1.0 - rho_s() * hemispherical_albedo(DEFAULT_M, F0_SKIN))
        * ALBEDO.powf(s.file.skin.mix);
    let expected: Vec<Option<f32>> = img
        .chunks_exact(4)
        .map(|t| (t[3] > 0.999).then_some(want))
        .collect();
    let (n, _) = compare("uniform environment, entry", |i| img[i * 4], &expected);
    assert!(n > 10_000, "{n}");
    println!(
        "entry factor 1 − ρs·Ā = {:.4}",
        want / (std::f32::consts::PI * radiance * ALBEDO.powf(s.file.skin.mix))
    );
}

/// A medium's boundary under a uniform sky L: it reflects ρs·A(N·V, m)·L toward
/// the viewer and lets in 1 − ρs·Ā(m) of the irradiance πL, with ρs = 1/π and
/// A, Ā the rough dielectric's of its ior (skin::specular::Lobe; the albedo
/// table integrates it). At ior 1.55 the specular view pixel by pixel and the
/// irradiance texture texel by texel (within 1 % plus 1/255 of the peak, as
/// above) against the CPU quadrature; the paper's KS lobe at d'Eon's 0.028
/// with the same ρs would reflect 45 % less at normal incidence. What enters
/// differs by only 2 % between ior 1.33 and 1.55, under what the 1 % per texel
/// can tell, so also the mean entry factor at 1.55 over that at 1.33 (what the
/// whole chain shares, the SH's quadrature of πL, cancels; 0.2 % in each)
/// against the CPU's ratio, within a tenth of its distance from 1, the ratio
/// of a lobe that ignored the ior.
#[test]
fn a_mediums_boundary_reflects_and_admits_by_its_ior() {
    use dermis::scene::file::MediumPreset;
    let (radiance, m) = (10.0, DEFAULT_M);
    let with_ior = |ior: f32| {
        let mut s = scene(
            sphere(Vec3::ZERO, R, 192, 96, (0.0, 1.0)),
            Vec::new(),
            EnvMap::uniform(Vec3::splat(radiance), 64, 32),
        );
        s.file.skin.medium.preset = Some(MediumPreset::JensenSkin1);
        s.file.skin.medium.ior = ior;
        s
    };
    let s = with_ior(1.55);
    let rho_s = DIELECTRIC_RHO_S;
    let albedo = specular_albedo_table(Lobe::Dielectric { ior: 1.55 });
    let albedo_0 = specular_albedo_table(Lobe::PAPER);
    let img = render(&s, View::named("specular"));
    let expected: Vec<Option<f32>> = pixel_hits(&s.camera, &[(Vec3::ZERO, R)])
        .into_iter()
        .map(|h| {
            let (_, p) = h?;
            let cos = p.normalize().dot((s.camera.position - p).normalize());
            (cos >= 0.3).then(|| rho_s * albedo(cos) * radiance)
        })
        .collect();
    let (n, _) = compare("ior 1.55, uniform sky, specular", |i| img[i * 4], &expected);
    assert!(n > 10_000);
    let at_normal = albedo_0(1.0) / albedo(1.0);
    println!("reflected at normal incidence with F0 0.028: {at_normal:.3} of the ior's");
    assert!(at_normal < 0.7, "{at_normal}");

    // What enters: (GPU mean over the covered texels, 1 − ρs·Ā at the ior's
    // F0, the same at 0.028), each over πL·albedo^mix.
    let scale = std::f32::consts::PI * radiance * ALBEDO.powf(s.file.skin.mix);
    let entry = |ior: f32| {
        let img = render(&with_ior(ior), View::named("irradiance"));
        let want = 1.0 - rho_s * Lobe::Dielectric { ior }.hemispherical_albedo(m);
        let expected: Vec<Option<f32>> = img
            .chunks_exact(4)
            .map(|t| (t[3] > 0.999).then_some(scale * want))
            .collect();
        let (n, _) = compare(
            &format!("ior {ior}, uniform sky, entry"),
            |i| img[i * 4],
            &expected,
        );
        assert!(n > 10_000, "{n}");
        let covered: Vec<f64> = img
            .chunks_exact(4)
            .filter(|t| t[3] > 0.999)
            .map(|t| f64::from(t[0] / scale))
            .collect();
        let mean = (covered.iter().sum::<f64>() / covered.len() as f64) as f32;
        println!("ior {ior}: entry factor GPU mean {mean:.5}, CPU {want:.5}");
        (mean, want)
    };
    let (low, high) = (entry(1.33), entry(1.55));
    let (got, want) = (high.0 / low.0, high.1 / low.1);
    let tolerance = 0.1 * (want - 1.0).abs();
    println!(
        "entry at ior 1.55 over 1.33: GPU {got:.5}, CPU {want:.5} (± {tolerance:.5}), \
         a lobe that ignored the ior 1"
    );
    assert!((got - want).abs() <= tolerance, "{got} against {want}");
}

/// The furnace through the whole frame: a sphere of albedo `rho` (`albedo`, its
/// texture), no occlusion, a uniform L. The specular takes ρs·Ā(m) of the light
/// entering and reflects ρs·A(N·V, m)·L toward the viewer; the diffuse enters
/// with albedo^mix, leaves with albedo^(1−mix) and the exit factor renormalised
/// by 1 − ρs·Ā(m): ρ·L·(1 − ρs·A) + ρs·A·L at every angle, L where ρ = 1.
fn furnace(albedo: Texture, rho: f32) {
    let radiance = 2.0;
    let mut s = scene(
        sphere(Vec3::ZERO, R, 96, 48, (0.0, 1.0)),
        Vec::new(),
        EnvMap::uniform(Vec3::splat(radiance), 64, 32),
    );
    s.albedo = albedo;
    let img = render(&s, View::FINAL);
    let expected: Vec<Option<f32>> = pixel_hits(&s.camera, &[(Vec3::ZERO, R)])
        .into_iter()
        .map(|h| {
            let (_, p) = h?;
            let cos = p.normalize().dot((s.camera.position - p).normalize());
            let reflected = rho_s() * specular_albedo(cos, DEFAULT_M, F0_SKIN);
            (cos >= 0.3).then_some(radiance * (rho * (1.0 - reflected) + reflected))
        })
        .collect();
    for c in 0..3 {
        let (n, _) = compare("furnace", |i| img[i * 4 + c], &expected);
        assert!(n > 10_000, "{n}");
    }
}

#[test]
fn a_white_sphere_under_a_white_sky_reflects_it_whole() {
    furnace(Texture::solid([255, 255, 255, 255], Encoding::Srgb), 1.0);
}

#[test]
fn a_grey_sphere_under_a_white_sky_reflects_its_albedo() {
    // Where the albedo is not 1 its split between entry and exit (mix) must
    // multiply back to the albedo: a white sphere cannot tell.
    furnace(Texture::solid([128, 128, 128, 255], Encoding::Srgb), ALBEDO);
}

/// Relative errors (max over channels) of the GPU prefiltered environment of
/// the CC0 map `name` with `lights` extracted against brute force integration of
/// what it prefilters (the map less those sources), on a grid of texels of
/// three levels.
fn prefilter_errors(dir: &std::path::Path, name: &str, lights: LightsMode) -> Vec<f32> {
    let (map, _) = envmap::load(&dir.join(name)).unwrap();
    let mut s = scene(
        sphere(Vec3::ZERO, R, 32, 16, (0.0, 1.0)),
        Vec::new(),
        map.clone(),
    );
    s.file.environment.lights = lights;
    let env = extract(&map, lights).residual;
    let img = render(&s, View::named("prefiltered"));
    let w = prefilter::WIDTH;
    let mut errors = Vec::new();
    for k in [0, 2, 5] {
        let m = prefilter::level_m(k);
        for y in (4..prefilter::HEIGHT).step_by(8) {
            for x in (3..w).step_by(16) {
                let want = prefilter::reference(&env, prefilter::texel_direction(x, y), m, F0_SKIN);
                let i = ((k * prefilter::HEIGHT + y) * w + x) as usize * 4;
                let got = Vec3::new(img[i], img[i + 1], img[i + 2]);
                errors.push(((got - want).abs() / want.max(Vec3::splat(1e-3))).max_element());
            }
        }
    }
    errors.sort_by(f32::total_cmp);
    println!(
        "{name} (lights = {lights}): prefiltered vs brute force, {} texels of m = 0.1, 0.3, \
         0.6: median {:.2} %, 90th percentile {:.2} %, worst {:.2} %",
        errors.len(),
        100.0 * errors[errors.len() / 2],
        100.0 * errors[errors.len() * 9 / 10],
        100.0 * errors[errors.len() - 1]
    );
    errors
}

#[test]
fn prefiltered_environment_matches_brute_force_integration() {
    let dir = dermis::assets::path("env");
    // A low sun: importance sampling with filtered samples holds it to a few %.
    let e = prefilter_errors(&dir, "venice_sunset_1k.hdr", LightsMode::Auto);
    assert!(e[e.len() / 2] < 0.01 && e[e.len() - 1] < 0.05, "{e:?}");
    // Tiny, very bright lamps: 1024 samples still miss or smear them near
    // their direction (docs/design/lighting.md); the bulk stays close.
    let e = prefilter_errors(&dir, "royal_esplanade_1k.hdr", LightsMode::Count(0));
    assert!(e[e.len() / 2] < 0.02 && e[e.len() * 9 / 10] < 0.2, "{e:?}");
    // Taken out as lights, what is left prefilters nearly as well as the sunset.
    let e = prefilter_errors(&dir, "royal_esplanade_1k.hdr", LightsMode::Auto);
    assert!(e[e.len() / 2] < 0.01 && e[e.len() - 1] < 0.1, "{e:?}");
}

/// The calibration of docs/design/skin.md: under a uniform white sky of radiance 1
/// (occlusion off) the scan's specular is 5–10 % of the light its face
/// reflects (the paper: skin reflects ~9 % specularly; d'Eon ~6 %; a
/// dielectric microfacet surface with F0 = 0.028 gives ~10 %). It was 0.6 %.
#[test]
fn the_scans_specular_share_under_a_uniform_sky() {
    let mut file = dermis::scene::file::scene_by_name(None).unwrap();
    file.environment.source = "uniform:1,1,1".parse().unwrap();
    file.skin.occlusion = Occlusion::Off;
    file.render.skybox = false; // alpha: the mesh's coverage
    file.render.exposure = Some(0.0);
    file.render.width = 96;
    file.render.height = 120;
    file.render.irradiance_resolution = 512;
    let scene = Scene::load(file).unwrap();
    let [total, specular] = [View::FINAL, View::named("specular")].map(|view| render(&scene, view));
    let mean = |img: &[f32]| {
        let (sum, n) = img
            .chunks_exact(4)
            .zip(total.chunks_exact(4))
            .filter(|(_, t)| t[3] > 0.5)
            .fold((0.0f64, 0usize), |(s, n), (p, _)| {
                (s + f64::from(p[0] + p[1] + p[2]) / 3.0, n + 1)
            });
        assert!(n > 1000, "{n} mesh pixels");
        sum / n as f64
    };
    let share = mean(&specular) / mean(&total);
    println!(
        "uniform sky L = 1: mean specular {:.4}, reflected {:.4}, share {:.1} %",
        mean(&specular),
        mean(&total),
        100.0 * share
    );
    assert!((0.05..=0.10).contains(&share), "{share}");
}

#[test]
fn a_polyhedrons_silhouette_is_shaded_as_its_front() {
    // Near a coarse sphere's silhouette the interpolated vertex normal faces
    // away from the camera on faces that face it: the front, whose normal
    // must stay outward (two-sided shading turns only the back's). The
    // `normals` view shows the shading normal every shading pass uses.
    let s = scene(
        sphere(Vec3::ZERO, R, 8, 4, (0.0, 1.0)),
        Vec::new(),
        EnvMap::uniform(Vec3::ONE, 64, 32),
    );
    let img = render(&s, View::named("normals"));
    let (mut leaning_away, mut inward, mut covered) = (0, 0, 0);
    for (k, px) in img.chunks_exact(4).enumerate() {
        if px[3] < 1.0 {
            continue;
        }
        covered += 1;
        let n = Vec3::new(px[0], px[1], px[2]) * 2.0 - 1.0;
        let d = pixel_ray(&s.camera, k as u32 % SIZE, k as u32 / SIZE);
        // The ray's nearest approach to the centre, outward across the view.
        let o = s.camera.position;
        let across = o - d * o.dot(d);
        leaning_away += usize::from(n.dot(d) > 0.0);
        inward += usize::from(across.length() > 0.1 * R && n.dot(across) < 0.0);
    }
    println!("{covered} pixels, {leaning_away} with the normal leaning away, {inward} inward");
    assert!(
        covered > 10_000 && leaning_away >= 50,
        "{covered} {leaning_away}"
    );
    assert_eq!(inward, 0);
}
