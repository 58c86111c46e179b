//! A uniform grid over items with bounding boxes (triangles, edges): which items
//! may lie within a distance of a point. The cell is the search radius, so a
//! query visits at most 3 × 3 × 3 cells.

use glam::{IVec3, Vec3};

/// Cells per side at most, so a tiny radius over a large mesh cannot allocate
/// without bound (the cell grows instead).
const MAX_CELLS_PER_SIDE: i32 = 256;

pub struct Grid {
    origin: Vec3,
    cell: f32,
    dims: IVec3,
    /// Item ids of cell c at `ids[starts[c]..starts[c + 1]]`.
    starts: Vec<u32>,
    ids: Vec<u32>,
}

impl Grid {
    /// Items by their boxes (min, max), for queries out to `radius`.
    pub fn new(boxes: &[(Vec3, Vec3)], radius: f32) -> Grid {
        let (lo, hi) = boxes.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), &(a, b)| (lo.min(a), hi.max(b)),
        );
        let (lo, hi) = if boxes.is_empty() {
            (Vec3::ZERO, Vec3::ZERO)
        } else {
            (lo, hi)
        };
        let extent = (hi - lo).max_element();
        let cell = radius.max(extent / MAX_CELLS_PER_SIDE as f32).max(1e-6);
        let dims = (((hi - lo) / cell).floor().as_ivec3() + 1).max(IVec3::ONE);
        let mut grid = Grid {
            origin: lo,
            cell,
            dims,
            starts: vec![0; (dims.x * dims.y * dims.z) as usize + 1],
            ids: Vec::new(),
        };
        // Counting sort of (cell, item) pairs.
        let mut count = vec![0u32; grid.starts.len()];
        for &(a, b) in boxes {
            grid.each_cell(a, b, |c| count[c] += 1);
        }
        let mut total = 0;
        for (start, n) in grid.starts.iter_mut().zip(&count) {
            *start = total;
            total += n;
        }
        grid.ids = vec![0; total as usize];
        let mut next = grid.starts.clone();
        for (id, &(a, b)) in boxes.iter().enumerate() {
            let ids = &mut grid.ids;
            grid_cells(grid.origin, grid.cell, grid.dims, a, b, |c| {
                ids[next[c] as usize] = id as u32;
                next[c] += 1;
            });
        }
        grid
    }

    fn each_cell(&self, a: Vec3, b: Vec3, f: impl FnMut(usize)) {
        grid_cells(self.origin, self.cell, self.dims, a, b, f)
    }

    /// Ids of the items whose boxes may come within `radius` (≤ the grid's) of
    /// `x`, each once, in `out` (cleared first).
    pub fn near(&self, x: Vec3, radius: f32, out: &mut Vec<u32>) {
        out.clear();
        let r = Vec3::splat(radius);
        self.each_cell(x - r, x + r, |c| {
            out.extend_from_slice(&self.ids[self.starts[c] as usize..self.starts[c + 1] as usize])
        });
        out.sort_unstable();
        out.dedup();
    }
}

impl Grid {
    /// Calls `f` with the id of every item in the cells within `radius` (≤ the
    /// grid's) of `x`: an item in several cells, more than once; for points,
    /// each once, unsorted, without [`Grid::near`]'s sort.
    pub fn each_near(&self, x: Vec3, radius: f32, mut f: impl FnMut(u32)) {
        let r = Vec3::splat(radius);
        self.each_cell(x - r, x + r, |c| {
            for &id in &self.ids[self.starts[c] as usize..self.starts[c + 1] as usize] {
                f(id)
            }
        });
    }
}

/// Calls `f` with the index of every cell the box (a, b) overlaps.
fn grid_cells(origin: Vec3, cell: f32, dims: IVec3, a: Vec3, b: Vec3, mut f: impl FnMut(usize)) {
    let index = |p: Vec3| {
        ((p - origin) / cell)
            .floor()
            .as_ivec3()
            .clamp(IVec3::ZERO, dims - 1)
    };
    let (lo, hi) = (index(a), index(b));
    for z in lo.z..=hi.z {
        for y in lo.y..=hi.y {
            for x in lo.x..=hi.x {
                f(((z * dims.y + y) * dims.x + x) as usize);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_every_item_within_the_radius() {
        // Points on a line 1 mm apart; a radius of 2.5 mm around x = 10.2 holds 8..=12.
        let boxes: Vec<(Vec3, Vec3)> = (0..30)
            .map(|i| Vec3::new(i as f32, 0.0, 0.0))
            .map(|p| (p, p))
            .collect();
        let grid = Grid::new(&boxes, 2.5);
        let mut near = Vec::new();
        grid.near(Vec3::new(10.2, 0.0, 0.0), 2.5, &mut near);
        for i in 8..=12 {
            assert!(near.contains(&i), "{i} missing from {near:?}");
        }
        assert!(near.windows(2).all(|w| w[0] < w[1]), "sorted, no repeats");
        assert!(!near.contains(&0) && !near.contains(&29));
    }
}
