//! Test meshes shared by the occlusion tests.

use std::f32::consts::PI;

use glam::{Vec2, Vec3, Vec4};

use crate::scene::mesh::Mesh;

/// Mesh from positions, normals and triangles (other attributes filled).
pub(crate) fn mesh(positions: Vec<Vec3>, normals: Vec<Vec3>, indices: Vec<u32>) -> Mesh {
    let n = positions.len();
    Mesh {
        name: "test".into(),
        positions,
        normals,
        uvs: vec![Vec2::ZERO; n],
        tangents: vec![Vec4::X; n],
        indices,
    }
}

/// Appends a quad (two triangles) with corners in order and normal `nrm`.
pub(super) fn quad(
    p: &mut Vec<Vec3>,
    n: &mut Vec<Vec3>,
    idx: &mut Vec<u32>,
    c: [Vec3; 4],
    nrm: Vec3,
) {
    let b = p.len() as u32;
    p.extend(c);
    n.extend([nrm; 4]);
    idx.extend([b, b + 1, b + 2, b, b + 2, b + 3]);
}

/// Ground square of half-size `h` in y = 0, built as a fan around vertex 0
/// at the origin (normal +Y).
pub(super) fn ground(h: f32) -> (Vec<Vec3>, Vec<Vec3>, Vec<u32>) {
    let p = vec![
        Vec3::ZERO,
        Vec3::new(-h, 0.0, -h),
        Vec3::new(h, 0.0, -h),
        Vec3::new(h, 0.0, h),
        Vec3::new(-h, 0.0, h),
    ];
    let n = vec![Vec3::Y; 5];
    let idx = vec![0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1];
    (p, n, idx)
}

/// Cylinder cavity of radius `r`, depth `d` around +Y, open at the top,
/// floor fanned around vertex 0 at the origin; `seg` wall segments.
pub(super) fn cylinder(r: f32, d: f32, seg: u32) -> Mesh {
    let mut p = vec![Vec3::ZERO];
    let mut n = vec![Vec3::Y];
    let mut idx = Vec::new();
    let ring = |k: u32| {
        let a = 2.0 * PI * k as f32 / seg as f32;
        Vec3::new(a.cos(), 0.0, a.sin())
    };
    for k in 0..seg {
        p.push(ring(k) * r);
        n.push(Vec3::Y);
        idx.extend([0, 1 + k, 1 + (k + 1) % seg]);
    }
    for k in 0..seg {
        let (a, b) = (ring(k), ring(k + 1));
        let nrm = -(a + b).normalize();
        let up = Vec3::Y * d;
        quad(
            &mut p,
            &mut n,
            &mut idx,
            [a * r, b * r, b * r + up, a * r + up],
            nrm,
        );
    }
    mesh(p, n, idx)
}

/// A sphere of radius `r` about the origin without the cap within polar angle
/// `alpha` of +Y (0: whole), normals outward: `rings` rings of `segments`
/// vertices from `alpha` towards −Y, closed by a vertex at the pole.
pub(crate) fn open_sphere(r: f32, alpha: f32, rings: u32, segments: u32) -> Mesh {
    let (mut p, mut n, mut idx) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..rings {
        let theta = alpha.max(1e-3) + (PI - alpha.max(1e-3)) * i as f32 / rings as f32;
        for j in 0..segments {
            let phi = 2.0 * PI * j as f32 / segments as f32;
            let d = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            p.push(r * d);
            n.push(d);
        }
    }
    let pole = p.len() as u32;
    p.push(Vec3::new(0.0, -r, 0.0));
    n.push(Vec3::NEG_Y);
    let at = |i: u32, j: u32| i * segments + j % segments;
    for i in 0..rings {
        for j in 0..segments {
            if i + 1 < rings {
                let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
                idx.extend([a, b, c, a, c, d]);
            } else {
                idx.extend([at(i, j), at(i, j + 1), pole]);
            }
        }
    }
    mesh(p, n, idx)
}

/// [`ground`] of half-size 1000 mm with vertex 0 at the origin, and a 1000 mm
/// wall at x = 0.5 mm facing it (−X): it blocks ω.x > 0 as seen from vertex 0
/// (but for directions within ~1e-3 rad of its top and side edges).
pub(super) fn floor_beside_a_wall() -> Mesh {
    let (mut p, mut n, mut idx) = ground(1000.0);
    let (x, h) = (0.5, 1000.0);
    let corners = [
        Vec3::new(x, 0.0, -h),
        Vec3::new(x, h, -h),
        Vec3::new(x, h, h),
        Vec3::new(x, 0.0, h),
    ];
    quad(&mut p, &mut n, &mut idx, corners, Vec3::NEG_X);
    mesh(p, n, idx)
}
