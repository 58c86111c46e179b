//! Bounding volume hierarchy over triangles, for any-hit and closest-hit ray
//! queries.
//!
//! Möller & Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection" (JGT
//! 1997) against a binned-SAH BVH (Wald, "On fast construction of SAH-based
//! bounding volume hierarchies", 2007). Triangles with out-of-range or
//! non-finite vertices or (near) zero area are skipped.

use glam::Vec3;

use crate::scene::mesh::Mesh;

/// Triangle in Möller–Trumbore form: a vertex and the two edges from it.
#[derive(Clone, Copy, Debug)]
struct Tri {
    v0: Vec3,
    e1: Vec3,
    e2: Vec3,
}

/// BVH node: a box and either two children (`count == 0`, children at
/// `first` and `first + 1`) or `count` triangles from `first`.
#[derive(Clone, Copy, Debug)]
struct Node {
    lo: Vec3,
    first: u32,
    hi: Vec3,
    count: u32,
}

/// Bounding volume hierarchy over a triangle set, for any-hit and closest-hit
/// ray queries.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<Tri>,
    /// The input index of each triangle of `tris` (the build reorders them and
    /// drops invalid ones); kept apart so any-hit traversal reads only `tris`.
    ids: Vec<u32>,
}

/// The closest intersection of a ray: [`Bvh::closest_hit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter: the hit point is `origin + t·dir`.
    pub t: f32,
    /// Index of the triangle in the input: the mesh's triangle (`indices[3k..3k+3]`)
    /// for [`Bvh::from_mesh`], the iterator position for [`Bvh::from_triangles`].
    pub triangle: u32,
    /// Barycentric weights of the triangle's corners 0, 1, 2 at the hit (sum 1).
    pub barycentric: Vec3,
}

impl Hit {
    /// The mesh's vertices at the hit triangle's corners 0, 1, 2 (a hit of
    /// [`Bvh::from_mesh`]).
    pub fn corners(&self, mesh: &Mesh) -> [usize; 3] {
        let k = 3 * self.triangle as usize;
        [0, 1, 2].map(|c| mesh.indices[k + c] as usize)
    }

    /// A per-vertex attribute of the mesh at the hit, barycentrically
    /// interpolated (as a rasteriser interpolates it).
    pub fn interpolate<T>(&self, mesh: &Mesh, values: &[T]) -> T
    where
        T: Copy + std::ops::Mul<f32, Output = T> + std::ops::Add<Output = T>,
    {
        let [a, b, c] = self.corners(mesh);
        let w = self.barycentric;
        values[a] * w.x + values[b] * w.y + values[c] * w.z
    }
}

/// Leaves hold at most this many triangles unless the centroids coincide.
const MAX_LEAF: usize = 4;
/// Depth cap: the traversal stack holds `MAX_DEPTH + 1` entries at most.
const MAX_DEPTH: usize = 48;
const STACK: usize = 64;
const BINS: usize = 16;

impl Bvh {
    /// BVH over `mesh`'s triangles (invalid ones, including those with an
    /// out-of-range index, skipped); [`Hit::triangle`] is the mesh's triangle index.
    pub fn from_mesh(mesh: &Mesh) -> Bvh {
        let tris = mesh
            .indices
            .chunks_exact(3)
            .enumerate()
            .filter_map(|(k, t)| {
                let v = |k: usize| mesh.positions.get(t[k] as usize).copied();
                Some((k as u32, [v(0)?, v(1)?, v(2)?]))
            });
        Bvh::build(tris)
    }

    /// BVH over triangles given by their three corners; [`Hit::triangle`] is the
    /// position in `tris`.
    pub fn from_triangles(tris: impl IntoIterator<Item = [Vec3; 3]>) -> Bvh {
        Bvh::build((0..).zip(tris))
    }

    /// BVH over `(input index, corners)` pairs.
    fn build(tris: impl IntoIterator<Item = (u32, [Vec3; 3])>) -> Bvh {
        let (ids, tris): (Vec<u32>, Vec<Tri>) = tris
            .into_iter()
            .filter(|(_, t)| t.iter().all(|v| v.is_finite()))
            .filter_map(|(k, [a, b, c])| {
                let (e1, e2) = (b - a, c - a);
                // Zero area (relative to the edge lengths) never hits robustly.
                let area2 = e1.cross(e2).length();
                let scale = e1.length_squared().max(e2.length_squared());
                (area2 > 1e-10 * scale && area2.is_finite()).then_some((k, Tri { v0: a, e1, e2 }))
            })
            .unzip();
        if tris.is_empty() {
            return Bvh::default();
        }
        let bounds: Vec<(Vec3, Vec3)> = tris
            .iter()
            .map(|t| {
                let (b, c) = (t.v0 + t.e1, t.v0 + t.e2);
                (t.v0.min(b).min(c), t.v0.max(b).max(c))
            })
            .collect();
        // Pad boxes so flat (axis-aligned) triangles and rays grazing a box face
        // are not lost to rounding in the slab test; only costs a little speed.
        let (lo, hi) = bounds
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), b| {
                (l.min(b.0), h.max(b.1))
            });
        let pad = 1e-6 * (hi - lo).max_element() + 1e-6;
        let mut b = Builder {
            bounds,
            centroids: Vec::new(),
            order: (0..tris.len() as u32).collect(),
            nodes: vec![empty_node()],
            pad: Vec3::splat(pad),
        };
        b.centroids = b.bounds.iter().map(|(l, h)| 0.5 * (*l + *h)).collect();
        let n = tris.len();
        b.build(0, 0, n, 0);
        Bvh {
            tris: b.order.iter().map(|&i| tris[i as usize]).collect(),
            ids: b.order.iter().map(|&i| ids[i as usize]).collect(),
            nodes: b.nodes,
        }
    }

    /// Number of (valid) triangles held.
    pub fn triangle_count(&self) -> usize {
        self.tris.len()
    }

    /// Whether the ray `origin + t·dir`, `0 < t < t_max`, hits any triangle.
    /// `dir` need not be unit length (then `t` is in units of `|dir|`).
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        if self.tris.is_empty() || !origin.is_finite() || !dir.is_finite() {
            return false;
        }
        let inv = dir.recip();
        let mut stack = [0u32; STACK];
        let mut sp = 0usize;
        let mut node = &self.nodes[0];
        if slab(node, origin, inv, t_max).is_none() {
            return false;
        }
        loop {
            if node.count > 0 {
                let (a, b) = (node.first as usize, (node.first + node.count) as usize);
                if self.tris[a..b]
                    .iter()
                    .any(|t| intersect(t, origin, dir, t_max).is_some())
                {
                    return true;
                }
            } else {
                let (l, r) = (node.first as usize, node.first as usize + 1);
                let tl = slab(&self.nodes[l], origin, inv, t_max);
                let tr = slab(&self.nodes[r], origin, inv, t_max);
                match (tl, tr) {
                    (Some(a), Some(b)) => {
                        let (near, far) = if a <= b { (l, r) } else { (r, l) };
                        if sp < STACK {
                            stack[sp] = far as u32;
                            sp += 1;
                        }
                        node = &self.nodes[near];
                        continue;
                    }
                    (Some(_), None) => {
                        node = &self.nodes[l];
                        continue;
                    }
                    (None, Some(_)) => {
                        node = &self.nodes[r];
                        continue;
                    }
                    (None, None) => {}
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            node = &self.nodes[stack[sp] as usize];
        }
    }

    /// The closest intersection of the ray `origin + t·dir`, `0 < t < t_max`
    /// (either face), if any. `dir` need not be unit length.
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        if self.tris.is_empty() || !origin.is_finite() || !dir.is_finite() {
            return None;
        }
        let inv = dir.recip();
        // Boxes are visited near to far and skipped once they start beyond the
        // closest hit so far (`t_best`).
        let mut best: Option<(usize, f32, f32)> = None; // (triangle slot, u, v)
        let mut t_best = t_max;
        let mut stack = [(0u32, 0.0f32); STACK]; // (node, entry distance)
        let mut sp = 0usize;
        if let Some(t_in) = slab(&self.nodes[0], origin, inv, t_best) {
            stack[0] = (0, t_in);
            sp = 1;
        }
        while sp > 0 {
            sp -= 1;
            let (ni, t_in) = stack[sp];
            if t_in > t_best {
                continue;
            }
            let node = &self.nodes[ni as usize];
            if node.count > 0 {
                let first = node.first as usize;
                for (k, tri) in self.tris[first..first + node.count as usize]
                    .iter()
                    .enumerate()
                {
                    if let Some((t, u, v)) = intersect(tri, origin, dir, t_best) {
                        t_best = t;
                        best = Some((first + k, u, v));
                    }
                }
                continue;
            }
            let (l, r) = (node.first, node.first + 1);
            let tl = slab(&self.nodes[l as usize], origin, inv, t_best);
            let tr = slab(&self.nodes[r as usize], origin, inv, t_best);
            // Push the far child first so the near one is popped next.
            let mut children = [(l, tl), (r, tr)];
            if tl.unwrap_or(f32::INFINITY) < tr.unwrap_or(f32::INFINITY) {
                children.swap(0, 1);
            }
            for (c, t) in children {
                if let Some(t) = t {
                    if sp < STACK {
                        stack[sp] = (c, t);
                        sp += 1;
                    }
                }
            }
        }
        best.map(|(slot, u, v)| Hit {
            t: t_best,
            triangle: self.ids[slot],
            barycentric: Vec3::new(1.0 - u - v, u, v),
        })
    }

    /// Reference: the same query testing every triangle (for tests).
    #[cfg(test)]
    fn occluded_brute_force(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        self.tris
            .iter()
            .any(|t| intersect(t, origin, dir, t_max).is_some())
    }
}

fn empty_node() -> Node {
    Node {
        lo: Vec3::ZERO,
        first: 0,
        hi: Vec3::ZERO,
        count: 0,
    }
}

/// Entry distance of the ray into the node's box, if it enters before `t_max`
/// (Kay & Kajiya slabs; `f32::min/max` drop the NaN of `0 · ∞`).
#[inline]
fn slab(n: &Node, o: Vec3, inv: Vec3, t_max: f32) -> Option<f32> {
    let t1 = (n.lo - o) * inv;
    let t2 = (n.hi - o) * inv;
    let t_in = t1.min(t2).max_element().max(0.0);
    let t_out = t1.max(t2).min_element().min(t_max);
    (t_in <= t_out).then_some(t_in)
}

/// Möller & Trumbore 1997: solve `o + t d = v0 + u e1 + v e2`, hit when
/// `u ≥ 0, v ≥ 0, u + v ≤ 1, 0 < t < t_max` (both faces count); `(t, u, v)`.
#[inline]
fn intersect(tri: &Tri, o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, f32, f32)> {
    let p = d.cross(tri.e2);
    let det = tri.e1.dot(p);
    if det.abs() < 1e-30 {
        return None; // ray parallel to the plane
    }
    let inv_det = 1.0 / det;
    let s = o - tri.v0;
    let u = s.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(tri.e1);
    let v = d.dot(q) * inv_det;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = tri.e2.dot(q) * inv_det;
    (t > 0.0 && t < t_max).then_some((t, u, v))
}

struct Builder {
    bounds: Vec<(Vec3, Vec3)>,
    centroids: Vec<Vec3>,
    order: Vec<u32>,
    nodes: Vec<Node>,
    pad: Vec3,
}

fn half_area(lo: Vec3, hi: Vec3) -> f32 {
    let e = (hi - lo).max(Vec3::ZERO);
    e.x * e.y + e.y * e.z + e.z * e.x
}

impl Builder {
    /// Fills node `ni` with triangles `order[start..end]`, recursively.
    fn build(&mut self, ni: usize, start: usize, end: usize, depth: usize) {
        let ids = &self.order[start..end];
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        let (mut clo, mut chi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        for &i in ids {
            let (l, h) = self.bounds[i as usize];
            lo = lo.min(l);
            hi = hi.max(h);
            let c = self.centroids[i as usize];
            clo = clo.min(c);
            chi = chi.max(c);
        }
        let count = end - start;
        self.nodes[ni] = Node {
            lo: lo - self.pad,
            first: start as u32,
            hi: hi + self.pad,
            count: count as u32,
        };
        let extent = chi - clo;
        if count <= MAX_LEAF || depth >= MAX_DEPTH || extent.max_element() <= 0.0 {
            return;
        }
        let mid = match self.sah_split(start, end, clo, extent, half_area(lo, hi)) {
            Some(m) => m,
            None if count <= 4 * MAX_LEAF => return,
            None => {
                // SAH found nothing cheaper than a leaf but the leaf is large:
                // median split on the widest centroid axis.
                let axis = extent.max_position();
                let c = &self.centroids;
                let mid = count / 2;
                self.order[start..end].select_nth_unstable_by(mid, |a, b| {
                    c[*a as usize][axis].total_cmp(&c[*b as usize][axis])
                });
                start + mid
            }
        };
        let child = self.nodes.len();
        self.nodes.push(empty_node());
        self.nodes.push(empty_node());
        self.nodes[ni].first = child as u32;
        self.nodes[ni].count = 0;
        self.build(child, start, mid, depth + 1);
        self.build(child + 1, mid, end, depth + 1);
    }

    /// Binned SAH over all three axes; partitions `order[start..end]` and
    /// returns the split index if splitting is estimated cheaper than a leaf.
    fn sah_split(
        &mut self,
        start: usize,
        end: usize,
        clo: Vec3,
        extent: Vec3,
        parent_area: f32,
    ) -> Option<usize> {
        let ids = &self.order[start..end];
        let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, split bin)
        for axis in 0..3 {
            if extent[axis] <= 0.0 {
                continue;
            }
            let scale = BINS as f32 / extent[axis];
            let bin_of = |c: Vec3| (((c[axis] - clo[axis]) * scale) as usize).min(BINS - 1);
            let mut cnt = [0usize; BINS];
            let mut blo = [Vec3::INFINITY; BINS];
            let mut bhi = [Vec3::NEG_INFINITY; BINS];
            for &i in ids {
                let b = bin_of(self.centroids[i as usize]);
                let (l, h) = self.bounds[i as usize];
                cnt[b] += 1;
                blo[b] = blo[b].min(l);
                bhi[b] = bhi[b].max(h);
            }
            // Sweep from the right to get the right-side area/count per plane.
            let mut right = [(0.0f32, 0usize); BINS];
            let (mut lo, mut hi, mut n) = (Vec3::INFINITY, Vec3::NEG_INFINITY, 0);
            for b in (1..BINS).rev() {
                lo = lo.min(blo[b]);
                hi = hi.max(bhi[b]);
                n += cnt[b];
                right[b] = (half_area(lo, hi), n);
            }
            let (mut lo, mut hi, mut n) = (Vec3::INFINITY, Vec3::NEG_INFINITY, 0);
            for b in 0..BINS - 1 {
                lo = lo.min(blo[b]);
                hi = hi.max(bhi[b]);
                n += cnt[b];
                let (ra, rn) = right[b + 1];
                if n == 0 || rn == 0 {
                    continue;
                }
                let cost = half_area(lo, hi) * n as f32 + ra * rn as f32;
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, b));
                }
            }
        }
        // Cost model: traversal step ≈ one triangle test.
        let (cost, axis, split) = best?;
        let leaf_cost = parent_area * (end - start) as f32;
        if cost + parent_area >= leaf_cost {
            return None;
        }
        let scale = BINS as f32 / extent[axis];
        let c = &self.centroids;
        let left = |i: &u32| {
            let v = c[*i as usize][axis];
            (((v - clo[axis]) * scale) as usize).min(BINS - 1) <= split
        };
        // In-place partition.
        let slice = &mut self.order[start..end];
        let mut k = 0;
        for j in 0..slice.len() {
            if left(&slice[j]) {
                slice.swap(k, j);
                k += 1;
            }
        }
        (k > 0 && k < slice.len()).then_some(start + k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Wellons' "lowbias32", as `raytrace`'s sample hash (kept separate so
    /// the BVH depends on nothing else).
    fn hash32(mut x: u32) -> u32 {
        x ^= x >> 16;
        x = x.wrapping_mul(0x7feb_352d);
        x ^= x >> 15;
        x = x.wrapping_mul(0x846c_a68b);
        x ^= x >> 16;
        x
    }

    /// Small deterministic generator for the tests.
    struct Rng(u32);
    impl Rng {
        fn next(&mut self) -> f32 {
            self.0 = hash32(self.0.wrapping_add(0x9e37_79b9));
            (self.0 >> 8) as f32 * (1.0 / 16_777_216.0)
        }
        fn vec(&mut self, s: f32) -> Vec3 {
            Vec3::new(self.next(), self.next(), self.next()) * 2.0 * s - s
        }
    }

    #[test]
    fn bvh_matches_brute_force() {
        let mut rng = Rng(1);
        let mut tris = Vec::new();
        for _ in 0..2000 {
            let c = rng.vec(100.0);
            tris.push([c + rng.vec(8.0), c + rng.vec(8.0), c + rng.vec(8.0)]);
        }
        // Degenerate and non-finite triangles must be skipped without panics.
        tris.push([Vec3::ONE, Vec3::ONE, Vec3::ONE]);
        tris.push([Vec3::ZERO, Vec3::X, Vec3::X * 2.0]);
        tris.push([Vec3::NAN, Vec3::X, Vec3::Y]);
        tris.push([Vec3::INFINITY, Vec3::X, Vec3::Y]);
        let bvh = Bvh::from_triangles(tris.iter().copied());
        assert_eq!(bvh.triangle_count(), 2000);
        let (mut hits, mut mismatches) = (0, 0);
        for k in 0..5000 {
            let o = rng.vec(120.0);
            let d = rng.vec(1.0).normalize_or(Vec3::Y);
            let t_max = if k % 3 == 0 { 30.0 } else { f32::INFINITY };
            let a = bvh.occluded(o, d, t_max);
            if a != bvh.occluded_brute_force(o, d, t_max) {
                mismatches += 1;
            }
            hits += a as u32;
        }
        println!("BVH vs brute force: {hits}/5000 rays hit, {mismatches} mismatches");
        assert_eq!(mismatches, 0);
        assert!(hits > 500 && hits < 4500, "{hits}");
        // Hand-checked single cases of the triangle test.
        let one = Bvh::from_triangles([[Vec3::ZERO, Vec3::X, Vec3::Z]]);
        assert!(one.occluded(Vec3::new(0.2, 1.0, 0.2), Vec3::NEG_Y, f32::INFINITY));
        assert!(!one.occluded(Vec3::new(0.2, 1.0, 0.2), Vec3::NEG_Y, 0.9));
        assert!(!one.occluded(Vec3::new(0.6, 1.0, 0.6), Vec3::NEG_Y, f32::INFINITY));
        assert!(!one.occluded(Vec3::new(0.2, 1.0, 0.2), Vec3::Y, f32::INFINITY));
        assert!(!one.occluded(Vec3::NAN, Vec3::Y, f32::INFINITY));
        assert!(!Bvh::default().occluded(Vec3::ZERO, Vec3::Y, 1.0));
    }

    /// Closest hit of a ray by testing every input triangle (Möller–Trumbore
    /// written out again here, inside-edge form), as (t, input index).
    fn closest_brute_force(tris: &[[Vec3; 3]], o: Vec3, d: Vec3) -> Option<(f32, usize)> {
        let mut best: Option<(f32, usize)> = None;
        for (k, [a, b, c]) in tris.iter().enumerate() {
            let n = (*b - *a).cross(*c - *a);
            let denom = n.dot(d);
            if !n.is_finite() || n.length() < 1e-6 || denom.abs() < 1e-12 {
                continue;
            }
            let t = n.dot(*a - o) / denom;
            let x = o + t * d;
            // Inside when x lies on the inner side of all three edges.
            let inside = [(*a, *b), (*b, *c), (*c, *a)]
                .iter()
                .all(|(p, q)| (*q - *p).cross(x - *p).dot(n) >= 0.0);
            if t > 0.0 && inside && best.is_none_or(|(tb, _)| t < tb) {
                best = Some((t, k));
            }
        }
        best
    }

    #[test]
    fn closest_hit_matches_brute_force() {
        let mut rng = Rng(7);
        let mut tris = Vec::new();
        for k in 0..1500 {
            // Degenerate triangles among them: the BVH drops those, and the
            // indices it reports must still be the input's.
            if k % 100 == 0 {
                tris.push([Vec3::ONE, Vec3::ONE, Vec3::ONE]);
            }
            let c = rng.vec(100.0);
            tris.push([c + rng.vec(10.0), c + rng.vec(10.0), c + rng.vec(10.0)]);
        }
        let bvh = Bvh::from_triangles(tris.iter().copied());
        let (mut hits, mut worst_t) = (0, 0.0f32);
        for _ in 0..5000 {
            let o = rng.vec(120.0);
            let d = rng.vec(1.0).normalize_or(Vec3::Y);
            let got = bvh.closest_hit(o, d, f32::INFINITY);
            let want = closest_brute_force(&tris, o, d);
            match (got, want) {
                (None, None) => {}
                (Some(h), Some((t, k))) => {
                    hits += 1;
                    // Two triangles at (almost) the same distance may swap.
                    if h.triangle as usize != k {
                        assert!((h.t - t).abs() < 1e-3, "{h:?} vs {t} {k}");
                    }
                    worst_t = worst_t.max((h.t - t).abs() / t);
                    // The barycentrics rebuild the hit point on the triangle reported.
                    let [a, b, c] = tris[h.triangle as usize];
                    let b3 = h.barycentric;
                    assert!(b3.min_element() >= 0.0 && (b3.element_sum() - 1.0).abs() < 1e-5);
                    let x = a * b3.x + b * b3.y + c * b3.z;
                    assert!(
                        (x - (o + h.t * d)).length() < 1e-3,
                        "{x} vs {}",
                        o + h.t * d
                    );
                }
                (got, want) => panic!("BVH {got:?}, brute force {want:?} for {o} {d}"),
            }
            // t_max cuts off hits at or beyond it.
            if let Some(h) = got {
                assert!(bvh.closest_hit(o, d, h.t * 0.999).is_none_or(|e| e.t < h.t));
                assert_eq!(bvh.closest_hit(o, d, h.t * 1.001), Some(h));
            }
        }
        println!("closest hit vs brute force: {hits}/5000 rays hit, worst relative t difference {worst_t:.1e}");
        assert!(hits > 500 && hits < 4500, "{hits}");
        assert!(worst_t < 1e-4);
    }
}
