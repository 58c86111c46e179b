//! The environment's light through thin skin (the ears, the nostrils' rims):
//! a per-vertex transfer of the SH environment entering the skin's far side
//! and diffusing through to the near one, the environment's counterpart of
//! the final pass's translucent shadow maps for the explicit lights
//! (docs/records/2026-11-26-transmission.md, "Transmission").
//!
//! # What is computed
//! Light entering the surface at q with irradiance E(q) leaves at p with the
//! profile R(|p − q|) per unit area (d'Eon & Luebke's model; Jensen & Buhler
//! 2002 integrate it over the surface). Texture-space diffusion sums it over
//! the surface around p; what it misses is the far side of a thin part, which
//! lies near p in space but far along the surface. So over the far side
//! (surface points whose normal faces away from p's: n_q·n_p < 0),
//! ```text
//! M(p) = ∫ E(q) R(|p − q|) dA_q,   dA_q = t² dω / cos_q
//! ```
//! by rays from p into the skin (cosine-weighted about −n_p, `t` the distance
//! to the first surface the ray leaves the mesh by, cos_q = n_q·ω), with E(q)
//! the environment through q's own transfer, `Σ_j L_j T_j(q)` (interpolated
//! from the hit triangle's corners as on the GPU). Per channel
//! ```text
//! X_j(p) ≈ (π/n) Σ_k T_j(q_k) · R(t_k) · t_k² / (cos_q · cos_p)
//! ```
//! times `skin.transmission`, so that `M = Σ_j L_j X_j`. On a slab d thick
//! this is `E·Σ wᵢ exp(−d²/2vᵢ)` ([`Profile::transmittance`], the tests).
//! With a medium, R is the kernel whose integral over a slab's far side is
//! the medium's walked T(d) ÷ albedo (the final pass multiplies by the
//! albedo): ∫_d^∞ R(r) 2πr dr = T(d) gives R(r) = −T′(r)/2πr (skin::falloff).
//! The GPU applies it to the environment's SH only (the explicit lights have
//! their own term).

use glam::Vec3;
use rayon::prelude::*;

use super::occlusion::{cache_key, directions, rgb_cached, transfer_key};
use super::occlusion::{Bvh, RayOptions, RgbTransfer, Transfer};
use crate::scene::file::Occlusion;
use crate::scene::mesh::Mesh;
use crate::skin::falloff::Falloff;

/// Far sides met at grazing angles count as if met at this cosine (the
/// estimator's 1/cos_q would let one ray dominate).
const MIN_COS_Q: f32 = 0.1;

/// Transfer of vertex `i` at `p`, unit normal `nrm` (module doc), unscaled.
#[allow(clippy::too_many_arguments)]
fn vertex(
    bvh: &Bvh,
    mesh: &Mesh,
    direct: &Transfer,
    falloff: &Falloff,
    p: Vec3,
    nrm: Vec3,
    opts: &RayOptions,
    i: u32,
) -> [[f32; 9]; 3] {
    let n = opts.samples.max(1);
    let offset = opts.offset_mm.max(0.0);
    let origin = p - nrm * offset;
    let mut out = [[0.0f64; 9]; 3];
    for w in directions(-nrm, n, opts.seed, i) {
        let Some(hit) = bvh.closest_hit(origin, w, falloff.reach_mm()) else {
            continue;
        };
        let Some(normal) = hit.interpolate(mesh, &mesh.normals).try_normalize() else {
            continue;
        };
        // Leaving the mesh there, on the far side.
        let cos_q = normal.dot(w);
        if cos_q <= 0.0 || normal.dot(nrm) >= 0.0 {
            continue;
        }
        // R at the distance from p; the area element from the ray's origin,
        // where the directions are drawn.
        let r = (origin + w * hit.t - p).length();
        let weight = falloff.radial(r) * hit.t * hit.t / (cos_q.max(MIN_COS_Q) * w.dot(-nrm));
        let (corners, b) = (hit.corners(mesh), hit.barycentric.to_array());
        for (c, row) in out.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                let tj: f32 = (0..3).map(|k| b[k] * direct.coeffs[corners[k]][j]).sum();
                *x += f64::from(weight[c] * tj);
            }
        }
    }
    let scale = std::f64::consts::PI / f64::from(n);
    out.map(|row| row.map(|x| (x * scale) as f32))
}

/// The transmitted transfer of `mesh` through `falloff` under its direct
/// transfer `direct`, scaled by `scale` (`skin.transmission`; 0: none), by
/// rays cast as `opts` says.
pub fn transmitted(
    mesh: &Mesh,
    direct: &Transfer,
    falloff: &Falloff,
    scale: f32,
    opts: &RayOptions,
) -> RgbTransfer {
    let count = mesh.vertex_count();
    if scale <= 0.0 || falloff.reach_mm() <= 0.0 {
        return RgbTransfer::none(count);
    }
    let start = std::time::Instant::now();
    let bvh = Bvh::from_mesh(mesh);
    let coeffs = (0..count)
        .into_par_iter()
        .map(|i| {
            let p = mesh.positions[i];
            match mesh.normals.get(i).and_then(|n| n.try_normalize()) {
                Some(n) if p.is_finite() => {
                    vertex(&bvh, mesh, direct, falloff, p, n, opts, i as u32)
                        .map(|row| row.map(|x| x * scale))
                }
                _ => [[0.0; 9]; 3],
            }
        })
        .collect();
    log::info!(
        "transmission: {count} vertices × {} rays within {:.1} mm: {:.2} s",
        opts.samples,
        falloff.reach_mm(),
        start.elapsed().as_secs_f64()
    );
    RgbTransfer { coeffs }
}

/// [`transmitted`] with the default rays under the direct transfer `direct` of
/// occlusion `mode` (none for `Off`), from the disk cache when it holds it
/// (keyed by the mesh, the direct transfer's key, the falloff, the scale and
/// the settings).
pub fn transmitted_for(
    mesh: &Mesh,
    direct: &Transfer,
    mode: Occlusion,
    falloff: &Falloff,
    scale: f32,
) -> RgbTransfer {
    let Some(direct_key) = transfer_key(mesh, mode).filter(|_| scale > 0.0) else {
        return RgbTransfer::none(mesh.vertex_count());
    };
    let opts = RayOptions {
        seed: 2,
        ..RayOptions::default()
    };
    let settings = format!(
        "{} direct={direct_key} scale={:08x} profile={}",
        opts.cache_settings(),
        scale.to_bits(),
        falloff.key()
    );
    let key = cache_key(mesh, "transmission", &settings);
    rgb_cached("transmission", &key, mesh.vertex_count(), || {
        transmitted(mesh, direct, falloff, scale, &opts)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::occlusion::testutil::mesh;
    use crate::light::occlusion::{raytrace, unoccluded};
    use crate::light::sh;
    use crate::skin::profile::Profile;

    /// A slab d mm thick, 2 m across: the front face (normal +Z) a fan around
    /// vertex 0 at the origin, the back face (normal −Z) at z = −d.
    fn slab(d: f32) -> Mesh {
        let h = 1000.0;
        let mut p = vec![Vec3::ZERO];
        let ring = [(-h, -h), (h, -h), (h, h), (-h, h)];
        p.extend(ring.iter().map(|&(x, y)| Vec3::new(x, y, 0.0)));
        p.extend(ring.iter().map(|&(x, y)| Vec3::new(x, y, -d)));
        let mut n = vec![Vec3::Z; 5];
        n.extend([Vec3::NEG_Z; 4]);
        let idx = vec![0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 1, 5, 7, 6, 5, 8, 7];
        mesh(p, n, idx)
    }

    /// E/(πL) at vertex 0 under a uniform sky of radiance L: X_0·L_0/(πL),
    /// L_0 = L·4π·Y00.
    fn transmitted_share(x: &RgbTransfer) -> Vec3 {
        Vec3::from_array(x.coeffs[0].map(|c| c[0])) * 4.0 * sh::K00
    }

    /// The issue's backlit slab: under a uniform sky of radiance L behind it
    /// the far side receives E = πL, and the near side's vertex gets
    /// E·Σ wᵢ exp(−d²/2vᵢ) per channel (Profile::transmittance, the profile
    /// integrated over the far side), within 2 % for d = 0.5–5 mm.
    #[test]
    fn a_backlit_slab_transmits_the_profile_s_transmittance() {
        let profile = Profile::skin();
        for d in [0.5_f32, 1.0, 2.0, 3.5, 5.0] {
            let m = slab(d);
            let x = transmitted(
                &m,
                &unoccluded(&m),
                &Falloff::Profile(&profile),
                1.0,
                &RayOptions::default(),
            );
            let (e, expected) = (transmitted_share(&x), profile.transmittance(d));
            eprintln!("d {d} mm: E/πL {e:.5}, T(d) {expected:.5}");
            for c in 0..3 {
                let (got, want) = (e[c], expected[c]);
                assert!(
                    (got - want).abs() <= 0.02 * want + 1e-5,
                    "d {d} mm, channel {c}: {got} against {want}"
                );
            }
        }
        // Scaled by skin.transmission; none at 0.
        let m = slab(1.0);
        let at = |scale| {
            transmitted(
                &m,
                &unoccluded(&m),
                &Falloff::Profile(&profile),
                scale,
                &RayOptions::default(),
            )
        };
        assert_eq!(at(0.5).coeffs[0][0][0] * 2.0, at(1.0).coeffs[0][0][0]);
        assert_eq!(at(0.0), RgbTransfer::none(9));
    }

    /// With a medium's slab table the far side's light integrates back to
    /// the table: T(d) where it falls, and its largest value beyond d where a
    /// thin slab's scattered light still rises (the envelope), within 2 %
    /// from 1 mm (thinner, [`MIN_COS_Q`] drops part of the light arriving
    /// from beyond 10 d: −16 % at 0.3 mm for this table).
    #[test]
    fn a_backlit_slab_transmits_a_medium_s_table() {
        let max_mm = 12.0;
        let n = 48;
        let d_of = |i: usize| max_mm * (i as f32 / (n - 1) as f32).powi(2);
        // Rises to a peak at 1 mm, then falls as e^(−d/1.5), per channel slower.
        let t = |d: f32| Vec3::new(0.3, 0.2, 0.1) * (d / (d + 0.1)) * (-(d / 1.5).max(0.6)).exp();
        let samples: Vec<Vec3> = (0..n).map(|i| t(d_of(i))).collect();
        let falloff = Falloff::slab(&samples, max_mm);
        let envelope = |d: f32| {
            (0..n)
                .filter(|&i| d_of(i) >= d)
                .fold(Vec3::ZERO, |a, i| a.max(samples[i]))
        };
        for d in [1.0_f32, 2.0, 3.5, 5.0] {
            let m = slab(d);
            let x = transmitted(&m, &unoccluded(&m), &falloff, 1.0, &RayOptions::default());
            let e = transmitted_share(&x);
            // The table read linearly in √d, as the kernel integrates it.
            let s = (d / max_mm).sqrt() * (n - 1) as f32;
            let (i, f) = (s as usize, s.fract());
            let want = envelope(d_of(i)).lerp(envelope(d_of(i + 1)), f);
            eprintln!("d {d} mm: E/πL {e:.5}, T {want:.5}");
            for c in 0..3 {
                assert!(
                    (e[c] - want[c]).abs() <= 0.02 * want[c] + 1e-5,
                    "d {d} mm, channel {c}: {} against {}",
                    e[c],
                    want[c]
                );
            }
        }
    }

    /// Nothing comes through a block thicker than the profile's reach, nor
    /// where the far side sees no sky (a second slab close behind it), nor
    /// from the near side's own surface (a convex sphere: its chords meet
    /// the surface where n_q·n_p > 0, which the texture-space blur covers).
    #[test]
    fn nothing_through_thick_covered_or_convex_skin() {
        let profile = Profile::skin();
        let opts = RayOptions::default();
        let m = slab(30.0);
        let x = transmitted(&m, &unoccluded(&m), &Falloff::Profile(&profile), 1.0, &opts);
        assert_eq!(transmitted_share(&x), Vec3::ZERO);
        // A second slab 5 mm behind the first one's far side, ten times as
        // wide (so that the far side's corners see no sky either), covers it.
        let mut m = slab(1.0);
        let open = transmitted_share(&transmitted(
            &m,
            &unoccluded(&m),
            &Falloff::Profile(&profile),
            1.0,
            &opts,
        ));
        let base = m.positions.len() as u32;
        for k in 5..9 {
            let p = m.positions[k];
            m.positions
                .push(Vec3::new(10.0 * p.x, 10.0 * p.y, p.z - 5.0));
            m.normals.push(Vec3::Z);
            m.uvs.push(glam::Vec2::ZERO);
            m.tangents.push(glam::Vec4::X);
        }
        m.indices
            .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
        let covered = transmitted_share(&transmitted(
            &m,
            &raytrace(&m, &opts, false),
            &Falloff::Profile(&profile),
            1.0,
            &opts,
        ));
        eprintln!("1 mm slab: open {open:.5}, covered {covered:.5}");
        assert!(covered.x < 0.02 * open.x, "{covered} against {open}");
        // A sphere of radius 20 mm seen from outside.
        let sphere = crate::light::occlusion::testutil::open_sphere(20.0, 0.0, 24, 48);
        let x = transmitted(
            &sphere,
            &unoccluded(&sphere),
            &Falloff::Profile(&profile),
            1.0,
            &opts,
        );
        assert!(x.coeffs.iter().flatten().flatten().all(|&c| c == 0.0));
    }
}
