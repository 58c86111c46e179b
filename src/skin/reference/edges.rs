//! The mesh's UV seams (an edge of the surface where the UVs of its two
//! triangles differ: the texture-space chain cannot blur across it) and open
//! boundaries (an edge with one triangle: the scan's cut at the neck, the eyes),
//! found on the mesh welded by position; and how far a point is from them.

use super::grid::Grid;
use glam::{Vec2, Vec3};
use std::collections::HashMap;

/// Positions closer than this (mm) are one vertex when welding.
const WELD_MM: f32 = 1e-4;

/// Segments (mm) of the seams and of the open boundaries, and grids to query
/// them out to `radius`.
pub struct MeshEdges {
    pub seams: Vec<(Vec3, Vec3)>,
    pub open: Vec<(Vec3, Vec3)>,
    seam_grid: Grid,
    open_grid: Grid,
    radius: f32,
}

impl MeshEdges {
    /// Seams and open boundaries of the triangles `indices`, for distance
    /// queries out to `radius` mm.
    pub fn new(positions: &[Vec3], uvs: &[Vec2], indices: &[u32], radius: f32) -> MeshEdges {
        let mut weld: HashMap<[i64; 3], u32> = HashMap::new();
        let id: Vec<u32> = positions
            .iter()
            .map(|p| {
                let key = p.to_array().map(|c| (c / WELD_MM).round() as i64);
                let next = weld.len() as u32;
                *weld.entry(key).or_insert(next)
            })
            .collect();
        // Per welded edge: the vertices (of the lower, then the higher id) of each
        // triangle that uses it.
        let mut edges: HashMap<(u32, u32), Vec<(u32, u32)>> = HashMap::new();
        for t in indices.chunks_exact(3) {
            for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                let (a, b) = if id[a as usize] <= id[b as usize] {
                    (a, b)
                } else {
                    (b, a)
                };
                edges
                    .entry((id[a as usize], id[b as usize]))
                    .or_default()
                    .push((a, b));
            }
        }
        let (mut seams, mut open) = (Vec::new(), Vec::new());
        for uses in edges.values() {
            let (a, b) = uses[0];
            let segment = (positions[a as usize], positions[b as usize]);
            if uses.len() == 1 {
                open.push(segment);
            } else if uses.iter().any(|&(c, d)| {
                uvs[c as usize].distance(uvs[a as usize]) > 1e-6
                    || uvs[d as usize].distance(uvs[b as usize]) > 1e-6
            }) {
                seams.push(segment);
            }
        }
        let grid = |s: &[(Vec3, Vec3)]| {
            let boxes: Vec<(Vec3, Vec3)> = s.iter().map(|&(a, b)| (a.min(b), a.max(b))).collect();
            Grid::new(&boxes, radius)
        };
        MeshEdges {
            seam_grid: grid(&seams),
            open_grid: grid(&open),
            seams,
            open,
            radius,
        }
    }

    /// Distance from `x` to the nearest seam, if within the radius.
    pub fn to_seam(&self, x: Vec3) -> Option<f32> {
        nearest(&self.seam_grid, &self.seams, x, self.radius)
    }

    /// Distance from `x` to the nearest open boundary, if within the radius.
    pub fn to_open(&self, x: Vec3) -> Option<f32> {
        nearest(&self.open_grid, &self.open, x, self.radius)
    }
}

fn nearest(grid: &Grid, segments: &[(Vec3, Vec3)], x: Vec3, radius: f32) -> Option<f32> {
    let mut near = Vec::new();
    grid.near(x, radius, &mut near);
    near.iter()
        .map(|&i| {
            let (a, b) = segments[i as usize];
            let ab = b - a;
            let t = ((x - a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
            x.distance(a + t * ab)
        })
        .filter(|&d| d <= radius)
        .reduce(f32::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_strip_with_a_seam_in_the_middle() {
        // Two squares side by side (x 0..10 and 10..20 mm); the right one has its
        // own copies of the shared vertices with other UVs: a seam at x = 10.
        let p = |x: f32, y: f32| Vec3::new(x, y, 0.0);
        let positions = [
            p(0.0, 0.0),
            p(10.0, 0.0),
            p(10.0, 10.0),
            p(0.0, 10.0),
            p(10.0, 0.0),
            p(20.0, 0.0),
            p(20.0, 10.0),
            p(10.0, 10.0),
        ];
        let uvs = [
            Vec2::new(0.0, 0.0),
            Vec2::new(0.4, 0.0),
            Vec2::new(0.4, 0.4),
            Vec2::new(0.0, 0.4),
            Vec2::new(0.5, 0.5),
            Vec2::new(0.9, 0.5),
            Vec2::new(0.9, 0.9),
            Vec2::new(0.5, 0.9),
        ];
        let indices = [0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7];
        let e = MeshEdges::new(&positions, &uvs, &indices, 3.0);
        assert_eq!(e.seams.len(), 1);
        assert_eq!(e.open.len(), 6, "the outline");
        assert!((e.to_seam(Vec3::new(8.5, 5.0, 0.0)).unwrap() - 1.5).abs() < 1e-5);
        assert_eq!(
            e.to_seam(Vec3::new(3.0, 5.0, 0.0)),
            None,
            "beyond the radius"
        );
        assert!((e.to_open(Vec3::new(5.0, 9.0, 0.0)).unwrap() - 1.0).abs() < 1e-5);
    }
}
