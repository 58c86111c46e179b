//! Normals where a file has none, and MikkTSpace tangents (with the sign
//! convention of the module documentation).

use std::collections::HashMap;
use std::path::Path;

use glam::{Vec3, Vec4};

use super::Part;

/// Twice the triangle's area along its normal: (b - a) × (c - a).
pub(super) fn face_cross(positions: &[Vec3], tri: &[u32]) -> Vec3 {
    let p = |k: usize| {
        tri.get(k)
            .and_then(|&i| positions.get(i as usize))
            .copied()
            .unwrap_or(Vec3::ZERO)
    };
    (p(1) - p(0)).cross(p(2) - p(0))
}

/// Area-weighted vertex normals, accumulated over vertices at identical positions
/// so UV seams (split vertices) stay smooth. Vertices touching only degenerate
/// triangles get +Z.
pub(super) fn smooth_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    // `+ 0.0` turns -0.0 into 0.0 so both hash alike.
    let key = |p: Vec3| {
        [
            (p.x + 0.0).to_bits(),
            (p.y + 0.0).to_bits(),
            (p.z + 0.0).to_bits(),
        ]
    };
    let mut sums: HashMap<[u32; 3], Vec3> = HashMap::new();
    for tri in indices.chunks_exact(3) {
        let n = face_cross(positions, tri);
        for &i in tri {
            if let Some(&p) = positions.get(i as usize) {
                *sums.entry(key(p)).or_insert(Vec3::ZERO) += n;
            }
        }
    }
    positions
        .iter()
        .map(|&p| {
            sums.get(&key(p))
                .map(|n| n.normalize_or_zero())
                .filter(|n| *n != Vec3::ZERO)
                .unwrap_or(Vec3::Z)
        })
        .collect()
}

/// MikkTSpace adapter; writes one tangent per triangle corner.
pub(super) struct MikkInput<'a> {
    part: &'a Part,
    corners: Vec<Option<Vec4>>,
}

impl MikkInput<'_> {
    fn vertex(&self, face: usize, vert: usize) -> usize {
        self.part
            .indices
            .get(face * 3 + vert)
            .map_or(0, |&i| i as usize)
    }
}

impl mikktspace::Geometry for MikkInput<'_> {
    fn num_faces(&self) -> usize {
        self.part.indices.len() / 3
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        let v = self.vertex(face, vert);
        self.part
            .positions
            .get(v)
            .copied()
            .unwrap_or_default()
            .into()
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        let v = self.vertex(face, vert);
        self.part.normals.get(v).copied().unwrap_or(Vec3::Z).into()
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        // glTF's v points down; MikkTSpace (like Blender) expects v up. Flipping v
        // here yields glTF's bitangent sign directly.
        let uv = self
            .part
            .uvs
            .get(self.vertex(face, vert))
            .copied()
            .unwrap_or_default();
        [uv.x, 1.0 - uv.y]
    }
    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
        if let Some(slot) = self.corners.get_mut(face * 3 + vert) {
            *slot = Some(Vec4::from(tangent));
        }
    }
}

/// MikkTSpace tangents (Mikkelsen 2008, the glTF 2.0 reference for generated
/// tangents). A vertex whose corners get different tangents (mirrored UVs) is
/// split so each copy keeps its own.
pub(super) fn mikktspace_tangents(part: &mut Part) -> Result<(), String> {
    let mut input = MikkInput {
        part,
        corners: vec![None; part.indices.len()],
    };
    // The crate is a C translation; guard against a panic inside it (input here is
    // already finite and in range).
    let ok = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        mikktspace::generate_tangents(&mut input)
    }))
    .map_err(|_| "MikkTSpace tangent generation failed")?;
    if !ok {
        return Err("MikkTSpace tangent generation failed".into());
    }
    let corners = input.corners;

    let same = |a: Vec4, b: Vec4| a.w == b.w && a.truncate().dot(b.truncate()) > 0.9999;
    let n = part.positions.len();
    let mut tangent: Vec<Option<Vec4>> = vec![None; n];
    // original vertex -> its extra copies (new index, tangent)
    let mut copies: HashMap<u32, Vec<(u32, Vec4)>> = HashMap::new();
    let mut extra: Vec<(u32, Vec4)> = Vec::new();
    for (slot, t) in part.indices.iter_mut().zip(corners) {
        let Some(t) = t else { continue };
        let v = *slot;
        let Some(current) = tangent.get_mut(v as usize) else {
            continue;
        };
        match current {
            None => *current = Some(t),
            Some(existing) if same(*existing, t) => {}
            Some(_) => {
                let list = copies.entry(v).or_default();
                if let Some(&(copy, _)) = list.iter().find(|(_, ct)| same(*ct, t)) {
                    *slot = copy;
                } else {
                    let copy = u32::try_from(n + extra.len()).map_err(|_| "too many vertices")?;
                    list.push((copy, t));
                    extra.push((v, t));
                    *slot = copy;
                }
            }
        }
    }
    part.tangents = tangent
        .into_iter()
        .map(|t| t.unwrap_or(Vec4::ZERO))
        .collect();
    for (v, t) in extra {
        let v = v as usize;
        let (Some(&p), Some(&nm), Some(&uv)) =
            (part.positions.get(v), part.normals.get(v), part.uvs.get(v))
        else {
            continue;
        };
        part.positions.push(p);
        part.normals.push(nm);
        part.uvs.push(uv);
        part.tangents.push(t);
    }
    Ok(())
}

/// Gram–Schmidt: makes each tangent unit length and perpendicular to its normal;
/// where that is impossible (tangent parallel to the normal or zero) any
/// perpendicular unit vector is used.
pub(super) fn orthonormalise_tangents(part: &mut Part, path: &Path) {
    let mut fallback = 0usize;
    for (t, n) in part.tangents.iter_mut().zip(&part.normals) {
        let w = if t.w < 0.0 { -1.0 } else { 1.0 };
        let xyz = t.truncate();
        let ortho = (xyz - *n * n.dot(xyz)).normalize_or_zero();
        let ortho = if ortho == Vec3::ZERO {
            fallback += 1;
            n.any_orthonormal_vector()
        } else {
            ortho
        };
        *t = ortho.extend(w);
    }
    if fallback > 0 {
        log::warn!(
            "{}: {fallback} vertices have no usable UV gradient; gave them an arbitrary tangent",
            path.display()
        );
    }
}
