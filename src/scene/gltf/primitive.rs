//! One triangle primitive: attributes read, checked and transformed to world
//! millimetres.

use std::path::Path;

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use gltf::mesh::Semantic;

use super::accessor::{read_floats, read_indices};
use super::tangents::{face_cross, mikktspace_tangents, orthonormalise_tangents, smooth_normals};
use super::Part;

pub(super) fn read_primitive(
    prim: &gltf::Primitive,
    buffers: &[Vec<u8>],
    world: Mat4,
    scale: f32,
    path: &Path,
) -> Result<Part, String> {
    let Attributes {
        positions,
        uvs,
        normals,
        tangents,
        mut indices,
    } = read_attributes(prim, buffers)?;
    check_attributes(&positions, &uvs, &normals, &tangents, &indices)?;
    let transform = Transform::new(world)?;
    let positions = world_positions(&positions, world, scale)?;
    if transform.mirrored {
        for tri in indices.chunks_exact_mut(3) {
            tri.swap(1, 2);
        }
    }
    let triangle_area_sum: f32 = indices
        .chunks_exact(3)
        .map(|t| face_cross(&positions, t).length())
        .sum();
    if triangle_area_sum.is_nan() || triangle_area_sum <= 0.0 {
        return Err("every triangle is degenerate (zero area)".into());
    }
    let normals = world_normals(normals, &transform, &positions, &indices, path);
    let mut part = Part {
        positions,
        normals,
        uvs,
        tangents: Vec::new(),
        indices,
    };
    set_tangents(&mut part, tangents, &transform, path)?;
    orthonormalise_tangents(&mut part, path);
    Ok(part)
}

/// A primitive's attributes as stored in the file (before any check but the
/// vertex count).
struct Attributes {
    positions: Vec<Vec3>,
    uvs: Vec<Vec2>,
    normals: Option<Vec<Vec3>>,
    tangents: Option<Vec<Vec4>>,
    indices: Vec<u32>,
}

/// Decodes POSITION, TEXCOORD_0, NORMAL, TANGENT and the indices (0..n where
/// the primitive has none).
fn read_attributes(prim: &gltf::Primitive, buffers: &[Vec<u8>]) -> Result<Attributes, String> {
    let attr = |s: Semantic| prim.get(&s);
    let positions: Vec<Vec3> = match attr(Semantic::Positions) {
        Some(a) => read_floats::<3>(&a, buffers, "POSITION")?
            .into_iter()
            .map(Vec3::from)
            .collect(),
        None => return Err("no POSITION attribute".into()),
    };
    let n = positions.len();
    if n == 0 {
        return Err("no vertices".into());
    }
    let uvs: Vec<Vec2> = match attr(Semantic::TexCoords(0)) {
        Some(a) => read_floats::<2>(&a, buffers, "TEXCOORD_0")?
            .into_iter()
            .map(Vec2::from)
            .collect(),
        None => {
            return Err(
                "no TEXCOORD_0 attribute: texture-space diffusion needs UV coordinates".into(),
            )
        }
    };
    let normals: Option<Vec<Vec3>> = match attr(Semantic::Normals) {
        Some(a) => Some(
            read_floats::<3>(&a, buffers, "NORMAL")?
                .into_iter()
                .map(Vec3::from)
                .collect(),
        ),
        None => None,
    };
    let tangents: Option<Vec<Vec4>> = match attr(Semantic::Tangents) {
        Some(a) => Some(
            read_floats::<4>(&a, buffers, "TANGENT")?
                .into_iter()
                .map(Vec4::from)
                .collect(),
        ),
        None => None,
    };
    let indices = match prim.indices() {
        Some(a) => read_indices(&a, buffers)?,
        None => (0..u32::try_from(n).map_err(|_| "too many vertices")?).collect(),
    };
    Ok(Attributes {
        positions,
        uvs,
        normals,
        tangents,
        indices,
    })
}

/// Shape checks (one element per vertex, whole triangles, indices in range),
/// then finiteness.
fn check_attributes(
    positions: &[Vec3],
    uvs: &[Vec2],
    normals: &Option<Vec<Vec3>>,
    tangents: &Option<Vec<Vec4>>,
    indices: &[u32],
) -> Result<(), String> {
    let n = positions.len();
    check_len("TEXCOORD_0", uvs.len(), n)?;
    if let Some(v) = normals {
        check_len("NORMAL", v.len(), n)?;
    }
    if let Some(v) = tangents {
        check_len("TANGENT", v.len(), n)?;
    }
    if indices.is_empty() || !indices.len().is_multiple_of(3) {
        return Err(format!(
            "{} indices do not form whole triangles",
            indices.len()
        ));
    }
    if let Some((k, i)) = indices.iter().enumerate().find(|(_, &i)| i as usize >= n) {
        return Err(format!("index {k} is {i}, but there are only {n} vertices"));
    }
    check_finite("POSITION", positions.iter().map(|v| v.is_finite()))?;
    check_finite("TEXCOORD_0", uvs.iter().map(|v| v.is_finite()))?;
    if let Some(v) = normals {
        check_finite("NORMAL", v.iter().map(|v| v.is_finite()))?;
    }
    if let Some(v) = tangents {
        check_finite("TANGENT", v.iter().map(|v| v.is_finite()))?;
    }
    Ok(())
}

/// The node's world transform as it applies to each attribute: points by the
/// matrix, normals by the inverse transpose, tangents by the linear part; a
/// mirror flips winding and bitangent sign.
struct Transform {
    linear: Mat3,
    normal_matrix: Mat3,
    mirrored: bool,
}

impl Transform {
    fn new(world: Mat4) -> Result<Self, String> {
        let linear = Mat3::from_mat4(world);
        let det = linear.determinant();
        if !world.is_finite() || !det.is_finite() || det.abs() < 1e-12 {
            return Err(format!(
                "node transform is singular or not finite (det {det})"
            ));
        }
        Ok(Self {
            linear,
            normal_matrix: linear.inverse().transpose(),
            mirrored: det < 0.0,
        })
    }
}

/// Positions in world millimetres.
fn world_positions(positions: &[Vec3], world: Mat4, scale: f32) -> Result<Vec<Vec3>, String> {
    let positions: Vec<Vec3> = positions
        .iter()
        .map(|p| world.transform_point3(*p) * scale)
        .collect();
    if !positions.iter().all(|p| p.is_finite()) {
        return Err("positions overflow after the node transform and unit scale".into());
    }
    Ok(positions)
}

/// Normals: transformed, or generated; zero-length ones are repaired.
fn world_normals(
    normals: Option<Vec<Vec3>>,
    transform: &Transform,
    positions: &[Vec3],
    indices: &[u32],
    path: &Path,
) -> Vec<Vec3> {
    match normals {
        Some(ns) => {
            let mut ns: Vec<Vec3> = ns
                .iter()
                .map(|v| (transform.normal_matrix * *v).normalize_or_zero())
                .collect();
            let bad = ns.iter().filter(|v| *v == &Vec3::ZERO).count();
            if bad > 0 {
                log::warn!(
                    "{}: {bad} zero-length normals replaced by generated ones",
                    path.display()
                );
                let generated = smooth_normals(positions, indices);
                for (v, g) in ns.iter_mut().zip(generated) {
                    if *v == Vec3::ZERO {
                        *v = g;
                    }
                }
            }
            ns
        }
        None => {
            log::warn!(
                "{}: no NORMAL attribute; generated area-weighted smooth normals",
                path.display()
            );
            smooth_normals(positions, indices)
        }
    }
}

/// Tangents: transformed, or MikkTSpace where absent or zero-length.
fn set_tangents(
    part: &mut Part,
    tangents: Option<Vec<Vec4>>,
    transform: &Transform,
    path: &Path,
) -> Result<(), String> {
    let transformed: Option<Vec<Vec4>> = tangents.map(|ts| {
        ts.iter()
            .map(|t| {
                let xyz = (transform.linear * t.truncate()).normalize_or_zero();
                let w = if t.w < 0.0 { -1.0 } else { 1.0 }
                    * if transform.mirrored { -1.0 } else { 1.0 };
                xyz.extend(w)
            })
            .collect()
    });
    match transformed {
        Some(ts) if ts.iter().all(|t| t.truncate() != Vec3::ZERO) => part.tangents = ts,
        given => {
            if given.is_some() {
                log::warn!(
                    "{}: TANGENT has zero-length vectors; regenerating with MikkTSpace",
                    path.display()
                );
            }
            mikktspace_tangents(part)?;
        }
    }
    Ok(())
}

pub(super) fn check_len(semantic: &str, len: usize, n: usize) -> Result<(), String> {
    if len == n {
        Ok(())
    } else {
        Err(format!(
            "{semantic} has {len} elements but POSITION has {n}"
        ))
    }
}

pub(super) fn check_finite(semantic: &str, ok: impl Iterator<Item = bool>) -> Result<(), String> {
    match ok.enumerate().find(|(_, ok)| !ok) {
        None => Ok(()),
        Some((i, _)) => Err(format!("{semantic} of vertex {i} is NaN or infinite")),
    }
}
