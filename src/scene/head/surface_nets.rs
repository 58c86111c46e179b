//! Meshing: naive surface nets. One vertex per sign-changing cell, one quad per
//! sign-changing grid edge. The grid boundary lies outside the head, so the surface
//! is closed; quads are oriented by the edge's sign, so it is consistently oriented.

use glam::Vec3;
use rayon::prelude::*;

use super::sdf::{sdf, sdf_and_gradient, CROWN_Y, NECK_BOTTOM_Y};

/// Mesh of the zero set of [`sdf`] with cells of `h` mm: positions, unit normals and
/// triangles.
pub(super) fn surface_nets(h: f32) -> (Vec<Vec3>, Vec<Vec3>, Vec<[u32; 3]>) {
    // Symmetric in x about 0, so the mesh is mirror-symmetric like the field.
    let half_x = (96.0 / h).ceil() * h;
    let lo = Vec3::new(-half_x, NECK_BOTTOM_Y - 2.0 * h, -112.0);
    let hi = Vec3::new(half_x, CROWN_Y + 2.0 * h, 126.0);
    let dims = ((hi - lo) / h).ceil();
    let (nx, ny, nz) = (
        dims.x as usize + 1,
        dims.y as usize + 1,
        dims.z as usize + 1,
    );
    let sample = |i: usize, j: usize, k: usize| lo + Vec3::new(i as f32, j as f32, k as f32) * h;

    // Sample the field, one z-slab per work item.
    let mut vals = vec![0f32; nx * ny * nz];
    vals.par_chunks_mut(nx * ny)
        .enumerate()
        .for_each(|(k, slab)| {
            for (idx, v) in slab.iter_mut().enumerate() {
                *v = sdf(sample(idx % nx, idx / nx, k));
            }
        });
    let val = |i: usize, j: usize, k: usize| vals[i + nx * (j + ny * k)];

    // Cell vertices: mean of the edge crossings.
    let (cx, cy, cz) = (nx - 1, ny - 1, nz - 1);
    let mut cell_vertex = vec![u32::MAX; cx * cy * cz];
    let mut verts = Vec::new();
    let mut cell_min = Vec::new();
    for k in 0..cz {
        for j in 0..cy {
            for i in 0..cx {
                let mut c = [0f32; 8];
                let mut inside = 0u32;
                for (bit, cv) in c.iter_mut().enumerate() {
                    *cv = val(i + (bit & 1), j + ((bit >> 1) & 1), k + ((bit >> 2) & 1));
                    inside += u32::from(*cv < 0.0);
                }
                if inside == 0 || inside == 8 {
                    continue;
                }
                let mut sum = Vec3::ZERO;
                let mut count = 0.0;
                for a in 0..8usize {
                    for axis_bit in [1usize, 2, 4] {
                        let b = a | axis_bit;
                        if a & axis_bit != 0 || (c[a] < 0.0) == (c[b] < 0.0) {
                            continue;
                        }
                        let t = c[a] / (c[a] - c[b]);
                        let corner = |n: usize| {
                            Vec3::new((n & 1) as f32, ((n >> 1) & 1) as f32, ((n >> 2) & 1) as f32)
                        };
                        sum += corner(a) + (corner(b) - corner(a)) * t;
                        count += 1.0;
                    }
                }
                let m = sample(i, j, k);
                cell_vertex[i + cx * (j + cy * k)] = verts.len() as u32;
                verts.push(m + sum / count * h);
                cell_min.push(m);
            }
        }
    }

    // Project the vertices onto the surface (kept inside their cells) and take
    // normals from the field's gradient.
    let mut normals = vec![Vec3::Y; verts.len()];
    verts
        .par_iter_mut()
        .zip(&mut normals)
        .zip(&cell_min)
        .for_each(|((v, n), &m)| {
            let (lo_c, hi_c) = (m + Vec3::splat(0.02 * h), m + Vec3::splat(0.98 * h));
            for _ in 0..2 {
                let (f, g) = sdf_and_gradient(*v);
                let g2 = g.length_squared();
                if g2 < 1e-8 {
                    break;
                }
                *v = (*v - g * (f / g2)).clamp(lo_c, hi_c);
            }
            *n = sdf_and_gradient(*v).1.try_normalize().unwrap_or(Vec3::Y);
        });

    // Quads around sign-changing edges.
    let cell = |i: usize, j: usize, k: usize| cell_vertex[i + cx * (j + cy * k)];
    let mut tris = Vec::new();
    for k in 1..nz - 1 {
        for j in 1..ny - 1 {
            for i in 1..nx - 1 {
                let s = [i, j, k];
                let inside = val(i, j, k) < 0.0;
                for a in 0..3 {
                    let mut nb = s;
                    nb[a] += 1;
                    if (val(nb[0], nb[1], nb[2]) < 0.0) == inside {
                        continue;
                    }
                    let (u, v) = ((a + 1) % 3, (a + 2) % 3);
                    let at = |du: usize, dv: usize| {
                        let mut c = s;
                        c[u] -= du;
                        c[v] -= dv;
                        cell(c[0], c[1], c[2])
                    };
                    // Counter-clockwise around +axis a.
                    let mut quad = [at(1, 1), at(0, 1), at(0, 0), at(1, 0)];
                    if !inside {
                        quad.reverse();
                    }
                    if quad.contains(&u32::MAX) {
                        continue; // cannot happen: all four cells straddle the edge
                    }
                    let p = quad.map(|q| verts[q as usize]);
                    if (p[0] - p[2]).length_squared() <= (p[1] - p[3]).length_squared() {
                        tris.push([quad[0], quad[1], quad[2]]);
                        tris.push([quad[0], quad[2], quad[3]]);
                    } else {
                        tris.push([quad[0], quad[1], quad[3]]);
                        tris.push([quad[1], quad[2], quad[3]]);
                    }
                }
            }
        }
    }
    // Where the field's gradient is unreliable (features thinner than a cell), use
    // the area-weighted normal of the adjacent faces instead.
    let mut face_n = vec![Vec3::ZERO; verts.len()];
    for t in &tris {
        let [a, b, c] = t.map(|i| verts[i as usize]);
        let n = (b - a).cross(c - a);
        for &i in t {
            face_n[i as usize] += n;
        }
    }
    for (n, f) in normals.iter_mut().zip(face_n) {
        if let Some(f) = f.try_normalize() {
            if n.dot(f) < 0.3 {
                *n = f;
            }
        }
    }
    (verts, normals, tris)
}

#[cfg(test)]
mod tests {
    use super::super::tests::head;
    use super::*;

    #[test]
    fn mesh_is_valid_closed_and_sized() {
        let h = head();
        let m = &h.mesh;
        m.validate().unwrap();
        let tris = m.triangle_count();
        assert!((20_000..=80_000).contains(&tris), "{tris} triangles");
        // Weld by position: every directed edge must meet its reverse exactly as often
        // (closed, consistently oriented surface before the UV split).
        let mut id = std::collections::HashMap::new();
        let weld: Vec<u32> = m
            .positions
            .iter()
            .map(|p| {
                let key = p.to_array().map(f32::to_bits);
                let next = id.len() as u32;
                *id.entry(key).or_insert(next)
            })
            .collect();
        let mut edges = std::collections::HashMap::<(u32, u32), i32>::new();
        for t in m.indices.chunks_exact(3) {
            for k in 0..3 {
                let (a, b) = (weld[t[k] as usize], weld[t[(k + 1) % 3] as usize]);
                *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
            }
        }
        let open = edges.values().filter(|&&v| v != 0).count();
        assert_eq!(open, 0, "unmatched edges");
        // Normals are unit and point outward (the field grows along them), except at
        // the few vertices of sub-cell features where face normals stand in.
        let mut inward = 0;
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!((n.length() - 1.0).abs() < 1e-3);
            inward += usize::from(sdf(*p + *n * 0.5) <= sdf(*p - *n * 0.5));
        }
        assert!(inward * 1000 < m.vertex_count(), "{inward} inward normals");
    }
}
