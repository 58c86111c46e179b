//! `textures.uv_origin` on the Lee Perry-Smith scan, whose maps are authored for
//! a bottom-left origin (assets/README.md): with `bottom-left` the colour map puts
//! red on the lips and the normal map's detail follows the mesh's own curvature;
//! forced to `top-left`, both checks fail. CPU only: the maps and the mesh come
//! from `Scene::load`, and the checks sample them as the shaders do.

use std::path::Path;

use glam::{Vec2, Vec3};

use super::file::{load_scene, UvOrigin};
use super::mesh::Mesh;
use super::texture::{srgb_to_linear, Texture};
use super::{Overrides, Scene};

const SCENES: [&str; 2] = [
    "docs/scenes/lee-perry-smith.toml",
    "docs/scenes/lee-perry-smith-lights.toml",
];

/// docs/scenes/lee-perry-smith.toml loaded by `Scene::load` with its UV origin
/// replaced, as `--uv-origin` does.
fn scan_scene(origin: UvOrigin) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(SCENES[0]);
    let file = load_scene(&path).unwrap();
    let overrides = Overrides {
        uv_origin: Some(origin),
        ..Overrides::default()
    };
    Scene::load(overrides.apply(file).unwrap()).unwrap()
}

/// RGB of an RGBA8 texture as floats, `decode` applied per channel.
struct Rgb {
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
}

impl Rgb {
    fn of(t: &Texture, decode: impl Fn(u8) -> f32) -> Rgb {
        Rgb {
            width: t.width as usize,
            height: t.height as usize,
            texels: t
                .rgba8
                .chunks_exact(4)
                .map(|p| Vec3::new(decode(p[0]), decode(p[1]), decode(p[2])))
                .collect(),
        }
    }

    /// The next mip level: 2 × 2 box average (the GPU's blit chain for even sizes).
    fn half(&self) -> Rgb {
        let (w, h) = (self.width / 2, self.height / 2);
        let at = |x: usize, y: usize| self.texels[y * self.width + x];
        let texels = (0..w * h)
            .map(|i| {
                let (x, y) = (2 * (i % w), 2 * (i / w));
                0.25 * (at(x, y) + at(x + 1, y) + at(x, y + 1) + at(x + 1, y + 1))
            })
            .collect();
        Rgb {
            width: w,
            height: h,
            texels,
        }
    }

    /// Bilinear filtering with clamp-to-edge, texel centres at (i + ½)/size
    /// (Vulkan 1.2 §16.6; the renderer's `Sampler::clamped`).
    fn sample(&self, uv: Vec2) -> Vec3 {
        let x = uv.x * self.width as f32 - 0.5;
        let y = uv.y * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let at = |dx: f32, dy: f32| {
            let xi = ((x0 + dx) as isize).clamp(0, self.width as isize - 1) as usize;
            let yi = ((y0 + dy) as isize).clamp(0, self.height as isize - 1) as usize;
            self.texels[yi * self.width + xi]
        };
        let top = at(0.0, 0.0).lerp(at(1.0, 0.0), fx);
        let bottom = at(0.0, 1.0).lerp(at(1.0, 1.0), fx);
        top.lerp(bottom, fy)
    }
}

/// The most forward vertex (+Z, glTF's front; docs/reference/scene-format.md) within
/// `r` mm of (x, y).
fn front_vertex(mesh: &Mesh, x: f32, y: f32, r: f32) -> usize {
    (0..mesh.vertex_count())
        .filter(|&i| {
            let p = mesh.positions[i];
            (p.x - x).abs() < r && (p.y - y).abs() < r
        })
        .max_by(|&a, &b| mesh.positions[a].z.total_cmp(&mesh.positions[b].z))
        .unwrap_or_else(|| panic!("no vertex near x = {x}, y = {y}"))
}

/// The nose tip: the most forward vertex within 10 mm of the midline (the scan
/// is centred on x = 0) in the middle half of the height.
fn nose_tip(mesh: &Mesh) -> Vec3 {
    let (lo, hi) = mesh.bounds().unwrap();
    let (mid_x, mid_y, quarter) = (
        0.5 * (lo.x + hi.x),
        0.5 * (lo.y + hi.y),
        0.25 * (hi.y - lo.y),
    );
    mesh.positions
        .iter()
        .filter(|p| (p.x - mid_x).abs() < 10.0 && (p.y - mid_y).abs() < quarter)
        .copied()
        .max_by(|a, b| a.z.total_cmp(&b.z))
        .unwrap()
}

/// Mean linear-chromaticity redness r / (r + g + b) of the colour map at the
/// vertices' UVs, sampled bilinearly after sRGB decoding (the shader reads an
/// `_SRGB` view, so filtering happens on linear values).
fn redness(map: &Rgb, mesh: &Mesh, vertices: &[usize]) -> f32 {
    let sum: f32 = vertices
        .iter()
        .map(|&i| {
            let c = map.sample(mesh.uvs[i]);
            c.x / (c.x + c.y + c.z)
        })
        .sum();
    sum / vertices.len() as f32
}

/// Lip and cheek redness for one origin: lips on the midline 20–40 mm below the
/// nose tip, cheeks 40–50 mm to either side at nose height (±5 mm), each on the
/// front surface.
fn lips_and_cheeks(scene: &Scene) -> (f32, f32) {
    let mesh = &scene.mesh;
    let nose = nose_tip(mesh);
    let mut lips = Vec::new();
    for dy in [20.0, 25.0, 30.0, 35.0, 40.0] {
        for dx in [-6.0, 0.0, 6.0] {
            lips.push(front_vertex(mesh, nose.x + dx, nose.y - dy, 4.0));
        }
    }
    let mut cheeks = Vec::new();
    for side in [-1.0, 1.0] {
        for dx in [40.0, 45.0, 50.0] {
            for dy in [-5.0, 0.0, 5.0] {
                cheeks.push(front_vertex(mesh, nose.x + side * dx, nose.y + dy, 4.0));
            }
        }
    }
    // +Z is the front and the nose protrudes: the lips lie within 25 mm of the
    // tip's depth, the cheeks at least 20 mm behind it (measured 12–16, 30–45).
    let depth = |i: &usize| nose.z - mesh.positions[*i].z;
    assert!(lips.iter().all(|i| depth(i) < 25.0), "lips off the face");
    assert!(cheeks.iter().all(|i| depth(i) > 20.0), "no nose in front");
    let albedo = Rgb::of(&scene.albedo, |c| srgb_to_linear(f32::from(c) / 255.0));
    (
        redness(&albedo, mesh, &lips),
        redness(&albedo, mesh, &cheeks),
    )
}

/// The triangles' undirected edges, each once.
fn edges(mesh: &Mesh) -> Vec<(usize, usize)> {
    let mut e: Vec<(usize, usize)> = mesh
        .indices
        .chunks_exact(3)
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| (a.min(b) as usize, a.max(b) as usize))
        .collect();
    e.sort_unstable();
    e.dedup();
    e
}

/// Per vertex, the mean over its edges of (n_j − n_i)·(p_j − p_i) / |p_j − p_i|²:
/// normal curvature along the edges, 1/R on a sphere of radius R (outward
/// normals), so convex is positive. In 1/mm.
fn edge_curvature(mesh: &Mesh, edges: &[(usize, usize)], normals: &[Vec3]) -> Vec<f32> {
    let mut sum = vec![0.0f32; mesh.vertex_count()];
    let mut count = vec![0u32; mesh.vertex_count()];
    for &(i, j) in edges {
        let d = mesh.positions[j] - mesh.positions[i];
        if d.length_squared() < 1e-6 {
            continue;
        }
        let k = (normals[j] - normals[i]).dot(d) / d.length_squared();
        for v in [i, j] {
            sum[v] += k;
            count[v] += 1;
        }
    }
    sum.iter()
        .zip(&count)
        .map(|(s, &c)| s / c.max(1) as f32)
        .collect()
}

/// The shading normal at every vertex as `map_normal` (common/normal_map.glsl)
/// builds it: t orthonormalised against n, b = w · n × t, m.xy = (255c − 128)/127,
/// m.z = 2c − 1.
fn mapped_normals(mesh: &Mesh, map: &Rgb) -> Vec<Vec3> {
    (0..mesh.vertex_count())
        .map(|i| {
            let n = mesh.normals[i].normalize();
            let t4 = mesh.tangents[i];
            let t = (t4.truncate() - n * n.dot(t4.truncate())).normalize();
            let b = n.cross(t) * t4.w;
            let c = map.sample(mesh.uvs[i]);
            let m = Vec3::new(
                (c.x * 255.0 - 128.0) / 127.0,
                (c.y * 255.0 - 128.0) / 127.0,
                c.z * 2.0 - 1.0,
            );
            (m.x * t + m.y * b + m.z * n).normalize()
        })
        .collect()
}

fn pearson(a: &[f32], b: &[f32]) -> f64 {
    let n = a.len() as f64;
    let mean = |x: &[f32]| x.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let (ma, mb) = (mean(a), mean(b));
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (&x, &y) in a.iter().zip(b) {
        let (x, y) = (f64::from(x) - ma, f64::from(y) - mb);
        sab += x * y;
        saa += x * x;
        sbb += y * y;
    }
    sab / (saa * sbb).sqrt()
}

/// Pearson correlation of the ranks (ties broken by index; the values are floats).
fn spearman(a: &[f32], b: &[f32]) -> f64 {
    let ranks = |x: &[f32]| {
        let mut order: Vec<usize> = (0..x.len()).collect();
        order.sort_by(|&i, &j| x[i].total_cmp(&x[j]));
        let mut r = vec![0.0f32; x.len()];
        for (rank, &i) in order.iter().enumerate() {
            r[i] = rank as f32;
        }
        r
    };
    pearson(&ranks(a), &ranks(b))
}

/// Correlations (Pearson, Spearman) over the vertices of the normal map's detail
/// curvature (the edge curvature of the mapped normals minus that of the mesh
/// normals) with the mesh's own edge curvature, the map read `mip` levels down.
fn detail_vs_curvature(mesh: &Mesh, normal_map: &Texture, mip: usize) -> (f64, f64) {
    let mut map = Rgb::of(normal_map, |c| f32::from(c) / 255.0);
    for _ in 0..mip {
        map = map.half();
    }
    let e = edges(mesh);
    let mesh_k = edge_curvature(mesh, &e, &mesh.normals);
    let mapped_k = edge_curvature(mesh, &e, &mapped_normals(mesh, &map));
    let detail: Vec<f32> = mapped_k.iter().zip(&mesh_k).map(|(a, b)| a - b).collect();
    (pearson(&detail, &mesh_k), spearman(&detail, &mesh_k))
}

#[test]
fn scan_scenes_declare_a_bottom_left_origin() {
    for scene in SCENES {
        let file = load_scene(&Path::new(env!("CARGO_MANIFEST_DIR")).join(scene)).unwrap();
        assert_eq!(file.textures.uv_origin, UvOrigin::BottomLeft, "{scene}");
    }
}

#[test]
fn bottom_left_puts_the_scan_maps_in_place() {
    let bottom = scan_scene(UvOrigin::BottomLeft);
    let top = scan_scene(UvOrigin::TopLeft);
    // The scene's mesh is the scan at 50.3 mm per unit (assets/README.md).
    let direct =
        super::gltf::load_mesh(&crate::assets::scan().join("LeePerrySmith.glb"), Some(50.3))
            .unwrap();
    assert_eq!(bottom.mesh.positions, direct.positions);
    assert_eq!(bottom.mesh.uvs, top.mesh.uvs, "the UVs stay as authored");

    // Colour: the lips redder than the cheeks by at least 0.05 in linear
    // chromaticity. Measured: bottom-left 0.603 vs 0.506, top-left 0.469 vs 0.463.
    let lips_are_red = |(lips, cheeks): (f32, f32)| lips - cheeks > 0.05;
    let (b, t) = (lips_and_cheeks(&bottom), lips_and_cheeks(&top));
    println!(
        "redness r/(r+g+b), linear: bottom-left lips {:.3} cheeks {:.3}; \
         top-left lips {:.3} cheeks {:.3}",
        b.0, b.1, t.0, t.1
    );
    assert!(
        lips_are_red(b),
        "bottom-left: lips {:.3}, cheeks {:.3}",
        b.0,
        b.1
    );
    assert!(
        !lips_are_red(t),
        "top-left: lips {:.3}, cheeks {:.3}",
        t.0,
        t.1
    );

    // Normal map: its detail curvature follows the mesh's own (convex detail
    // where the mesh is convex), read two mips down: 4 × 4 texels, near the
    // median edge (5.3 texels), so edge differences do not alias the map.
    // Measured (Pearson, Spearman): bottom-left 0.233, 0.300; bottom-left with
    // w not negated −0.180, −0.024; top-left −0.077, −0.044.
    let follows = |(p, s): (f64, f64)| p > 0.15 && s > 0.15;
    let mut unnegated = bottom.mesh.clone();
    unnegated.negate_bitangent_sign();
    let mut passed = Vec::new();
    for (name, mesh, map) in [
        ("bottom-left", &bottom.mesh, &bottom.normal),
        ("bottom-left, w not negated", &unnegated, &bottom.normal),
        ("top-left", &top.mesh, &top.normal),
    ] {
        let (p, s) = detail_vs_curvature(mesh, map, 2);
        println!("normal-map detail vs mesh curvature, {name}: pearson {p:.3}, spearman {s:.3}");
        passed.push(follows((p, s)));
    }
    assert_eq!(passed, [true, false, false]);
}
