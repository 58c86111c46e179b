//! The fold term: light the texture-space chain cannot carry where the skin
//! comes back on itself (a UV seam's other side, a chart border, a squeezed UV
//! region, the eyelids' and lips' lines), precomputed once per mesh, profile
//! and irradiance resolution, as sparse per-texel lists (Sloan et al. 2002's
//! precomputed transfer, here of the profile through the tissue).
//!
//! Every level the chain blurs adds variance v to the previous level's image
//! (GPU Gems 3 §14.4.2). At a texel x of the level, over the texels y of that
//! previous image, two kernels are compared. The chain's, K_y: the Gaussian
//! G(v, |J_x Δuv|²) in UV space under x's surface metric J_x (what the
//! stretch and shear maps give the blur) over texel y, on covered texels, as a
//! share of its sum over the whole UV plane. The tissue's, T_y: the mass of
//! G(v, |x − y|²) over the surface texel y holds (skin::reference's kernel;
//! a chart border's texel holds part of its square). Both are integrated over
//! the texel, on sub-samples at most σ/[`BOX_SIGMA`] apart (one, the texel's
//! centre, where the Gaussian spans [`BOX_SIGMA`] texels or more).
//!
//! The chain gives D = Σ K_y E_y / C with C = Σ K_y (it normalises by
//! coverage), so Σ T_y E_y = C·D + Σ w_y E_y with w_y = T_y − K_y. The pass
//! replaces D by that: the chain's own share is kept, scaled back by the
//! coverage it normalised away — which removes the double count (at a seam the
//! one-sided mean no longer stands in for the other side, which the term
//! brings itself) — and the weights move the rest from the UV neighbours to
//! the 3-D ones. Only where the two disagree is a source the term's: its
//! distances along the UVs and through the tissue differ by more than
//! [`GROSS_SIGMA`] σ, or the chord leaves x through the air (more than
//! [`AIR_ELEVATION_DEG`] above its tangent plane: T_y = 0, as the reference
//! without air paths counts it), or it is a chart border's partial texel;
//! elsewhere the chain's weight stands. A thin part's far side (y faces away
//! from x, and x lies behind y's surface) is left to the transmission terms
//! (light::transmission, skin::translucent). Near an open boundary both are
//! divided by the tissue kernel's reach, as the reference divides there. Each
//! corrected level is the next one's source, so a kernel that keeps less than
//! the chain's mass (a thin rim's missing surface) is renormalised, by at
//! most 1/[`MIN_KEPT`]; the air's share is still taken away and a fold's
//! extra surface adds. A texel is listed where |C − 1| + Σ|w_y| ≥ [`MIN_ERROR`].

mod cache;
mod pass;

pub use pass::FoldPass;

use super::chain::Level;
use super::reference::{
    gaussian, texels_of_every_triangle, Grid, MeshEdges, AIR_ELEVATION_DEG, EXTENT_SIGMA,
};
use crate::scene::mesh::Mesh;
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use std::time::Instant;

/// A texel is corrected where |C − 1| + Σ|w_y| reaches this share of its kernel.
pub const MIN_ERROR: f32 = 0.02;
/// A source is the term's where its distance along the chain's UVs and
/// through the tissue differ by more than this many σ of the level (their
/// weights by e² or more): the chain reaches what the tissue does not, or the
/// tissue what the chain does not. A curved surface's chord against its
/// geodesic, or the stretch varying across the kernel, stays under it.
const GROSS_SIGMA: f32 = 2.0;
/// A Gaussian narrower than this many texels is integrated over a source
/// texel on sub-samples σ/BOX_SIGMA apart, not sampled at its centre
/// ([`subsamples`]).
const BOX_SIGMA: f32 = 2.0;
/// A kernel that keeps less than this share of the chain's mass (most of its
/// surface across the air) is renormalised by this share, not by its own.
const MIN_KEPT: f32 = 0.5;
/// A texel covered less than this is a chart border's (more than one
/// sub-sample of [`coverage`] missing).
const PARTIAL: f32 = 0.98;
/// Sources below this share of the kernel are not listed: their weight goes
/// to the nearest listed source, or to the chain's own value (C) where the
/// texel itself is nearer, as if their light were that one's.
const MIN_WEIGHT: f32 = 2e-3;
/// The UV window holds at most this many source texels either side of x.
const MAX_WINDOW: i32 = 48;
/// Levels of at least [`SCREEN_FROM`]² are screened at 1/SCREEN of their side
/// first, and evaluated only near the coarse texels that need a term; a
/// screen that large is itself screened the same way.
const SCREEN: u32 = 4;
const SCREEN_FROM: u32 = 1024;
/// A screen flags where a coarse texel's error reaches this: half the
/// listing threshold, as a coarse kernel averages a fold over its texels.
const SCREEN_ERROR: f32 = MIN_ERROR / 2.0;

/// A corrected texel: `scale` = C, its sources at `first..first + count`.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Target {
    /// y << 16 | x in the level's image.
    pub texel: u32,
    pub scale: f32,
    pub first: u32,
    pub count: u32,
}

/// A source texel of the previous image and its weight w_y.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Source {
    /// y << 16 | x in the previous level's image.
    pub texel: u32,
    pub weight: f32,
}

/// The term of one level of the chain.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FoldLevel {
    /// Index into the chain's levels (0: blur1).
    pub level: usize,
    /// Sides of the level's image and of its source.
    pub side: u32,
    pub source_side: u32,
    pub targets: Vec<Target>,
    pub sources: Vec<Source>,
}

/// The term of every blurred level.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FoldTerm {
    pub levels: Vec<FoldLevel>,
}

impl FoldTerm {
    /// The term for `levels` (skin::chain::plan) of a chain whose irradiance
    /// is `irradiance_side`², on `mesh` (mm).
    pub fn compute(mesh: &Mesh, levels: &[Level], irradiance_side: u32) -> FoldTerm {
        let jacobians = jacobians(mesh);
        let widest = levels
            .iter()
            .filter_map(|l| l.sigma_mm)
            .fold(0.0f32, f32::max);
        let edges = MeshEdges::new(
            &mesh.positions,
            &mesh.uvs,
            &mesh.indices,
            2.0 * EXTENT_SIGMA * widest.max(1e-3),
        );
        let mut out = FoldTerm::default();
        let mut surfaces: Vec<Surface> = Vec::new();
        let mut source_side = irradiance_side;
        for (k, level) in levels.iter().enumerate() {
            let side = level.resolution;
            if let Some(sigma) = level.sigma_mm.filter(|s| *s > 0.0) {
                let started = Instant::now();
                // The sides it is screened at, finest first.
                let coarse: Vec<u32> = std::iter::successors(Some(side), |&n| {
                    (n >= SCREEN_FROM).then_some(n / SCREEN)
                })
                .skip(1)
                .collect();
                for &n in [source_side, side].iter().chain(&coarse) {
                    if !surfaces.iter().any(|s| s.side == n) {
                        surfaces.push(Surface::new(mesh, &jacobians, n));
                    }
                }
                let of = |n: u32| surfaces.iter().find(|s| s.side == n).expect("made above");
                let (sources, targets) = (of(source_side), of(side));
                let v = sigma * sigma;
                let surfaced = started.elapsed();
                // Each screen only where the coarser one flags.
                let screened = coarse.iter().rev().fold(None, |parent, &n| {
                    Some(screen(of(n), &edges, v, parent.as_ref()))
                });
                let after_screen = started.elapsed();
                out.levels.push(level_term(
                    k,
                    (targets, sources),
                    &edges,
                    v,
                    screened.as_ref(),
                ));
                log::debug!(
                    "fold term: blur{} {side}²: surfaces {:.2} s, screen {:.2} s, lists {:.2} s",
                    k + 1,
                    surfaced.as_secs_f64(),
                    (after_screen - surfaced).as_secs_f64(),
                    (started.elapsed() - after_screen).as_secs_f64()
                );
            }
            source_side = side;
        }
        out
    }

    /// Listed texels and sources over all levels.
    pub fn size(&self) -> (usize, usize) {
        self.levels.iter().fold((0, 0), |(t, s), l| {
            (t + l.targets.len(), s + l.sources.len())
        })
    }
}

/// ∂P/∂u and ∂P/∂v (mm per UV unit) of every triangle; zero where its UVs are
/// degenerate.
fn jacobians(mesh: &Mesh) -> Vec<(Vec3, Vec3)> {
    mesh.indices
        .chunks_exact(3)
        .map(|t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| i as usize);
            let (e1, e2) = (
                mesh.positions[b] - mesh.positions[a],
                mesh.positions[c] - mesh.positions[a],
            );
            let (f1, f2) = (mesh.uvs[b] - mesh.uvs[a], mesh.uvs[c] - mesh.uvs[a]);
            let det = f1.perp_dot(f2);
            if det.abs() < 1e-12 || !det.is_finite() {
                return (Vec3::ZERO, Vec3::ZERO);
            }
            ((e1 * f2.y - e2 * f1.y) / det, (e2 * f1.x - e1 * f2.x) / det)
        })
        .collect()
}

/// Sub-samples per texel side for [`coverage`]: 8² = the 64 bits of a mask.
const SUBSAMPLES: u32 = 8;

/// The share of each texel of an N × N image the mesh's UVs cover, from
/// [`SUBSAMPLES`]² points, and the mean UV offset of the covered points from
/// the texel's centre: a chart border's texels hold only their part of the
/// surface, centred where it is (the exact diffusion integrates to the border,
/// not to the texel's edge).
fn coverage(mesh: &Mesh, side: u32) -> Vec<(f32, Vec2)> {
    let n = side as usize;
    // Each triangle in texel units, and its rows.
    let triangles: Vec<([Vec2; 3], f32, (usize, usize))> = mesh
        .indices
        .chunks_exact(3)
        .filter_map(|t| {
            let q = [t[0], t[1], t[2]].map(|i| mesh.uvs[i as usize] * side as f32);
            let area = (q[1] - q[0]).perp_dot(q[2] - q[0]);
            let rows = |a: f32, b: f32| {
                (
                    a.floor().max(0.0) as usize,
                    (b.ceil().max(0.0) as usize).min(n),
                )
            };
            (area != 0.0 && area.is_finite()).then(|| {
                (
                    q,
                    area,
                    rows(
                        q[0].y.min(q[1].y).min(q[2].y),
                        q[0].y.max(q[1].y).max(q[2].y),
                    ),
                )
            })
        })
        .collect();
    // One bit per sub-sample (bit 8·j + i): a point on an edge two triangles
    // share counts once. Bands of rows are filled in parallel.
    const BAND: usize = 16;
    let mut taken = vec![0u64; n * n];
    taken
        .par_chunks_mut(n * BAND)
        .enumerate()
        .for_each(|(band, rows)| {
            let (y0, y1) = (band * BAND, (band * BAND + BAND).min(n));
            for (q, area, (t0, t1)) in &triangles {
                if *t1 <= y0 || *t0 >= y1 {
                    continue;
                }
                let inside = |c: Vec2| {
                    let b1 = (c - q[0]).perp_dot(q[2] - q[0]) / area;
                    let b2 = (q[1] - q[0]).perp_dot(c - q[0]) / area;
                    b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0
                };
                let lo = q[0].min(q[1]).min(q[2]).floor().max(Vec2::ZERO).x as usize;
                let hi = (q[0].max(q[1]).max(q[2]).ceil().x.max(0.0) as usize).min(n);
                for y in (*t0).max(y0)..(*t1).min(y1) {
                    for x in lo..hi {
                        let corner = Vec2::new(x as f32, y as f32);
                        let sample = |i: u32, j: u32| {
                            corner + (Vec2::new(i as f32, j as f32) + 0.5) / SUBSAMPLES as f32
                        };
                        let last = SUBSAMPLES - 1;
                        // A convex triangle holding the four outer samples holds all.
                        let mask = if [(0, 0), (last, 0), (0, last), (last, last)]
                            .into_iter()
                            .all(|(i, j)| inside(sample(i, j)))
                        {
                            u64::MAX
                        } else {
                            let mut mask = 0u64;
                            for j in 0..SUBSAMPLES {
                                for i in 0..SUBSAMPLES {
                                    if inside(sample(i, j)) {
                                        mask |= 1 << (j * SUBSAMPLES + i);
                                    }
                                }
                            }
                            mask
                        };
                        rows[(y - y0) * n + x] |= mask;
                    }
                }
            }
        });
    let full = (SUBSAMPLES * SUBSAMPLES) as f32;
    let step = 1.0 / (SUBSAMPLES * side) as f32;
    taken
        .into_par_iter()
        .map(|mask| {
            if mask == u64::MAX || mask == 0 {
                return (mask.count_ones() as f32 / full, Vec2::ZERO);
            }
            let mut offset = Vec2::ZERO;
            for bit in (0..64).filter(|b| mask >> b & 1 == 1) {
                let (i, j) = (bit % SUBSAMPLES, bit / SUBSAMPLES);
                let centre = (SUBSAMPLES as f32 - 1.0) / 2.0;
                offset += Vec2::new(i as f32 - centre, j as f32 - centre) * step;
            }
            (
                mask.count_ones() as f32 / full,
                offset / mask.count_ones() as f32,
            )
        })
        .collect()
}

/// A covered texel: where it sits, and the metric of its triangle.
#[derive(Clone, Copy, Debug)]
struct Point {
    texel: u32,
    uv: Vec2,
    position: Vec3,
    normal: Vec3,
    centroid: Vec3,
    du: Vec3,
    dv: Vec3,
    /// The share of the texel the surface covers (1 inside a chart).
    share: f32,
    /// The centre of the surface the texel holds, and its area in mm².
    area: f32,
}

/// The covered texels of an N × N image (a texel of overlapping charts once
/// per surface point), and a grid to find them in 3-D.
struct Surface {
    side: u32,
    /// Per texel, the index in `points` of its first point, or `u32::MAX`.
    index: Vec<u32>,
    points: Vec<Point>,
}

impl Surface {
    fn new(mesh: &Mesh, jacobians: &[(Vec3, Vec3)], side: u32) -> Surface {
        // Every surface point a texel's centre maps to: where UV charts
        // overlap, each of their surfaces reads the texel (and the reference
        // integrates over both).
        let texels = texels_of_every_triangle(
            &mesh.positions,
            &mesh.normals,
            &mesh.uvs,
            &mesh.indices,
            side,
        );
        let covered = coverage(mesh, side);
        let mut index = vec![u32::MAX; (side as usize).pow(2)];
        let n2 = (side as f32).powi(2);
        let points = texels
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let first = &mut index[(t.y * side + t.x) as usize];
                if *first == u32::MAX {
                    *first = i as u32;
                }
                let (du, dv) = jacobians[t.triangle as usize];
                let (share, offset) = covered[(t.y * side + t.x) as usize];
                Point {
                    texel: t.y << 16 | t.x,
                    uv: t.uv,
                    position: t.position,
                    normal: t.normal,
                    du,
                    dv,
                    share,
                    centroid: t.position + du * offset.x + dv * offset.y,
                    area: du.cross(dv).length() / n2 * share,
                }
            })
            .collect();
        Surface {
            side,
            index,
            points,
        }
    }

    fn at(&self, x: i32, y: i32) -> Option<u32> {
        let n = self.side as i32;
        if x < 0 || y < 0 || x >= n || y >= n {
            return None;
        }
        Some(self.index[(y * n + x) as usize]).filter(|&i| i != u32::MAX)
    }

    fn grid(&self, radius: f32) -> Grid {
        let boxes: Vec<(Vec3, Vec3)> = self
            .points
            .iter()
            .map(|p| (p.centroid, p.centroid))
            .collect();
        Grid::new(&boxes, radius)
    }
}

/// (source texel, w) of one corrected texel.
type Weights = Vec<(u32, f32)>;

/// C and the normalised (source, w) list at `x`, or `None` where the chain's
/// kernel is right to within `min_error` (or x's metric is degenerate).
fn evaluate(
    x: &Point,
    sources: &Surface,
    grid: &Grid,
    (v, reach): (f32, f32),
    open: bool,
    min_error: f32,
) -> Option<(f32, Weights)> {
    let (a, b, c) = (x.du.dot(x.du), x.du.dot(x.dv), x.dv.dot(x.dv));
    let det = a * c - b * b;
    if det <= 0.0 || !det.is_finite() {
        return None;
    }
    let n = sources.side as f32;
    let area_x = det.sqrt() / (n * n);
    let reach2 = reach * reach;
    // The chain's distance to a point of UV `uv`, squared.
    let uv_distance2 = |uv: Vec2| {
        let duv = uv - x.uv;
        (x.du * duv.x + x.dv * duv.y).length_squared()
    };
    // The chain's kernel over the texel at `uv`: as [`mass`], in x's metric.
    let samples = subsamples(v, area_x);
    let uv_mass = |uv: Vec2| {
        if samples == 1 {
            return gaussian(v, uv_distance2(uv)) * area_x;
        }
        texel_mean(samples, |a| gaussian(v, uv_distance2(uv + a / n))) * area_x
    };
    // The ellipse |J Δuv| ≤ reach bounds Δu by reach·√(G⁻¹)_uu.
    let half = |g: f32| ((reach * (g / det).sqrt() * n).ceil() as i32).min(MAX_WINDOW);
    let (hu, hv) = (half(c), half(a));
    let centre = (x.uv * n - 0.5).round().as_ivec2();
    // Every UV texel within reach: (i, j), and whether it is covered.
    let window = || {
        (centre.y - hv..=centre.y + hv)
            .flat_map(move |j| (centre.x - hu..=centre.x + hu).map(move |i| (i, j)))
            .map(move |(i, j)| ((Vec2::new(i as f32, j as f32) + 0.5) / n, sources.at(i, j)))
            .filter(|(uv, _)| uv_distance2(*uv) <= reach2)
    };
    let mut ids: Vec<u32> = Vec::new();
    let mut uncovered = 0;
    for (_, id) in window() {
        match id {
            Some(id) => ids.push(id),
            None => uncovered += 1,
        }
    }
    let in_window = ids.len();
    grid.each_near(x.position, reach, |s| {
        if sources.points[s as usize]
            .centroid
            .distance_squared(x.position)
            <= reach2
        {
            ids.push(s);
        }
    });
    ids.sort_unstable();
    ids.dedup();
    let rise = x.normal / AIR_ELEVATION_DEG.to_radians().sin();
    let margin = GROSS_SIGMA * v.sqrt();
    // Per source, from distances alone: (source, within the chain's reach,
    // whether the term takes it, through the air).
    let judged: Vec<(u32, bool, bool, bool)> = ids
        .into_iter()
        .map(|s| {
            let y = &sources.points[s as usize];
            let d2_uv = uv_distance2(y.uv);
            let offset = y.centroid - x.position;
            let d2 = offset.length_squared();
            let air = offset.dot(rise) > d2.sqrt();
            let far_side = y.normal.dot(x.normal) < 0.0 && offset.dot(y.normal) > 0.0;
            // The chain and the tissue disagree where one reaches y and the other
            // does not: across the air, or by more than the margin of distance.
            let apart = (d2_uv.sqrt() - d2.sqrt()).abs() > margin;
            let chain = d2_uv <= reach2;
            // A chart border's texel counts whole in the chain, in part in the tissue.
            let takes = !far_side && (apart || (air && chain) || y.share < PARTIAL);
            (s, chain, takes, air)
        })
        .collect();
    // No source the term would take, the chain's window whole and one source
    // per texel (C = 1), and no open boundary: the term is zero.
    let chain_sources = judged.iter().filter(|s| s.1).count();
    if !open && uncovered == 0 && chain_sources == in_window && !judged.iter().any(|s| s.2) {
        return None;
    }
    let plane: f32 = window().map(|(uv, _)| uv_mass(uv)).sum();
    if plane <= 0.0 {
        return None;
    }
    // (source, K, T, takes, air), K as a share of the chain's discrete
    // kernel, T as the 3-D kernel's mass over the texel's surface; and that
    // mass over everything within reach.
    let mut weighed = Vec::with_capacity(judged.len());
    let mut reach3 = 0.0f32;
    for (s, chain, takes, air) in judged {
        let y = &sources.points[s as usize];
        let k = match chain {
            true => uv_mass(y.uv) / plane,
            false => 0.0,
        };
        let g = match y.centroid.distance_squared(x.position) <= reach2 {
            true => mass(x.position, y, n, v),
            false => 0.0,
        };
        reach3 += g;
        let t = if air { 0.0 } else { g };
        weighed.push((s, k, t, takes, air));
    }
    // Near an open boundary the reference divides by the 3-D kernel's reach.
    let norm = match open {
        true if reach3 > 0.0 => reach3,
        _ => 1.0,
    };
    // The chain compounds its levels: a kernel that keeps less than the
    // chain's mass would lose it again at every later level (the increments'
    // product, not the whole Gaussian's share). Less surface within reach
    // than a plane holds (a thin rim) is left to the chain's normalisation;
    // more (a fold's other side) adds, and the air's share is taken away.
    let kept: f32 = weighed
        .iter()
        .map(|&(_, k, t, takes, air)| if takes && !air { t } else { k })
        .sum::<f32>()
        / norm;
    let norm = norm * kept.clamp(MIN_KEPT, 1.0);
    let mut scale = weighed.iter().map(|p| p.1).sum::<f32>() / norm;
    let taken: Vec<(u32, f32)> = weighed
        .into_iter()
        .filter(|s| s.3)
        .map(|(s, k, t, _, _)| (s, (t - k) / norm))
        .filter(|s| s.1 != 0.0)
        .collect();
    let error: f32 = taken.iter().map(|s| s.1.abs()).sum();
    let (mut out, small): (Weights, Weights) =
        taken.into_iter().partition(|s| s.1.abs() >= MIN_WEIGHT);
    let at = |s: u32| sources.points[s as usize].centroid;
    // A small source's light is taken as the nearest listed source's, or as
    // the chain's own where x itself is nearer.
    for (s, w) in small {
        let d2 = |p: Vec3| p.distance_squared(at(s));
        let nearest = out
            .iter_mut()
            .map(|o| (d2(at(o.0)), o))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .filter(|(d, _)| *d < d2(x.position));
        match nearest {
            Some((_, o)) => o.1 += w,
            None => scale += w,
        }
    }
    for o in &mut out {
        o.0 = sources.points[o.0 as usize].texel;
    }
    let finite = scale.is_finite() && out.iter().all(|s| s.1.is_finite());
    (finite && error + (scale - 1.0).abs() >= min_error).then_some((scale, out))
}

/// The mass of G(v, ·) about `x` over the surface texel `y` holds (of an
/// `n`² image): the mean of G over a grid across the texel's parallelogram
/// ([`subsamples`]; one point, its centre, where the Gaussian spans
/// [`BOX_SIGMA`] texels or more) times its area. A point sample of a Gaussian
/// narrower than a texel over- or undercounts it many times over.
fn mass(x: Vec3, y: &Point, n: f32, v: f32) -> f32 {
    let samples = subsamples(v, y.area);
    if samples == 1 {
        return gaussian(v, x.distance_squared(y.centroid)) * y.area;
    }
    let side = y.share.sqrt() / n;
    let (du, dv) = (y.du * side, y.dv * side);
    texel_mean(samples, |a| {
        gaussian(v, x.distance_squared(y.centroid + du * a.x + dv * a.y))
    }) * y.area
}

/// Sub-samples per side for a Gaussian of variance `v` over a texel of
/// `area` (same units): spaced at most σ/[`BOX_SIGMA`] apart, as far apart as
/// one point per texel is at σ = [`BOX_SIGMA`] texels (the midpoint rule's
/// error, h²/24σ² of the mass near the centre, stays at 1 %); at most 8.
fn subsamples(v: f32, area: f32) -> u32 {
    let sigma_texels = (v / area).sqrt();
    match sigma_texels.is_finite() {
        true => ((BOX_SIGMA / sigma_texels).ceil() as u32).clamp(1, 8),
        false => 1,
    }
}

/// The mean of `f` over a `samples`² grid of offsets in [−½, ½]².
fn texel_mean(samples: u32, f: impl Fn(Vec2) -> f32) -> f32 {
    let step = 1.0 / samples as f32;
    let mut sum = 0.0;
    for j in 0..samples {
        for i in 0..samples {
            sum += f((Vec2::new(i as f32, j as f32) + 0.5) * step - 0.5);
        }
    }
    sum * step * step
}

/// The term of one level: `v` mm² from `sources` to `targets`, only near the
/// coarse texels `screened` flags (if given).
fn level_term(
    level: usize,
    (targets, sources): (&Surface, &Surface),
    edges: &MeshEdges,
    v: f32,
    screened: Option<&Screen>,
) -> FoldLevel {
    let reach = EXTENT_SIGMA * v.sqrt();
    let grid = sources.grid(reach);
    let candidates: Vec<&Point> = targets
        .points
        .iter()
        .filter(|x| screened.is_none_or(|s| s.flags(x.texel)))
        .collect();
    log::debug!(
        "fold term: blur{} evaluates {} of {} texels",
        level + 1,
        candidates.len(),
        targets.points.len()
    );
    let mut listed: Vec<(u32, f32, Weights)> = candidates
        .into_par_iter()
        .filter_map(|x| {
            let open = edges.to_open(x.position).is_some_and(|d| d <= reach);
            evaluate(x, sources, &grid, (v, reach), open, MIN_ERROR)
                .map(|(scale, list)| (x.texel, scale, list))
        })
        .collect();
    let mut term = FoldLevel {
        level,
        side: targets.side,
        source_side: sources.side,
        ..FoldLevel::default()
    };
    // Longest lists first: a GPU thread runs one texel's list, and threads of
    // a SIMD group wait for the longest of theirs.
    listed.sort_by_key(|(_, _, list)| std::cmp::Reverse(list.len()));
    for (texel, scale, list) in listed {
        term.targets.push(Target {
            texel,
            scale,
            first: term.sources.len() as u32,
            count: list.len() as u32,
        });
        term.sources.extend(
            list.into_iter()
                .map(|(texel, weight)| Source { texel, weight }),
        );
    }
    term
}

/// Which coarse texels (of a `side`² image) need a term, dilated by one.
struct Screen {
    side: u32,
    /// Coarse texels per level texel, per axis.
    ratio: u32,
    flagged: Vec<bool>,
}

impl Screen {
    fn flags(&self, texel: u32) -> bool {
        let (x, y) = (texel & 0xffff, texel >> 16);
        self.flagged[((y / self.ratio) * self.side + x / self.ratio) as usize]
    }
}

/// Screens a level of variance `v` on the `coarse` surface (sources at the
/// same side): the Gaussian widened by a coarse texel's area so that it spans
/// the coarse texels, out to its own reach plus a texel, flags every place a
/// fold lies within the level's reach; only where `parent` (a screen of the
/// coarse surface) flags, if given.
fn screen(coarse: &Surface, edges: &MeshEdges, v: f32, parent: Option<&Screen>) -> Screen {
    let side = coarse.side;
    let texel_area =
        coarse.points.iter().map(|p| p.area).sum::<f32>() / coarse.points.len().max(1) as f32;
    let v = v + texel_area;
    let reach = EXTENT_SIGMA * v.sqrt() + texel_area.sqrt();
    let grid = coarse.grid(reach);
    let hit: Vec<u32> = coarse
        .points
        .par_iter()
        .filter(|x| parent.is_none_or(|s| s.flags(x.texel)))
        .filter(|x| {
            let open = edges.to_open(x.position).is_some_and(|d| d <= reach);
            evaluate(x, coarse, &grid, (v, reach), open, SCREEN_ERROR).is_some()
        })
        .map(|x| x.texel)
        .collect();
    let n = side as i32;
    let mut flagged = vec![false; (side as usize).pow(2)];
    for texel in hit {
        let (x, y) = ((texel & 0xffff) as i32, (texel >> 16) as i32);
        for j in (y - 1).max(0)..=(y + 1).min(n - 1) {
            for i in (x - 1).max(0)..=(x + 1).min(n - 1) {
                flagged[(j * n + i) as usize] = true;
            }
        }
    }
    Screen {
        side,
        ratio: SCREEN,
        flagged,
    }
}

#[cfg(test)]
mod tests {
    use super::cache::cache_key;
    use super::*;
    use crate::cache::hex;
    use crate::skin::reference::Diffusion;

    const SIDE: u32 = 128;
    const SIGMA: f32 = 0.7;

    /// Quads (corners counter-clockwise seen from their normal, with UVs) as a mesh.
    fn mesh(quads: &[([Vec3; 4], [Vec2; 4])]) -> Mesh {
        let mut m = Mesh {
            name: "test".into(),
            positions: Vec::new(),
            normals: Vec::new(),
            uvs: Vec::new(),
            tangents: Vec::new(),
            indices: Vec::new(),
        };
        for (p, uv) in quads {
            let base = m.positions.len() as u32;
            let n = (p[1] - p[0]).cross(p[3] - p[0]).normalize();
            m.positions.extend(p);
            m.uvs.extend(uv);
            m.normals.extend([n; 4]);
            m.indices.extend([0, 1, 2, 0, 2, 3].map(|i| base + i));
        }
        m
    }

    fn quad(x0: f32, x1: f32, u0: f32, u1: f32) -> ([Vec3; 4], [Vec2; 4]) {
        let p = |x: f32, y: f32| Vec3::new(x, y, 0.0);
        (
            [p(x0, -20.0), p(x1, -20.0), p(x1, 20.0), p(x0, 20.0)],
            [
                Vec2::new(u0, 0.0),
                Vec2::new(u1, 0.0),
                Vec2::new(u1, 1.0),
                Vec2::new(u0, 1.0),
            ],
        )
    }

    #[test]
    fn coverage_counts_a_shared_edge_once_and_centres_a_partial_texel() {
        // A 4 × 4 image; the quad's two triangles share the diagonal of every
        // texel they cross, and the quad ends half-way across column 2.
        let m = mesh(&[quad(0.0, 10.0, 0.0, 0.625)]);
        let c = coverage(&m, 4);
        for y in 0..4 {
            let at = |x: usize| c[y * 4 + x];
            for x in 0..2 {
                assert_eq!(at(x), (1.0, Vec2::ZERO), "texel ({x}, {y}) inside");
            }
            let (share, offset) = at(2);
            assert_eq!(share, 0.5, "half of column 2");
            // The covered half's centre: a quarter texel left of the centre.
            assert!(
                (offset - Vec2::new(-0.25 / 4.0, 0.0)).length() < 1e-6,
                "{offset}"
            );
            assert_eq!(at(3), (0.0, Vec2::ZERO));
        }
    }

    #[test]
    fn sub_samples_are_at_most_half_a_sigma_apart() {
        // (σ in texels, sub-samples per side)
        for (sigma, n) in [(2.0, 1), (3.0, 1), (1.0, 2), (0.5, 4), (0.3, 7), (0.1, 8)] {
            assert_eq!(subsamples(sigma * sigma, 1.0), n, "σ = {sigma} texels");
        }
        // A Gaussian of σ = 0.3 texels over the texel it is centred on: the
        // sub-samples give its mass within the midpoint rule's 1 %.
        let v = 0.09f32;
        let mean = texel_mean(subsamples(v, 1.0), |a| gaussian(v, a.length_squared()));
        // erf(0.5 / (0.3 √2))², by Python's math.erf.
        let mass = 0.817_974_3;
        assert!((mean / mass - 1.0).abs() < 0.01, "{mean} against {mass}");
    }

    /// Over the texels within 2 mm of x = 0 (away from the outer edges): the
    /// largest error of the chain's model, without and with the term, against
    /// the reference without air paths, with E = 1 on the charts left of u = ½.
    fn errors(m: &Mesh) -> (f32, f32) {
        errors_at(m, SIGMA)
    }

    fn errors_at(m: &Mesh, sigma: f32) -> (f32, f32) {
        let levels = [Level {
            resolution: SIDE,
            sigma_mm: Some(sigma),
            one_pass: None,
        }];
        let term = FoldTerm::compute(m, &levels, SIDE);
        let level = &term.levels[0];
        let jac = jacobians(m);
        let surface = Surface::new(m, &jac, SIDE);
        let e = |uv: Vec2| if uv.x < 0.5 { 1.0 } else { 0.0 };
        let v = sigma * sigma;
        let reference = Diffusion::new(&m.positions, &m.uvs, &m.indices, &[v]).unwrap();
        let edges = MeshEdges::new(&m.positions, &m.uvs, &m.indices, reference.extent());
        let (mut before, mut after) = (0.0f32, 0.0f32);
        for x in &surface.points {
            if x.position.x.abs() > 2.0 || x.position.y.abs() > 10.0 {
                continue;
            }
            // The chain: the UV Gaussian under x's metric, normalised over the covered texels.
            let (mut sum, mut total) = (0.0, 0.0);
            for y in &surface.points {
                let duv = y.uv - x.uv;
                let d2 = (x.du * duv.x + x.dv * duv.y).length_squared();
                let g = gaussian(v, d2);
                sum += g * e(y.uv);
                total += g;
            }
            let chain = sum / total;
            let corrected = match level.targets.iter().find(|t| t.texel == x.texel) {
                Some(t) => {
                    let list = &level.sources[t.first as usize..(t.first + t.count) as usize];
                    let at = |texel: u32| {
                        let (i, j) = (texel & 0xffff, texel >> 16);
                        e((Vec2::new(i as f32, j as f32) + 0.5) / SIDE as f32)
                    };
                    t.scale * chain + list.iter().map(|s| s.weight * at(s.texel)).sum::<f32>()
                }
                None => chain,
            };
            let s = reference.at(x.position, x.normal, &|uv| Some(Vec3::splat(e(uv))));
            let open = edges
                .to_open(x.position)
                .is_some_and(|d| d < reference.reach()[0]);
            let exact = s.diffuse(&[Vec3::ONE], false, |_| open).x;
            before = before.max((chain - exact).abs());
            after = after.max((corrected - exact).abs());
        }
        (before, after)
    }

    #[test]
    fn a_plane_of_one_chart_needs_no_term() {
        let m = mesh(&[quad(-20.0, 20.0, 0.05, 0.95)]);
        let levels = [Level {
            resolution: SIDE,
            sigma_mm: Some(SIGMA),
            one_pass: None,
        }];
        let term = FoldTerm::compute(&m, &levels, SIDE);
        // Only the border's texels, which hold part of a texel's surface, are
        // listed: none farther than the reach (2.8 mm, 8 texels) from it.
        let inner = |texel: u32| {
            let (x, y) = (texel & 0xffff, texel >> 16);
            (16..SIDE - 16).contains(&y) && (16..SIDE - 16).contains(&x)
        };
        let targets = &term.levels[0].targets;
        assert!(!targets.is_empty());
        assert!(targets.iter().all(|t| !inner(t.texel)), "{targets:?}");
    }

    #[test]
    fn the_cache_is_read_back_and_keyed_by_the_levels() {
        let m = mesh(&[quad(-20.0, 0.0, 0.02, 0.45), quad(0.0, 20.0, 0.55, 0.98)]);
        let levels = [Level {
            resolution: SIDE,
            sigma_mm: Some(SIGMA),
            one_pass: None,
        }];
        let dir = std::env::temp_dir().join(format!("dermis-fold-test-{}", std::process::id()));
        let term = FoldTerm::load_or_compute(&m, &levels, SIDE, &dir);
        assert!(term.size().0 > 0);
        let key = cache_key(&m, &levels, SIDE);
        let path = dir.join(format!("fold-{}.bin", hex(key)));
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(FoldTerm::from_bytes(&bytes), Some(term.clone()));
        assert_eq!(FoldTerm::load_or_compute(&m, &levels, SIDE, &dir), term);
        // Cut short, the file is not a term.
        assert_eq!(FoldTerm::from_bytes(&bytes[..bytes.len() - 1]), None);
        let wider = [Level {
            sigma_mm: Some(2.0 * SIGMA),
            ..levels[0]
        }];
        assert_ne!(cache_key(&m, &wider, SIDE), key);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_seam_gets_the_other_sides_light() {
        // One plane, two charts apart in UV: the left half lit.
        let m = mesh(&[quad(-20.0, 0.0, 0.02, 0.45), quad(0.0, 20.0, 0.55, 0.98)]);
        let (before, after) = errors(&m);
        assert!(before > 0.3, "the chain alone: {before}");
        // 1.9 % (the sources under MIN_WEIGHT counted as the texel's own
        // light instead of their nearest listed neighbour's: 3.5 %).
        assert!(after < 0.025, "with the term: {after} (before {before})");
    }

    #[test]
    fn a_level_narrower_than_a_texel_is_integrated_over_the_texels() {
        // σ = 0.12 mm, a third of a texel: point samples would weigh the other
        // side's nearest texel several times over.
        let m = mesh(&[quad(-20.0, 0.0, 0.02, 0.45), quad(0.0, 20.0, 0.55, 0.98)]);
        let (before, after) = errors_at(&m, 0.12);
        assert!(before > 0.3, "the chain alone: {before}");
        assert!(after < 0.05, "with the term: {after} (before {before})");
    }

    #[test]
    fn a_gap_of_a_millimetre_is_crossed_as_the_reference_crosses_it() {
        // Two coplanar half-planes 1 mm apart, open edges facing: the reference
        // normalises by its reach there, and so does the term.
        let m = mesh(&[quad(-20.0, -0.5, 0.02, 0.45), quad(0.5, 20.0, 0.55, 0.98)]);
        let (before, after) = errors(&m);
        assert!(before > 0.1, "the chain alone: {before}");
        assert!(after < 0.02, "with the term: {after} (before {before})");
    }

    #[test]
    fn a_groove_keeps_its_other_wall_out_of_the_air() {
        // A V groove along y of 60°, one chart unfolded: the chain reaches the
        // other wall along the surface; the reference without air paths does not.
        // Walls at ±30° from the vertical: x = ±t sin 30°, z = t cos 30°.
        let (sx, cz) = (30f32.to_radians().sin(), 30f32.to_radians().cos());
        let left = (
            [
                Vec3::new(-20.0 * sx, -20.0, 20.0 * cz),
                Vec3::new(0.0, -20.0, 0.0),
                Vec3::new(0.0, 20.0, 0.0),
                Vec3::new(-20.0 * sx, 20.0, 20.0 * cz),
            ],
            [
                Vec2::new(0.05, 0.0),
                Vec2::new(0.5, 0.0),
                Vec2::new(0.5, 1.0),
                Vec2::new(0.05, 1.0),
            ],
        );
        let right = (
            [
                Vec3::new(0.0, -20.0, 0.0),
                Vec3::new(20.0 * sx, -20.0, 20.0 * cz),
                Vec3::new(20.0 * sx, 20.0, 20.0 * cz),
                Vec3::new(0.0, 20.0, 0.0),
            ],
            [
                Vec2::new(0.5, 0.0),
                Vec2::new(0.95, 0.0),
                Vec2::new(0.95, 1.0),
                Vec2::new(0.5, 1.0),
            ],
        );
        let m = mesh(&[left, right]);
        let (before, after) = errors(&m);
        assert!(before > 0.1, "the chain alone: {before}");
        // The texel row at the crease is classified whole as through the air
        // or not, where the reference splits it: 4.8 % there, 2 % elsewhere.
        assert!(
            after < 0.05 && after < before / 5.0,
            "with the term: {after} (before {before})"
        );
    }
}
