//! The per-vertex transfer vectors, and the unoccluded case.

use glam::Vec3;

use crate::light::sh;
use crate::scene::mesh::Mesh;

/// One transfer vector per vertex (order of [`sh::basis`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Transfer {
    pub coeffs: Vec<[f32; 9]>,
}

/// Nine coefficients per colour channel (R, G, B) per vertex: a transfer
/// that depends on the skin's colour (light::interreflection,
/// light::transmission).
#[derive(Clone, Debug, PartialEq)]
pub struct RgbTransfer {
    pub coeffs: Vec<[[f32; 9]; 3]>,
}

impl RgbTransfer {
    /// All zero: no light of this kind.
    pub fn none(vertices: usize) -> RgbTransfer {
        RgbTransfer {
            coeffs: vec![[[0.0; 9]; 3]; vertices],
        }
    }
}

/// `T = sh::cosine_transfer(N)` per vertex (no occlusion). Vertices whose
/// normal is missing, zero or non-finite get zeros.
pub fn unoccluded(mesh: &Mesh) -> Transfer {
    let coeffs = (0..mesh.vertex_count())
        .map(|i| match vertex_frame(mesh, i) {
            Some((_, n)) => sh::cosine_transfer(n),
            None => [0.0; 9],
        })
        .collect();
    Transfer { coeffs }
}

/// Position and unit normal of vertex `i`, or `None` if either is unusable.
pub(super) fn vertex_frame(mesh: &Mesh, i: usize) -> Option<(Vec3, Vec3)> {
    let p = *mesh.positions.get(i)?;
    let n = mesh.normals.get(i)?.try_normalize()?;
    p.is_finite().then_some((p, n))
}
