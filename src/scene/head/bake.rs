//! Texture bake: every covered texel is evaluated at the 3D point it covers (see
//! `skin`), then the gutters between charts are filled by dilation.

use glam::Vec3;
use rayon::prelude::*;

use super::raster::raster_triangle;
use super::regions::{region_at, REGION_OTHER};
use super::skin::{albedo_at, detail_normal, linear_to_srgb, pores, Palette};
use crate::scene::mesh::Mesh;

/// Per covered texel: the triangle and barycentrics, then procedural evaluation.
pub(super) fn bake_textures(
    mesh: &Mesh,
    size: u32,
    texel_mm: f32,
    seed: u32,
) -> (Vec<u8>, Vec<u8>, Vec<u8>) {
    let n = size as usize;
    let mut hit = vec![(u32::MAX, Vec3::ZERO); n * n];
    for (ti, t) in mesh.indices.chunks_exact(3).enumerate() {
        let uv = [t[0], t[1], t[2]].map(|i| mesh.uvs[i as usize] * size as f32);
        raster_triangle(&uv, n, n, -1e-4, |x, y, b| hit[y * n + x] = (ti as u32, b));
    }
    let pal = Palette::new();
    let mut texels = vec![[0u8; 12]; n * n];
    texels.par_chunks_mut(n).enumerate().for_each(|(y, row)| {
        for (x, out) in row.iter_mut().enumerate() {
            let (ti, b) = hit[y * n + x];
            if ti == u32::MAX {
                continue;
            }
            let i = ti as usize * 3;
            let v = [mesh.indices[i], mesh.indices[i + 1], mesh.indices[i + 2]].map(|k| k as usize);
            let p = mesh.positions[v[0]] * b.x
                + mesh.positions[v[1]] * b.y
                + mesh.positions[v[2]] * b.z;
            let nn =
                (mesh.normals[v[0]] * b.x + mesh.normals[v[1]] * b.y + mesh.normals[v[2]] * b.z)
                    .try_normalize()
                    .unwrap_or(Vec3::Y);
            let t4 =
                mesh.tangents[v[0]] * b.x + mesh.tangents[v[1]] * b.y + mesh.tangents[v[2]] * b.z;
            let t = (t4.truncate() - nn * nn.dot(t4.truncate()))
                .try_normalize()
                .unwrap_or_else(|| nn.any_orthonormal_vector());
            let w = if mesh.tangents[v[0]].w < 0.0 {
                -1.0
            } else {
                1.0
            };
            let bt = nn.cross(t) * w;
            let region = region_at(p);
            let pore = pores(p, region, texel_mm, seed);
            let albedo = linear_to_srgb(albedo_at(p, region, pore.0, seed, &pal));
            let nd = detail_normal(p, (t, bt), region, texel_mm, pore, seed);
            let a = albedo
                .to_array()
                .map(|c| (c * 255.0 + 0.5).clamp(1.0, 255.0) as u8);
            let e = (nd * 0.5 + 0.5)
                .to_array()
                .map(|c| (c * 255.0 + 0.5).clamp(0.0, 255.0) as u8);
            *out = [
                a[0], a[1], a[2], 255, e[0], e[1], e[2], 255, region, 0, 0, 255,
            ];
        }
    });
    dilate(
        &mut texels,
        n,
        hit.iter().map(|h| h.0 != u32::MAX).collect(),
    );
    let mut albedo = Vec::with_capacity(n * n * 4);
    let mut normal = Vec::with_capacity(n * n * 4);
    let mut regions = Vec::with_capacity(n * n * 4);
    for t in &texels {
        albedo.extend_from_slice(&t[0..4]);
        normal.extend_from_slice(&t[4..8]);
        regions.extend_from_slice(&t[8..12]);
    }
    (albedo, normal, regions)
}

/// Fills every uncovered texel, ring by ring outward from the charts, with the mean of
/// its already-filled 8-neighbours (region ids: the first such neighbour's id).
fn dilate(texels: &mut [[u8; 12]], n: usize, mut filled: Vec<bool>) {
    let neighbours = |i: usize| {
        let (x, y) = ((i % n) as i64, (i / n) as i64);
        let mut out = [usize::MAX; 8];
        let mut k = 0;
        for dy in -1..=1i64 {
            for dx in -1..=1i64 {
                let (nx, ny) = (x + dx, y + dy);
                if (dx, dy) != (0, 0) && nx >= 0 && ny >= 0 && nx < n as i64 && ny < n as i64 {
                    out[k] = ny as usize * n + nx as usize;
                    k += 1;
                }
            }
        }
        out
    };
    let mut queued = filled.clone();
    let mut frontier = Vec::new();
    for i in 0..n * n {
        if !filled[i] && neighbours(i).iter().any(|&j| j != usize::MAX && filled[j]) {
            queued[i] = true;
            frontier.push(i);
        }
    }
    if frontier.is_empty() && !filled.iter().any(|&f| f) {
        // Nothing to grow from: a neutral skin tone and flat normals.
        for t in texels.iter_mut() {
            *t = [
                204,
                148,
                122,
                255,
                128,
                128,
                255,
                255,
                REGION_OTHER,
                0,
                0,
                255,
            ];
        }
        return;
    }
    while !frontier.is_empty() {
        let values: Vec<[u8; 12]> = frontier
            .iter()
            .map(|&i| {
                let mut sum = [0u32; 8];
                let mut count = 0;
                let mut region = REGION_OTHER;
                for &j in neighbours(i)
                    .iter()
                    .filter(|&&j| j != usize::MAX && filled[j])
                {
                    if count == 0 {
                        region = texels[j][8];
                    }
                    for (s, v) in sum.iter_mut().zip(&texels[j][..8]) {
                        *s += u32::from(*v);
                    }
                    count += 1;
                }
                let c = count.max(1);
                let m = sum.map(|s| ((s + c / 2) / c) as u8);
                [
                    m[0], m[1], m[2], 255, m[4], m[5], m[6], 255, region, 0, 0, 255,
                ]
            })
            .collect();
        for (&i, v) in frontier.iter().zip(values) {
            texels[i] = v;
            filled[i] = true;
        }
        let mut next = Vec::new();
        for &i in &frontier {
            for j in neighbours(i) {
                if j != usize::MAX && !queued[j] {
                    queued[j] = true;
                    next.push(j);
                }
            }
        }
        frontier = next;
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::super::regions::{
        REGION_COUNT, REGION_LEFT_CHEEK, REGION_LOWER_LIP, REGION_NAMES, REGION_RIGHT_CHEEK,
        REGION_UPPER_LIP,
    };
    use super::super::tests::{head, uv_texels};
    use super::super::BuiltinHead;
    use super::*;

    /// Which texels of the head's atlas a triangle covers.
    fn uv_coverage(h: &BuiltinHead) -> Vec<bool> {
        let n = h.texture_size as usize;
        let mut covered = vec![false; n * n];
        for t in h.mesh.indices.chunks_exact(3) {
            raster_triangle(&uv_texels(&h.mesh, t, n as f32), n, n, 1e-3, |x, y, _| {
                covered[y * n + x] = true
            });
        }
        covered
    }

    #[test]
    fn albedo_is_skin_with_redder_lips() {
        let h = head();
        let covered = uv_coverage(h);
        let mut sums = [(0.0f64, 0usize); REGION_COUNT];
        for (i, &inside) in covered.iter().enumerate() {
            let a = &h.albedo_srgb[i * 4..i * 4 + 4];
            assert_eq!(a[3], 255);
            assert!(a[0] > 2 || a[1] > 2 || a[2] > 2, "black texel {i}");
            let r = h.regions[i * 4];
            assert!((r as usize) < REGION_COUNT);
            if inside {
                let s = &mut sums[r as usize];
                s.0 += f64::from(a[0]) / f64::from(a[1].max(1));
                s.1 += 1;
            }
        }
        let mean = |r: u8| sums[r as usize].0 / sums[r as usize].1.max(1) as f64;
        let cheek = mean(REGION_LEFT_CHEEK).max(mean(REGION_RIGHT_CHEEK));
        assert!(
            mean(REGION_LOWER_LIP) > cheek + 0.1,
            "lip r/g {} cheek {cheek}",
            mean(REGION_LOWER_LIP)
        );
        assert!(mean(REGION_UPPER_LIP) > cheek);
        for (r, s) in sums.iter().enumerate() {
            assert!(s.1 > 100, "region {} has {} texels", REGION_NAMES[r], s.1);
        }
    }

    #[test]
    fn detail_normals_are_unit_and_face_out() {
        let h = head();
        let covered = uv_coverage(h);
        let mut bumped = 0;
        for (px, &inside) in h.normal_detail.chunks_exact(4).zip(&covered) {
            let v = Vec3::new(px[0] as f32, px[1] as f32, px[2] as f32) / 127.5 - Vec3::ONE;
            assert!(v.z > 0.0, "{v}");
            if inside {
                // 8-bit quantisation allows ≈ 1 % error; gutters hold averages.
                assert!((v.length() - 1.0).abs() < 0.02, "{v}");
                // Tilted by more than ≈ 1.5 quantisation steps.
                bumped += usize::from(v.x.abs().max(v.y.abs()) > 0.012);
            }
        }
        let total = covered.iter().filter(|&&c| c).count();
        assert!(
            bumped * 4 > total,
            "only {bumped} of {total} texels carry detail"
        );
    }
}
