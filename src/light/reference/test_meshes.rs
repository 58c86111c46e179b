//! Meshes of the reference integrator's closed-form tests.

use std::f32::consts::PI;

use glam::{Vec2, Vec3, Vec4};

use crate::light::occlusion::testutil::mesh;
use crate::scene::mesh::Mesh;

/// Square of half-size `h` in y = 0 about the origin, normal +Y.
pub fn plane(h: f32) -> Mesh {
    let p = vec![
        Vec3::new(-h, 0.0, -h),
        Vec3::new(h, 0.0, -h),
        Vec3::new(h, 0.0, h),
        Vec3::new(-h, 0.0, h),
    ];
    mesh(p, vec![Vec3::Y; 4], vec![0, 1, 2, 0, 2, 3])
}

/// [`plane`] plus a wall in x = 0 from the floor up to y = `h`, across z ∈ [−h, h].
pub fn floor_and_wall(h: f32) -> Mesh {
    let mut m = plane(h);
    m.positions.extend([
        Vec3::new(0.0, 0.0, -h),
        Vec3::new(0.0, h, -h),
        Vec3::new(0.0, h, h),
        Vec3::new(0.0, 0.0, h),
    ]);
    m.normals.extend([Vec3::NEG_X; 4]);
    m.uvs.extend([Vec2::ZERO; 4]);
    m.tangents.extend([Vec4::X; 4]);
    m.indices.extend([4, 5, 6, 4, 6, 7]);
    m
}

/// Latitude-longitude sphere of radius `r` about the origin: `rings` bands,
/// `segments` around; every vertex on the sphere, with the radial normal (so the
/// mesh is a convex polyhedron inside the sphere and never shadows a vertex's
/// upper hemisphere).
pub fn sphere(r: f32, rings: u32, segments: u32) -> Mesh {
    let (mut p, mut idx) = (vec![Vec3::Y * r], Vec::new());
    for i in 1..rings {
        let theta = PI * i as f32 / rings as f32;
        for k in 0..segments {
            let phi = 2.0 * PI * k as f32 / segments as f32;
            p.push(
                r * Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                ),
            );
        }
    }
    p.push(Vec3::NEG_Y * r);
    let ring = |i: u32, k: u32| 1 + (i - 1) * segments + k % segments;
    let last = p.len() as u32 - 1;
    for k in 0..segments {
        idx.extend([0, ring(1, k + 1), ring(1, k)]);
        idx.extend([last, ring(rings - 1, k), ring(rings - 1, k + 1)]);
        for i in 1..rings - 1 {
            let (a, b) = (ring(i, k), ring(i, k + 1));
            let (c, d) = (ring(i + 1, k), ring(i + 1, k + 1));
            idx.extend([a, b, d, a, d, c]);
        }
    }
    let normals = p.iter().map(|v| v.normalize()).collect();
    mesh(p, normals, idx)
}
