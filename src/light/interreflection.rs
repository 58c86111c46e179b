//! Interreflected transfer (Sloan, Kautz & Snyder 2002, §5): the light the
//! skin reflects onto itself — into creases, between the ear and the head,
//! under the chin — as a per-vertex SH transfer added to the direct one.
//!
//! # What is computed
//! The skin around a vertex leaves `L_o = ρ/π · E` (Lambertian, `ρ` its
//! albedo at the hit), and `E(hit) = Σ_j L_j (T_j + B_j)(hit)` with `T` the
//! direct transfer ([`occlusion`](super::occlusion)) and `B` this one. Over the
//! directions a vertex's cosine-weighted rays (`p(ω) = N·ω/π`) see the mesh's
//! front, `E_b = ∫ L_o(hit(ω)) N·ω dω ≈ (π/n) Σ_k L_o(hit_k)`, so per channel
//! ```text
//! B_j(v) ≈ (1/n) Σ_{k: ray k hits a front face} ρ(hit_k) · (T_j + B_j)(hit_k)
//! ```
//! with the hit's transfer interpolated from its triangle's corners as the
//! GPU interpolates it. Solved by iteration from `B = 0`, one bounce each,
//! until a bounce adds nothing that matters ([`TOLERANCE`]).
//! The sparse operator (row v: the corners its rays hit, weighted by
//! barycentrics × ρ / n) is built once from one ray cast per direction.
//!
//! # What is left out
//! Back faces (the inside of the head) reflect nothing. The hit reflects
//! `ρ·E`: its oil layer takes ρs·Ā ≈ 4 % of the light from the diffuse
//! (docs/design/skin.md) and reflects it itself, so `ρ`, the albedo map, stands for
//! both within ρs·Ā·(1 − ρ) ≈ 2 % of the hit's light. The GPU applies `B` to the
//! environment's SH and to the explicit lights projected into SH at the
//! receiving vertex (`uv_lit.vert`, `irradiance_vertices.comp`), so a lamp's light bounces as if the
//! hit's own occlusion shadowed it: second-order light, low in frequency.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use glam::Vec3;
use rayon::prelude::*;

use super::occlusion::{cache_key, rgb_cached};
use super::occlusion::{directions, transfer_key, Bvh, RayOptions, RgbTransfer, Transfer};
use super::reference::rgba8;
use crate::scene::file::Occlusion;
use crate::scene::mesh::Mesh;
use crate::scene::texture::Texture;

/// Bounces are summed until the last one adds at most this share of the
/// largest direct coefficient: a cavity that reflects q of what it receives
/// needs ln(tolerance)/ln(q) bounces, 7 for the skin's creases (ρ ≤ 0.6, at
/// most half the hemisphere blocked: q ≤ 0.3), 39 for q = 0.8.
const TOLERANCE: f32 = 1e-4;
/// The most bounces summed (q ≤ 0.98 converges within it).
const MAX_BOUNCES: u32 = 500;

/// One row of the bounce operator: (vertex, RGB weight) pairs.
type Row = Vec<(u32, [f32; 3])>;

/// Row of vertex `i` at `p` with unit normal `nrm`: its rays' front-face hits.
fn row(
    bvh: &Bvh,
    mesh: &Mesh,
    albedo: &Texture,
    p: Vec3,
    nrm: Vec3,
    opts: &RayOptions,
    i: u32,
) -> Row {
    let n = opts.samples.max(1);
    let origin = p + nrm * opts.offset_mm.max(0.0);
    let mut row: Row = Vec::new();
    for w in directions(nrm, n, opts.seed, i) {
        let Some(hit) = bvh.closest_hit(origin, w, f32::INFINITY) else {
            continue;
        };
        // The hit's side facing the ray: the interpolated normal against it.
        if hit.interpolate(mesh, &mesh.normals).dot(w) >= 0.0 {
            continue;
        }
        let (corners, b) = (hit.corners(mesh), hit.barycentric.to_array());
        // The albedo as the GPU samples it there (bilinear, sRGB decoded).
        let rho = rgba8(albedo, hit.interpolate(mesh, &mesh.uvs)).truncate() / n as f32;
        for k in 0..3 {
            row.push((corners[k] as u32, (rho * b[k]).to_array()));
        }
    }
    row.sort_unstable_by_key(|e| e.0);
    row.dedup_by(|e, kept| {
        let same = e.0 == kept.0;
        if same {
            for c in 0..3 {
                kept.1[c] += e.1[c];
            }
        }
        same
    });
    row
}

/// `B ← K·(T + B)` until converged (module doc, [`TOLERANCE`]); also the
/// number of bounces summed.
fn iterate(rows: &[Row], direct: &Transfer) -> (RgbTransfer, u32) {
    let scale = direct
        .coeffs
        .iter()
        .flatten()
        .fold(0.0f32, |a, t| a.max(t.abs()));
    let mut b = RgbTransfer::none(rows.len());
    for bounce in 1..=MAX_BOUNCES {
        let next: Vec<[[f32; 9]; 3]> = rows
            .par_iter()
            .map(|row| {
                let mut out = [[0.0f32; 9]; 3];
                for &(u, w) in row {
                    let (t, bu) = (&direct.coeffs[u as usize], &b.coeffs[u as usize]);
                    for c in 0..3 {
                        for j in 0..9 {
                            out[c][j] += w[c] * (t[j] + bu[c][j]);
                        }
                    }
                }
                out
            })
            .collect();
        let change = next
            .iter()
            .flatten()
            .flatten()
            .zip(b.coeffs.iter().flatten().flatten())
            .fold(0.0f32, |a, (x, y)| a.max((x - y).abs()));
        b.coeffs = next;
        if change <= TOLERANCE * scale {
            return (b, bounce);
        }
    }
    (b, MAX_BOUNCES)
}

/// The interreflected transfer of `mesh` under `direct` (its direct transfer)
/// with the albedo map `albedo`, by rays cast as `opts` says (module doc).
pub fn interreflect(
    mesh: &Mesh,
    albedo: &Texture,
    direct: &Transfer,
    opts: &RayOptions,
) -> RgbTransfer {
    let start = Instant::now();
    let bvh = Bvh::from_mesh(mesh);
    let invalid = AtomicUsize::new(0);
    let rows: Vec<Row> = (0..mesh.vertex_count())
        .into_par_iter()
        .map(|i| {
            let (Some(&p), Some(n)) = (
                mesh.positions.get(i),
                mesh.normals.get(i).and_then(|n| n.try_normalize()),
            ) else {
                invalid.fetch_add(1, Ordering::Relaxed);
                return Row::new();
            };
            if !p.is_finite() {
                invalid.fetch_add(1, Ordering::Relaxed);
                return Row::new();
            }
            row(&bvh, mesh, albedo, p, n, opts, i as u32)
        })
        .collect();
    let (b, bounces) = iterate(&rows, direct);
    log::info!(
        "interreflection: {} vertices × {} rays, {bounces} bounces: {:.2} s ({} without a frame)",
        rows.len(),
        opts.samples,
        start.elapsed().as_secs_f64(),
        invalid.into_inner()
    );
    b
}

/// FNV-1a 64 of the albedo map (its size and bytes), for the cache key.
fn albedo_hash(albedo: &Texture) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let dims = [albedo.width, albedo.height].map(u32::to_le_bytes);
    for &byte in dims.iter().flatten().chain(&albedo.rgba8) {
        h ^= u64::from(byte);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// [`interreflect`] with the default rays for the direct transfer `direct` of
/// occlusion `mode` (none for `Off`), from the disk cache when it holds it
/// (keyed by the mesh, the direct transfer's key, the albedo map and the
/// settings).
pub fn bounce_for(
    mesh: &Mesh,
    albedo: &Texture,
    direct: &Transfer,
    mode: Occlusion,
) -> RgbTransfer {
    let Some(direct_key) = transfer_key(mesh, mode) else {
        return RgbTransfer::none(mesh.vertex_count());
    };
    let opts = RayOptions {
        // Other directions than the direct transfer's: independent noise.
        seed: 1,
        ..RayOptions::default()
    };
    let settings = format!(
        "{} tolerance={TOLERANCE} albedo_lookup=bilinear direct={direct_key} albedo={:016x}",
        opts.cache_settings(),
        albedo_hash(albedo)
    );
    let key = cache_key(mesh, "interreflection", &settings);
    rgb_cached("interreflection", &key, mesh.vertex_count(), || {
        interreflect(mesh, albedo, direct, &opts)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::occlusion::testutil::open_sphere;
    use crate::light::occlusion::{raytrace, unoccluded};
    use crate::scene::texture::Encoding;
    use std::f32::consts::PI;

    /// A sphere of radius `r` without the cap within `alpha` of +Y, seen
    /// from inside (normals inward).
    fn cavity(r: f32, alpha: f32, rings: u32, segments: u32) -> Mesh {
        let mut m = open_sphere(r, alpha, rings, segments);
        for n in &mut m.normals {
            *n = -*n;
        }
        m
    }

    /// Inside a sphere every point sees every area element dA of it with the
    /// form factor dA/(4πR²) (the sphere's constant form factor), so under a
    /// uniform sky of radiance L through an opening that is a cap of the
    /// sphere (the share f = (1 − cos α)/2 of its area), every point of the
    /// wall receives E₀ = πLf directly and, with albedo ρ and every bounce,
    /// E = πLf / (1 − ρ(1 − f)). Checked on the vertices away from the rim.
    #[test]
    fn a_spherical_cavity_gets_the_closed_form() {
        let alpha = 1.0_f32;
        let m = cavity(100.0, alpha, 48, 96);
        let f = (1.0 - alpha.cos()) / 2.0;
        let opts = RayOptions::default();
        let direct = raytrace(&m, &opts, false);
        for rho in [0.3_f32, 0.8] {
            let grey = (rho * 255.0).round() as u8;
            let albedo = Texture::solid([grey, grey, grey, 255], Encoding::Linear);
            let rho = f32::from(grey) / 255.0;
            let b = interreflect(&m, &albedo, &direct, &RayOptions { seed: 1, ..opts });
            // E/(πL) = (T_0 + B_0)·L_0/(πL), L_0 = L·4π·Y00 for uniform radiance.
            let scale = 4.0 * PI * crate::light::sh::K00 / PI;
            let (mut sum, mut count, mut worst) = (0.0f64, 0, 0.0f32);
            let expected = f / (1.0 - rho * (1.0 - f));
            for (i, p) in m.positions.iter().enumerate() {
                if (p.y / 100.0).acos() < alpha + 0.5 {
                    continue;
                }
                let e = (direct.coeffs[i][0] + b.coeffs[i][0][0]) * scale;
                sum += f64::from(e);
                count += 1;
                worst = worst.max((e / expected - 1.0).abs());
            }
            let mean = (sum / f64::from(count)) as f32;
            let direct_only = f;
            eprintln!(
                "ρ {rho:.3}: E/πL mean {mean:.4}, expected {expected:.4} (direct {direct_only:.4}), \
                 worst vertex {:.1} %, {count} vertices",
                worst * 100.0
            );
            assert!(
                (mean / expected - 1.0).abs() < 0.005,
                "mean {mean} vs {expected}"
            );
            assert!(worst < 0.1, "worst vertex {worst}");
            // Each channel alike under a grey albedo.
            let i = m.vertex_count() - 1;
            assert_eq!(b.coeffs[i][0], b.coeffs[i][2]);
        }
    }

    /// A convex mesh sees none of itself: no interreflection.
    #[test]
    fn a_convex_mesh_reflects_nothing_onto_itself() {
        let m = open_sphere(100.0, 0.3, 16, 32);
        let albedo = Texture::solid([255; 4], Encoding::Linear);
        let b = interreflect(&m, &albedo, &unoccluded(&m), &RayOptions::default());
        // The open cap's rim is the only place a ray can meet the mesh again.
        let zero = b
            .coeffs
            .iter()
            .filter(|c| c.iter().flatten().all(|&x| x == 0.0))
            .count();
        assert!(
            zero as f32 >= 0.95 * m.vertex_count() as f32,
            "{zero} of {}",
            m.vertex_count()
        );
    }
}
