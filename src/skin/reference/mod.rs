//! The exact-diffusion reference: the skin profile convolved with the
//! irradiance over the surface in 3-D, by Euclidean distance (Jensen & Buhler
//! 2002, "A Rapid Hierarchical Rendering Technique for Translucent Materials"),
//! the yardstick for the texture-space chain (docs/records/2026-11-26-exact-diffusion.md, "Exact diffusion").
//!
//! At a point x, per Gaussian k of the profile,
//! `M_k(x) = ∫ G(v_k, |x − y|) E(y) dA(y)` and the profile's reach
//! `C_k(x) = ∫ G(v_k, |x − y|) dA(y)` (1 on an unbounded plane), each Gaussian
//! out to its own 4σ (the extent; beyond lies e⁻⁸ of its energy).
//! Each triangle near x is split in four until its pieces are smaller than
//! [`LEAF_SIGMA`] σ of the narrowest Gaussian that reaches them (and, where E
//! changes across a piece, down to [`FINEST_SIGMA`] σ), and each piece counts
//! once, by the edge-midpoint rule: fine near x, coarse far away (Jensen &
//! Buhler's hierarchy, built per query). E is read at the piece's UV, so the
//! reference sees the same irradiance as the texture-space chain. The light
//! whose straight path crosses the air is kept apart ([`Scattered::through_air`]).
//!
//! Files: `grid.rs` (which triangles are near), `texels.rs` (where a texel sits
//! on the surface), `edges.rs` (UV seams and open boundaries).

mod edges;
mod grid;
mod texels;

pub use edges::MeshEdges;
pub use grid::Grid;
pub use texels::{texels, texels_of_every_triangle, Texel};

use crate::error::{Error, Result};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A piece of a triangle stops splitting once its circumradius is below this
/// many σ of the narrowest Gaussian that reaches it (the plane and sphere tests
/// in `tests.rs` hold 0.5 % with it).
pub const LEAF_SIGMA: f32 = 0.35;
/// How far the profile reaches, in σ of each Gaussian (exp(−8) ≈ 3·10⁻⁴ beyond).
pub const EXTENT_SIGMA: f32 = 4.0;
/// A piece smooth for the profile still splits, down to this many σ, while E at
/// a corner differs from E at its centroid by more than [`SMOOTH_E`] of it.
pub const FINEST_SIGMA: f32 = 0.05;
/// See [`FINEST_SIGMA`].
pub const SMOOTH_E: f32 = 0.02;
/// A path that rises more than this above x's tangent plane leaves x into the
/// air (see [`Scattered::through_air`]): steeper than a gently curved surface's
/// own chords (at 5 mm on a 20 mm radius of curvature, 7°), shallower than a
/// fold's other side.
pub const AIR_ELEVATION_DEG: f32 = 20.0;
/// Splits per triangle at most (a guard against degenerate input).
const MAX_DEPTH: u32 = 24;

/// The mesh, ready for queries with a profile's variances.
pub struct Diffusion<'a> {
    positions: &'a [Vec3],
    uvs: &'a [Vec2],
    triangles: Vec<[u32; 3]>,
    variances: Vec<f32>,
    /// EXTENT_SIGMA · σ_k.
    reach: Vec<f32>,
    grid: Grid,
    irradiance_scale: f32,
}

/// What the surface around a point gives, per Gaussian of the profile.
#[derive(Clone, Debug, PartialEq)]
pub struct Scattered {
    /// M_k: the irradiance convolved with Gaussian k.
    pub irradiance: Vec<Vec3>,
    /// C_k: Gaussian k integrated over the surface (1 on a plane).
    pub reach: Vec<f32>,
    /// The part of M_k whose straight path leaves x into the air: more than
    /// [`AIR_ELEVATION_DEG`] above x's tangent plane (across a fold, a crease,
    /// the gap behind an ear), where light inside the skin goes the longer way
    /// round. Without it, M_k is a lower bound of the light there; with it an
    /// upper bound (docs/records/2026-11-26-exact-diffusion.md, "Exact diffusion").
    pub through_air: Vec<Vec3>,
}

impl<'a> Diffusion<'a> {
    /// `positions` in mm, `uvs` per vertex, `indices` three per triangle,
    /// `variances` (mm², ascending, positive) of the profile's Gaussians.
    pub fn new(
        positions: &'a [Vec3],
        uvs: &'a [Vec2],
        indices: &[u32],
        variances: &[f32],
    ) -> Result<Self> {
        if positions.len() != uvs.len() {
            return Err(Error::Input(format!(
                "exact diffusion: {} positions but {} UVs",
                positions.len(),
                uvs.len()
            )));
        }
        if !indices.len().is_multiple_of(3)
            || indices.iter().any(|&i| i as usize >= positions.len())
        {
            return Err(Error::Input(
                "exact diffusion: indices are not triangles of the mesh's vertices".into(),
            ));
        }
        let ascending = variances.windows(2).all(|w| w[0] < w[1]);
        if variances.is_empty()
            || !ascending
            || !variances.iter().all(|v| v.is_finite() && *v > 0.0)
        {
            return Err(Error::Input(format!(
                "exact diffusion: variances {variances:?} are not positive and ascending"
            )));
        }
        let triangles: Vec<[u32; 3]> = indices
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        let reach: Vec<f32> = variances.iter().map(|v| EXTENT_SIGMA * v.sqrt()).collect();
        let boxes: Vec<(Vec3, Vec3)> = triangles
            .iter()
            .map(|t| {
                let p = t.map(|i| positions[i as usize]);
                (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
            })
            .collect();
        let widest = *reach.last().expect("checked non-empty");
        Ok(Diffusion {
            grid: Grid::new(&boxes, widest),
            positions,
            uvs,
            triangles,
            variances: variances.to_vec(),
            reach,
            irradiance_scale: 0.0,
        })
    }

    /// The typical irradiance (e.g. its mean over the mesh): darker pieces are
    /// smooth when E changes by less than [`SMOOTH_E`] of it.
    pub fn with_irradiance_scale(self, scale: f32) -> Self {
        Diffusion {
            irradiance_scale: scale.max(0.0),
            ..self
        }
    }

    /// Each Gaussian's reach (EXTENT_SIGMA σ), mm.
    pub fn reach(&self) -> &[f32] {
        &self.reach
    }

    /// The widest Gaussian's reach, mm.
    pub fn extent(&self) -> f32 {
        *self.reach.last().expect("checked non-empty")
    }

    /// M_k and C_k at `x` (mm), whose outward normal is `normal` (zero: no path
    /// counts as through the air). `irradiance(uv)` is E at a point of the mesh
    /// by its UV; `None` where there is none (outside the irradiance's
    /// coverage): such a piece counts in neither.
    pub fn at(
        &self,
        x: Vec3,
        normal: Vec3,
        irradiance: &impl Fn(Vec2) -> Option<Vec3>,
    ) -> Scattered {
        let n = self.variances.len();
        let mut out = Scattered {
            irradiance: vec![Vec3::ZERO; n],
            reach: vec![0.0; n],
            through_air: vec![Vec3::ZERO; n],
        };
        let rise = normal.normalize_or_zero() / AIR_ELEVATION_DEG.to_radians().sin();
        let mut near = Vec::new();
        self.grid.near(x, self.extent(), &mut near);
        for &t in &near {
            let t = self.triangles[t as usize];
            let p = t.map(|i| self.positions[i as usize]);
            let uv = t.map(|i| self.uvs[i as usize]);
            self.piece(x, rise, p, uv, 0, irradiance, &mut out);
        }
        out
    }

    /// Whether E at the corners is within [`SMOOTH_E`] of E at the centre (or
    /// of the irradiance scale, where E is darker).
    fn smooth(&self, centre: Option<Vec3>, corners: [Option<Vec3>; 3]) -> bool {
        let Some(c) = centre else {
            return corners.iter().all(Option::is_none);
        };
        let tolerance = SMOOTH_E * c.max_element().max(self.irradiance_scale);
        corners
            .iter()
            .all(|e| e.is_some_and(|e| (e - c).abs().max_element() <= tolerance))
    }

    #[allow(clippy::too_many_arguments)]
    fn piece(
        &self,
        x: Vec3,
        rise: Vec3,
        p: [Vec3; 3],
        uv: [Vec2; 3],
        depth: u32,
        irradiance: &impl Fn(Vec2) -> Option<Vec3>,
        out: &mut Scattered,
    ) {
        let c = (p[0] + p[1] + p[2]) / 3.0;
        let radius = p.iter().map(|q| q.distance(c)).fold(0.0, f32::max);
        let d = x.distance(c);
        // The narrowest Gaussian that reaches any part of the piece.
        let Some(k0) = self.reach.iter().position(|&r| r >= d - radius) else {
            return;
        };
        let sigma = self.variances[k0].sqrt();
        // Split what is coarse for the profile, or for the irradiance: where E
        // changes across the piece (a shadow edge) by more than SMOOTH_E.
        let profile_coarse = radius > LEAF_SIGMA * sigma;
        let e = match profile_coarse {
            true => None,
            false => irradiance((uv[0] + uv[1] + uv[2]) / 3.0),
        };
        let coarse = profile_coarse
            || (radius > FINEST_SIGMA * sigma && !self.smooth(e, uv.map(irradiance)));
        if coarse && depth < MAX_DEPTH {
            let m = |a: usize, b: usize| ((p[a] + p[b]) * 0.5, (uv[a] + uv[b]) * 0.5);
            let (m01, m12, m20) = (m(0, 1), m(1, 2), m(2, 0));
            for (q, w) in [
                ([p[0], m01.0, m20.0], [uv[0], m01.1, m20.1]),
                ([m01.0, p[1], m12.0], [m01.1, uv[1], m12.1]),
                ([m20.0, m12.0, p[2]], [m20.1, m12.1, uv[2]]),
                ([m01.0, m12.0, m20.0], [m01.1, m12.1, m20.1]),
            ] {
                self.piece(x, rise, q, w, depth + 1, irradiance, out);
            }
            return;
        }
        let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
        if area <= 0.0 || d > self.extent() {
            return;
        }
        let Some(e) = e else {
            return;
        };
        // The profile by the edge-midpoint rule (exact for quadratics), E at the
        // centroid: E is a bilinear texture, smooth over a piece.
        let r2 = [(0, 1), (1, 2), (2, 0)].map(|(a, b)| x.distance_squared((p[a] + p[b]) * 0.5));
        let air = (c - x).dot(rise) > d;
        for k in k0..self.variances.len() {
            let v = self.variances[k];
            let g = area / 3.0 * r2.iter().map(|&r2| gaussian(v, r2)).sum::<f32>();
            out.irradiance[k] += g * e;
            out.reach[k] += g;
            if air {
                out.through_air[k] += g * e;
            }
        }
    }
}

/// G(v, r) = exp(−r²/2v)/(2πv), the profile's normalised 2-D Gaussian
/// (GPU Gems 3 §14.4), of r².
pub fn gaussian(v: f32, r2: f32) -> f32 {
    (-r2 / (2.0 * v)).exp() / (2.0 * PI * v)
}

impl Scattered {
    /// Σ_k w_k M_k: the diffused irradiance with per-channel weights `weights`
    /// (one per Gaussian), with or without the light whose path crosses the air;
    /// Gaussian k is divided by its reach C_k where `normalised(k)` (near an open
    /// boundary of the mesh, as the texture-space chain normalises by coverage).
    pub fn diffuse(
        &self,
        weights: &[Vec3],
        through_air: bool,
        normalised: impl Fn(usize) -> bool,
    ) -> Vec3 {
        weights
            .iter()
            .zip(&self.irradiance)
            .zip(&self.through_air)
            .zip(&self.reach)
            .enumerate()
            .map(|(k, (((w, all), air), c))| {
                let m = if through_air { *all } else { *all - *air };
                let m = &m;
                if normalised(k) && *c > 0.0 {
                    *w * *m / *c
                } else {
                    *w * *m
                }
            })
            .sum()
    }
}

#[cfg(test)]
mod tests;
