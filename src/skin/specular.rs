//! Kelemen/Szirmay-Kalos (KS) specular for skin: Beckmann distribution,
//! Schlick Fresnel, the directional albedo ρ_dt used for energy conservation,
//! the look-up tables the GPU samples, and the per-region (ρ_s, m) table.
//!
//! Sources:
//! - Yang, Wang & Zuo 2012, eq. 1 (Beckmann distribution) and §II.A;
//! - d'Eon & Luebke, GPU Gems 3 ch. 14, §14.3, listings `PHBeckmann` / `KSTextureCompute`,
//!   `fresnelReflectance`, `KS_Skin_Specular` and `computeRhodtTex` (cited by
//!   name; listing numbers not verified here);
//! - Kelemen & Szirmay-Kalos 2001, "A Microfacet Based Coupled Specular-Matte
//!   BRDF Model with Importance Sampling".
//!
//! Conventions (see `docs/skin.md`): vectors are unit length and point away
//! from the surface; `m` is the Beckmann RMS slope; `rho_s` is the specular
//! intensity. [`beckmann`] is normalised (it carries the 1/π of eq. 1, which
//! d'Eon's `PHBeckmann` listing omits).

use glam::Vec3;
use std::f64::consts::PI;

/// Normal-incidence Fresnel reflectance of skin: ((n−1)/(n+1))² with n ≈ 1.4
/// gives 0.0278; GPU Gems 3 §14.3 uses 0.028.
pub const F0_SKIN: f32 = 0.028;

/// d'Eon's default roughness where no measured value is used (GPU Gems 3 §14.3).
pub const DEFAULT_M: f32 = 0.3;
/// d'Eon's default specular intensity (GPU Gems 3 §14.3).
pub const DEFAULT_RHO_S: f32 = 0.18;

/// Beckmann distribution of eq. 1: D = exp(−tan²α / m²) / (π m² cos⁴α),
/// α = acos(N·H). Normalised so that ∫ D (N·H) dω_h = 1 over the hemisphere.
/// Returns 0 for N·H ≤ 0 or m ≤ 0.
pub fn beckmann(n_dot_h: f32, m: f32) -> f32 {
    beckmann_f64(f64::from(n_dot_h), f64::from(m)) as f32
}

fn beckmann_f64(c: f64, m: f64) -> f64 {
    if c <= 0.0 || m <= 0.0 {
        return 0.0;
    }
    let c = c.min(1.0);
    let c2 = c * c;
    let m2 = m * m;
    let tan2 = (1.0 - c2) / c2;
    (-tan2 / m2).exp() / (PI * m2 * c2 * c2)
}

/// Schlick's Fresnel approximation as d'Eon's `fresnelReflectance`:
/// F = (1 − H·V)⁵ + F0 (1 − (1 − H·V)⁵).
pub fn fresnel_schlick(h_dot_v: f32, f0: f32) -> f32 {
    fresnel_f64(f64::from(h_dot_v), f64::from(f0)) as f32
}

fn fresnel_f64(h_dot_v: f64, f0: f64) -> f64 {
    let e = (1.0 - h_dot_v).clamp(0.0, 1.0).powi(5);
    e + f0 * (1.0 - e)
}

/// d'Eon's `KS_Skin_Specular` (GPU Gems 3 §14.3) with an analytic
/// Beckmann term instead of the texture:
/// h = L + V (unnormalised), H = h/|h|, f = D(N·H, m) · F(H·V, F0_SKIN) / (h·h),
/// result = (N·L) · ρ_s · max(f, 0), and 0 where N·L ≤ 0.
///
/// The result includes the cosine N·L: it is reflected radiance per unit
/// incident radiance from L, not the bare BRDF. The BRDF is result / (N·L).
///
/// Why h·h: the microfacet BRDF is D F G / (4 (N·L)(N·V)); KS 2001 approximate
/// G / ((N·L)(N·V)) by 1 / (L·H)², and |L + V|² = 2 + 2 L·V = 4 (L·H)², so
/// D F G / (4 (N·L)(N·V)) ≈ D F / (h·h), with no division by grazing cosines.
///
/// Like d'Eon's code, no test on N·V: callers shade only visible points.
pub fn ks_brdf(n: Vec3, l: Vec3, v: Vec3, m: f32, rho_s: f32) -> f32 {
    let n_dot_l = n.dot(l);
    if n_dot_l <= 0.0 {
        return 0.0;
    }
    let h = l + v;
    let hh = h.dot(h);
    if hh <= 0.0 {
        return 0.0;
    }
    let hn = h / hh.sqrt();
    let ph = beckmann(n.dot(hn), m);
    let f = fresnel_schlick(hn.dot(v), F0_SKIN);
    let fr_spec = (ph * f / hh).max(0.0);
    n_dot_l * rho_s * fr_spec
}

/// Quadrature size of [`specular_albedo`]: (ξ, φ) midpoints; see there.
const ALBEDO_N_XI: usize = 1024;
const ALBEDO_N_PHI: usize = 256;

/// Directional albedo of the KS specular with ρ_s = 1:
/// A(θ, m) = ∫ ks_brdf(N, L, V, m, 1) dω_L over the hemisphere, with V at angle
/// θ from N (by reciprocity, equally the albedo for light from θ). This is the
/// quantity d'Eon's `computeRhodtTex` tabulates (its texture holds the integral,
/// and the shader uses `1 − ρ_s · tex`).
///
/// Computed in half-vector space: with u = −ln(1 − ξ), tan θ_h = m √u, φ_h
/// uniform, H has density D(N·H)(N·H), dω_L = 4 (V·H) dω_h and h·h = 4 (V·H)²,
/// so A = E[F(V·H) (N·L) / ((V·H)(N·H))] over L = 2(V·H)H − V with N·L > 0.
/// A 1024 × 256 midpoint grid on ξ ∈ (0,1), φ ∈ (0,π) (the integrand is even
/// in φ) is within 4e-5 of a 4096 × 1024 grid (tested; the worst case is grazing
/// and rough, where the N·L > 0 cut-off puts a kink in the integrand).
pub fn specular_albedo(cos_theta: f32, m: f32) -> f32 {
    albedo_f64(
        f64::from(cos_theta),
        f64::from(m),
        ALBEDO_N_XI,
        ALBEDO_N_PHI,
    ) as f32
}

fn albedo_f64(cos_theta: f64, m: f64, n_xi: usize, n_phi: usize) -> f64 {
    let c = cos_theta.clamp(0.0, 1.0);
    let m = m.max(0.0);
    // V = (v_x, 0, v_z) in the xz-plane, N = +z.
    let (v_x, v_z) = ((1.0 - c * c).max(0.0).sqrt(), c);
    let f0 = f64::from(F0_SKIN);
    let cos_phi_table: Vec<f64> = (0..n_phi)
        .map(|j| ((j as f64 + 0.5) / n_phi as f64 * PI).cos())
        .collect();
    let mut sum = 0.0;
    for i in 0..n_xi {
        let xi = (i as f64 + 0.5) / n_xi as f64;
        let u = -(1.0 - xi).ln();
        let tan_h = m * u.sqrt();
        let cos_h = 1.0 / (1.0 + tan_h * tan_h).sqrt();
        let sin_h = tan_h * cos_h;
        for &cos_phi in &cos_phi_table {
            // H = (sin_h cos φ, sin_h sin φ, cos_h); L·N = 2(V·H)(H·N) − V·N.
            let v_dot_h = v_x * sin_h * cos_phi + v_z * cos_h;
            if v_dot_h <= 0.0 {
                continue;
            }
            let n_dot_l = 2.0 * v_dot_h * cos_h - v_z;
            if n_dot_l <= 0.0 {
                continue;
            }
            sum += fresnel_f64(v_dot_h, f0) * n_dot_l / (v_dot_h * cos_h);
        }
    }
    sum / (n_xi * n_phi) as f64
}

/// Texel `i` of an endpoint-inclusive table of `size` entries over [0, 1]:
/// i / (size − 1). The GPU samples it at uv = (x·(size − 1) + ½) / size, so x = 1
/// (N·H = 1, the peak of the Beckmann lobe) is a texel centre, not a clamp.
pub fn table_point(i: usize, size: usize) -> f32 {
    i as f32 / (size.max(2) - 1) as f32
}

/// The specular albedo A(cos θ, m) as a `size_cos` × `size_m` table (row-major,
/// endpoint-inclusive, see [`table_point`]), integrated on an `n_xi` × `n_phi`
/// grid: the renderer's start-up table (256 × 64 is within 1e-5 of the fine grid).
pub fn specular_albedo_lut(size_cos: usize, size_m: usize, n_xi: usize, n_phi: usize) -> Vec<f32> {
    let mut lut = Vec::with_capacity(size_cos * size_m);
    for j in 0..size_m {
        for i in 0..size_cos {
            let (c, m) = (table_point(i, size_cos), table_point(j, size_m));
            lut.push(albedo_f64(f64::from(c), f64::from(m), n_xi, n_phi) as f32);
        }
    }
    lut
}

/// ρ_dt(θ, m) = 1 − A(θ, m) with ρ_s = 1 (GPU Gems 3 §14.3, energy conservation): the fraction of
/// light from direction θ that the specular does not reflect. With a region's
/// ρ_s, the energy-conserving diffuse factor is 1 − ρ_s · A = 1 − ρ_s (1 − ρ_dt),
/// applied once with θ from N·L (irradiance) and once from N·V (final pass).
pub fn rho_dt(cos_theta: f32, m: f32) -> f32 {
    1.0 - specular_albedo(cos_theta, m)
}

/// Texel-centre coordinate of texel `i` of `size`: (i + 0.5) / size. The GPU
/// reproduces a table entry exactly by sampling at this coordinate.
pub fn texel_centre(i: usize, size: usize) -> f32 {
    (i as f32 + 0.5) / size as f32
}

/// ρ_dt table, `size_cos` wide and `size_m` high, row-major:
/// `lut[j * size_cos + i] = rho_dt(texel_centre(i, size_cos), texel_centre(j, size_m))`.
/// As a texture: x (u) = cos θ ∈ [0, 1], y (v) = m ∈ [0, 1]; sample at
/// uv = (cos θ, m) with linear filtering and CLAMP_TO_EDGE (see [`sample_lut`]).
/// Store as R32F or R16F (values lie in [0, 1]).
pub fn rho_dt_lut(size_cos: usize, size_m: usize) -> Vec<f32> {
    let mut lut = Vec::with_capacity(size_cos * size_m);
    for j in 0..size_m {
        for i in 0..size_cos {
            lut.push(rho_dt(texel_centre(i, size_cos), texel_centre(j, size_m)));
        }
    }
    lut
}

/// Beckmann table in the role of d'Eon's `PHBeckmann` texture, `size` × `size`,
/// row-major: `lut[j * size + i] = beckmann(texel_centre(i, size), texel_centre(j, size))`,
/// x (u) = N·H, y (v) = m. Stores D itself (normalised, eq. 1), not d'Eon's
/// 8-bit encoding 0.5 · PH^0.1; values reach 1/(π m²) ≈ 3.3e5 at size 512, so
/// use R32F (they overflow R16F). Linear filtering in N·H is coarse for small m,
/// where D is sharp; the analytic [`beckmann`] costs about as much as a fetch.
pub fn beckmann_lut(size: usize) -> Vec<f32> {
    let mut lut = Vec::with_capacity(size * size);
    for j in 0..size {
        for i in 0..size {
            lut.push(beckmann(texel_centre(i, size), texel_centre(j, size)));
        }
    }
    lut
}

/// Bilinear look-up in a row-major `width` × `height` table at (x, y) ∈ [0, 1]²,
/// as a GPU sampler does with linear filtering, CLAMP_TO_EDGE and
/// unnormalised = false: texel i's centre is at (i + 0.5) / width.
pub fn sample_lut(lut: &[f32], width: usize, height: usize, x: f32, y: f32) -> f32 {
    assert_eq!(lut.len(), width * height, "table size");
    let axis = |t: f32, n: usize| {
        let p = (t * n as f32 - 0.5).clamp(0.0, (n - 1) as f32);
        let i0 = (p.floor() as usize).min(n - 1);
        let i1 = (i0 + 1).min(n - 1);
        (i0, i1, p - i0 as f32)
    };
    let (x0, x1, fx) = axis(x, width);
    let (y0, y1, fy) = axis(y, height);
    let at = |i: usize, j: usize| lut[j * width + i];
    let top = at(x0, y0) * (1.0 - fx) + at(x1, y0) * fx;
    let bottom = at(x0, y1) * (1.0 - fx) + at(x1, y1) * fx;
    top * (1.0 - fy) + bottom * fy
}

/// Specular parameters of one face region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    pub name: &'static str,
    /// Specular intensity ρ_s.
    pub rho_s: f32,
    /// Beckmann roughness m.
    pub m: f32,
}

/// The ten face regions of Weyrich et al. 2006 as the paper (§II.A) and
/// GPU Gems 3 §14.3 use them, in the order of the region map's indices.
pub const REGION_NAMES: [&str; 10] = [
    "forehead",
    "nose",
    "left cheek",
    "right cheek",
    "chin",
    "eyelids/around eyes",
    "upper lip",
    "lower lip",
    "ears",
    "neck/other",
];

/// Every region at d'Eon's defaults m = 0.3, ρ_s = 0.18 (GPU Gems 3 §14.3).
/// Weyrich et al. 2006's measured per-region values are printed only in figures
/// (their paper; GPU Gems 3 §14.3 reproduces them as a figure) and no machine-readable copy was found,
/// so none are transcribed here; see `docs/skin.md`.
pub fn default_regions() -> [Region; 10] {
    REGION_NAMES.map(|name| Region {
        name,
        rho_s: DEFAULT_RHO_S,
        m: DEFAULT_M,
    })
}

/// Region-map texels between the 3×3 samples blended per texel (±8 texels).
pub const REGION_BLEND_TEXELS: i64 = 4;

/// (ρs, m) per texel of the region map (id = red byte, clamped to the last
/// region): the regions' parameters blended with tent weights 1-2-1 over a 3×3
/// grid of texels [`REGION_BLEND_TEXELS`] apart, so borders are soft, not hard
/// edges. Computed once per scene; the shaders read it with nearest filtering.
pub fn region_params_map(
    width: u32,
    height: u32,
    rgba8: &[u8],
    params: &[[f32; 2]],
) -> Vec<[f32; 2]> {
    let (w, h) = (width as i64, height as i64);
    let last = params.len() - 1;
    let id = |x: i64, y: i64| {
        let t = (y.clamp(0, h - 1) * w + x.clamp(0, w - 1)) as usize;
        (rgba8[4 * t] as usize).min(last)
    };
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let mut acc = [0.0f32; 2];
            for dy in -1..=1i64 {
                for dx in -1..=1i64 {
                    let weight = ((2 - dx.abs()) * (2 - dy.abs())) as f32 / 16.0;
                    let p = params[id(x + dx * REGION_BLEND_TEXELS, y + dy * REGION_BLEND_TEXELS)];
                    acc[0] += weight * p[0];
                    acc[1] += weight * p[1];
                }
            }
            acc
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic pseudo-random numbers in [0, 1) (64-bit LCG, top bits).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f32 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    #[test]
    fn beckmann_is_normalised() {
        // ∫ D(θ) cos θ sin θ dθ dφ over the hemisphere, midpoint rule in θ.
        for m in [0.1_f64, 0.3, 0.5, 0.8] {
            let n = 200_000;
            let dt = PI / 2.0 / n as f64;
            let mut s = 0.0;
            for k in 0..n {
                let t = (k as f64 + 0.5) * dt;
                s += beckmann_f64(t.cos(), m) * t.cos() * t.sin() * dt;
            }
            let total = 2.0 * PI * s;
            println!("∫ D (N·H) dω, m = {m}: {total:.6}");
            assert!((total - 1.0).abs() < 5e-3, "m {m}: {total}");
        }
    }

    #[test]
    fn beckmann_and_fresnel_by_hand() {
        // N·H = 1: D = 1/(π m²).
        let d = beckmann(1.0, 0.3);
        assert!((d - 1.0 / (std::f32::consts::PI * 0.09)).abs() < 1e-5);
        // α = 30°, m = 0.3: exp(−(1/3)/0.09) / (π 0.09 · 0.5625).
        let c = 3f64.sqrt() / 2.0;
        let want = (-(1.0 / 3.0) / 0.09f64).exp() / (PI * 0.09 * 0.5625);
        assert!((f64::from(beckmann(c as f32, 0.3)) - want).abs() < 1e-5 * want);
        assert_eq!(fresnel_schlick(1.0, F0_SKIN), F0_SKIN);
        assert_eq!(fresnel_schlick(0.0, F0_SKIN), 1.0);
        assert!((fresnel_schlick(0.5, 0.028) - (0.03125 + 0.028 * 0.96875)).abs() < 1e-7);
    }

    #[test]
    fn ks_values_by_hand() {
        let n = Vec3::Z;
        // L = V = N: h·h = 4, D = 1/(π m²), F = F0 → N·L ρ_s F0 / (4 π m²).
        let got = ks_brdf(n, n, n, 0.3, 1.0);
        let want = 0.028 / (4.0 * PI * 0.09);
        assert!(
            (f64::from(got) - want).abs() < 1e-6 * want,
            "{got} vs {want}"
        );
        // L at 60° in xz, V = N: h·h = 3, N·H = V·H = cos 30°, N·L = 0.5.
        let l = Vec3::new(3f32.sqrt() / 2.0, 0.0, 0.5);
        let c = 3f64.sqrt() / 2.0;
        let d = (-(1.0 / 3.0) / 0.09f64).exp() / (PI * 0.09 * c.powi(4));
        let e = (1.0 - c).powi(5);
        let f = e + 0.028 * (1.0 - e);
        let want = 0.5 * 0.18 * d * f / 3.0;
        let got = ks_brdf(n, l, n, 0.3, 0.18);
        assert!(
            (f64::from(got) - want).abs() < 1e-5 * want,
            "{got} vs {want}"
        );
        // Light below the horizon: 0.
        assert_eq!(ks_brdf(n, -l, n, 0.3, 0.18), 0.0);
    }

    #[test]
    fn ks_brdf_is_reciprocal() {
        let mut rng = Lcg(7);
        let n = Vec3::Z;
        let dir = |rng: &mut Lcg| {
            let z: f32 = 0.05 + 0.95 * rng.next();
            let phi = 2.0 * std::f32::consts::PI * rng.next();
            let s = (1.0 - z * z).sqrt();
            Vec3::new(s * phi.cos(), s * phi.sin(), z)
        };
        for _ in 0..1000 {
            let (l, v) = (dir(&mut rng), dir(&mut rng));
            let m = 0.1 + 0.9 * rng.next();
            let a = ks_brdf(n, l, v, m, 1.0) / n.dot(l);
            let b = ks_brdf(n, v, l, m, 1.0) / n.dot(v);
            assert!(
                (a - b).abs() <= 1e-4 * a.abs().max(b.abs()) + 1e-12,
                "{a} vs {b}"
            );
        }
    }

    #[test]
    fn albedo_quadrature_is_converged() {
        let mut worst = 0.0_f64;
        for &c in &[0.02, 0.1, 0.3, 0.6, 1.0] {
            for &m in &[0.02, 0.1, 0.3, 0.6, 1.0] {
                let a = albedo_f64(c, m, ALBEDO_N_XI, ALBEDO_N_PHI);
                let b = albedo_f64(c, m, 4 * ALBEDO_N_XI, 4 * ALBEDO_N_PHI);
                worst = worst.max((a - b).abs());
            }
        }
        println!("albedo: |default − 16× finer grid| ≤ {worst:.2e}");
        assert!(worst < 5e-5);
    }

    #[test]
    fn albedo_matches_direct_integration_over_light_directions() {
        // Independent check, as d'Eon's computeRhodtTex does it: integrate
        // ks_brdf(ρ_s = 1) · sin θ_L over (θ_L, φ_L) with a fine midpoint grid.
        let n = Vec3::Z;
        let mut worst = 0.0_f64;
        for &c in &[0.2_f32, 0.5, 1.0] {
            let v = Vec3::new((1.0 - c * c).sqrt(), 0.0, c);
            for &m in &[0.3_f32, 0.5, 0.8] {
                let (nt, np) = (2000, 1000);
                let mut s = 0.0_f64;
                for i in 0..nt {
                    let t = (i as f64 + 0.5) / nt as f64 * PI / 2.0;
                    for j in 0..np {
                        let p = (j as f64 + 0.5) / np as f64 * PI;
                        let l = Vec3::new(
                            (t.sin() * p.cos()) as f32,
                            (t.sin() * p.sin()) as f32,
                            t.cos() as f32,
                        );
                        s += f64::from(ks_brdf(n, l, v, m, 1.0)) * t.sin();
                    }
                }
                let direct = s * (PI / 2.0 / nt as f64) * (PI / np as f64) * 2.0;
                let a = f64::from(specular_albedo(c, m));
                worst = worst.max((a - direct).abs());
            }
        }
        println!("albedo vs direct integration over L: max |Δ| = {worst:.2e}");
        assert!(worst < 1e-4);
    }

    /// Max relative and absolute error of a bilinearly sampled ρ_dt table at
    /// `count` pseudo-random points of [c_min, 1] × [m_min, 1].
    fn lut_error(lut: &[f32], w: usize, c_min: f32, m_min: f32, count: usize) -> (f32, f32) {
        let mut rng = Lcg(42);
        let (mut rel, mut abs) = (0.0_f32, 0.0_f32);
        for _ in 0..count {
            let c = c_min + (1.0 - c_min) * rng.next();
            let m = m_min + (1.0 - m_min) * rng.next();
            let exact = rho_dt(c, m);
            let d = (sample_lut(lut, w, w, c, m) - exact).abs();
            rel = rel.max(d / exact);
            abs = abs.max(d);
        }
        (rel, abs)
    }

    #[test]
    fn rho_dt_lut_layout() {
        let (w, h) = (8, 4);
        let lut = rho_dt_lut(w, h);
        assert_eq!(lut.len(), w * h);
        let (i, j) = (5, 3);
        assert_eq!(
            lut[j * w + i],
            rho_dt(texel_centre(i, w), texel_centre(j, h))
        );
    }

    #[test]
    fn rho_dt_lut_interpolates_within_half_a_percent() {
        // Asserted where skin shades: N·L or N·V ≥ 0.1 and m ≥ 0.1 (32²), and
        // ≥ 0.05 for both with 64². Nearer grazing and m → 0, ρ_dt changes too
        // fast for a linear table; those numbers are reported only.
        let lut32 = rho_dt_lut(32, 32);
        let lut64 = rho_dt_lut(64, 64);
        for (w, c_min, m_min, assert) in [
            (32, 0.1, 0.1, true),
            (64, 0.05, 0.05, true),
            (32, 0.0, 0.0, false),
            (64, 0.0, 0.0, false),
            (32, 0.02, 0.1, false),
        ] {
            let lut = if w == 32 { &lut32 } else { &lut64 };
            let (rel, abs) = lut_error(lut, w, c_min, m_min, 100);
            println!(
                "ρdt {w}×{w} bilinear, cos ≥ {c_min}, m ≥ {m_min}: max rel {rel:.2e}, max |Δ| {abs:.2e}"
            );
            if assert {
                assert!(rel < 5e-3, "{w}²: {rel}");
            }
        }
    }

    #[test]
    fn white_furnace() {
        // Light from θ_l: specular reflects ρ_s A(θ_l); the rest enters, is
        // diffused (albedo 1, Lambertian) and leaves with the exit factor
        // 1 − ρ_s A(θ_v): its hemispherical total is 1 − ρ_s · 2∫ A(μ) μ dμ.
        let nm = 24;
        let nmu = 64;
        let mut max_total = [0.0_f64; 2];
        let mut max_albedo = 0.0_f64;
        for jm in 0..nm {
            let m = (jm as f32 + 0.5) / nm as f32;
            let a: Vec<f64> = (0..nmu)
                .map(|k| f64::from(specular_albedo((k as f32 + 0.5) / nmu as f32, m)))
                .collect();
            let exit_mean: f64 = a
                .iter()
                .enumerate()
                .map(|(k, ak)| 2.0 * ak * (k as f64 + 0.5) / nmu as f64 / nmu as f64)
                .sum();
            for (slot, rho_s) in [1.0_f64, f64::from(DEFAULT_RHO_S)].iter().enumerate() {
                for &ak in &a {
                    assert!((0.0..=1.0).contains(&ak), "A = {ak}");
                    max_albedo = max_albedo.max(ak);
                    let total = rho_s * ak + (1.0 - rho_s * ak) * (1.0 - rho_s * exit_mean);
                    max_total[slot] = max_total[slot].max(total);
                }
            }
        }
        println!(
            "furnace: max A = {max_albedo:.4}; max total reflectance ρs=1: {:.4}, ρs=0.18: {:.4}",
            max_total[0], max_total[1]
        );
        assert!(max_total[0] <= 1.0 && max_total[1] <= 1.0);
    }

    #[test]
    fn beckmann_lut_layout() {
        let lut = beckmann_lut(16);
        assert_eq!(lut.len(), 256);
        assert_eq!(
            lut[3 * 16 + 15],
            beckmann(texel_centre(15, 16), texel_centre(3, 16))
        );
        assert_eq!(
            sample_lut(&lut, 16, 16, texel_centre(4, 16), texel_centre(7, 16)),
            lut[7 * 16 + 4]
        );
    }

    #[test]
    fn region_parameters_blend_across_borders_only() {
        // Left half region 0, right half region 2; ids beyond the list clamp.
        let (w, h) = (32u32, 4u32);
        let rgba8: Vec<u8> = (0..w * h)
            .flat_map(|i| [if i % w < w / 2 { 0 } else { 200 }, 0, 0, 255])
            .collect();
        let params = [[0.1, 0.2], [0.5, 0.5], [0.3, 0.6]];
        let map = region_params_map(w, h, &rgba8, &params);
        let at = |x: u32| map[(w + x) as usize];
        let close =
            |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6;
        assert!(close(at(0), [0.1, 0.2]), "{:?}", at(0));
        assert!(close(at(w - 1), [0.3, 0.6]), "{:?}", at(w - 1));
        // One texel left of the border the right-hand samples (weight 4/16) reach.
        let border = at(w / 2 - 1);
        assert!(
            (border[0] - (0.75 * 0.1 + 0.25 * 0.3)).abs() < 1e-6,
            "{border:?}"
        );
        assert!(
            (border[1] - (0.75 * 0.2 + 0.25 * 0.6)).abs() < 1e-6,
            "{border:?}"
        );
        // Beyond ±4 texels of the border nothing blends.
        assert!(close(at(w / 2 - 5), [0.1, 0.2]), "{:?}", at(w / 2 - 5));
        assert!(close(at(w / 2 + 4), [0.3, 0.6]), "{:?}", at(w / 2 + 4));
    }

    #[test]
    fn default_regions_use_deon_defaults() {
        let r = default_regions();
        assert_eq!(r.len(), 10);
        assert_eq!(r[0].name, "forehead");
        assert!(r.iter().all(|x| x.m == 0.3 && x.rho_s == 0.18));
    }

    #[test]
    fn coarse_albedo_table_matches_the_fine_integration() {
        let lut = specular_albedo_lut(8, 8, 256, 64);
        let mut worst = 0.0f32;
        for j in 1..8 {
            for i in 1..8 {
                let fine = specular_albedo(table_point(i, 8), table_point(j, 8));
                worst = worst.max((lut[j * 8 + i] - fine).abs());
            }
        }
        println!("coarse albedo table: max |error| {worst:.2e}");
        assert!(worst < 1e-3, "{worst}");
    }
}
