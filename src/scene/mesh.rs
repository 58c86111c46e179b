//! Triangle meshes as the renderer consumes them: positions in millimetres.

use glam::{Vec2, Vec3, Vec4};

/// An indexed triangle mesh in physical units.
///
/// Positions are in **millimetres** (skin scattering widths are in mm, GPU Gems 3
/// ch. 14); loaders multiply by the scene's `mm_per_unit`. UVs follow the glTF
/// convention: origin at the top-left of the texture, v pointing down.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    /// xyz: tangent along +u; w: sign of the bitangent (MikkTSpace convention).
    pub tangents: Vec<Vec4>,
    pub indices: Vec<u32>,
}

impl Mesh {
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Negates every tangent's bitangent sign `w`, for normal maps flipped
    /// vertically on load (`Texture::flip_vertical`, `UvOrigin::BottomLeft`).
    ///
    /// The shader's bitangent `w · n × t` points toward decreasing v, the top of
    /// the image, where a glTF normal map's green (+Y) points. A map authored
    /// for a bottom-left origin has +Y toward increasing v_GL = 1 − v, the top
    /// of its file; flipped, that is the bottom of the image, increasing v. The
    /// tangent (+u) is unchanged, so only the bitangent turns: w → −w
    /// (measured on the scan in `scene::uv_origin_tests`).
    pub fn negate_bitangent_sign(&mut self) {
        for t in &mut self.tangents {
            t.w = -t.w;
        }
    }

    /// Total area of the triangles in UV space (1: the whole map, once), out of
    /// range indices skipped.
    pub fn uv_area(&self) -> f64 {
        self.indices
            .chunks_exact(3)
            .filter_map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| self.uvs.get(i as usize).copied());
                let (a, b, c) = (a?, b?, c?);
                Some(0.5 * f64::from((b - a).perp_dot(c - a)).abs())
            })
            .sum()
    }

    /// Axis-aligned bounds (min, max) in mm; `None` for an empty mesh.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))),
        )
    }

    /// Checks the invariants every consumer relies on; returns what is wrong.
    pub fn validate(&self) -> Result<(), String> {
        let n = self.positions.len();
        if n == 0 || self.indices.is_empty() {
            return Err("mesh has no triangles".into());
        }
        if self.normals.len() != n || self.uvs.len() != n || self.tangents.len() != n {
            return Err(format!(
                "attribute counts differ: {n} positions, {} normals, {} uvs, {} tangents",
                self.normals.len(),
                self.uvs.len(),
                self.tangents.len()
            ));
        }
        if !self.indices.len().is_multiple_of(3) {
            return Err(format!(
                "{} indices is not a multiple of 3",
                self.indices.len()
            ));
        }
        if let Some(i) = self.indices.iter().find(|&&i| i as usize >= n) {
            return Err(format!("index {i} out of range for {n} vertices"));
        }
        let finite = self.positions.iter().all(|p| p.is_finite())
            && self.normals.iter().all(|v| v.is_finite())
            && self.uvs.iter().all(|v| v.is_finite())
            && self.tangents.iter().all(|v| v.is_finite());
        if !finite {
            return Err("mesh has NaN or infinite attributes".into());
        }
        Ok(())
    }
}
