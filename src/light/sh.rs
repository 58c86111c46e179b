//! Real spherical harmonics up to l = 2 (9 coefficients per colour channel),
//! as in Yang, Wang & Zuo 2012 eq. 7–9 and Ramamoorthi & Hanrahan, "An
//! Efficient Representation for Irradiance Environment Maps" (SIGGRAPH 2001).
//!
//! # Basis and frame
//! Coefficient order: `L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22`
//! (index `i = l(l+1) + m`). The basis is R&H 2001 eq. 3 in Cartesian form
//! (constants also in Sloan, "Stupid Spherical Harmonics (SH) Tricks", 2008):
//! ```text
//! Y00 = 0.282095
//! Y1-1 = 0.488603 y     Y10 = 0.488603 z     Y11 = 0.488603 x
//! Y2-2 = 1.092548 xy    Y2-1 = 1.092548 yz   Y21 = 1.092548 xz
//! Y20 = 0.315392 (3z² − 1)                   Y22 = 0.546274 (x² − y²)
//! ```
//! evaluated on the **world** axes x, y, z exactly as written, so the basis'
//! polar axis is world +Z, not the +Y "up" of the environment map. That is only
//! a choice of frame: irradiance `E(n)` is frame independent, and the GPU
//! shaders must use these same formulas on world-space normals.
//!
//! # Projection
//! [`project`] is the CPU reference: `L_i = Σ_texels L_texel · ∫_texel Y_i dω`,
//! each texel's radiance constant over its cell of the sphere and the basis
//! integrated over the cell exactly ([`texel_integrals`]: closed forms of the
//! polynomials' integrals over `θ0..θ1 × φ0..φ1`), not sampled at its centre.
//! So a constant map gives L00 alone to rounding at any size (a 2×1 map's
//! centre samples gave L20 = −3.96, L22 = 6.86), and a map of any resolution
//! is the piecewise-constant function it stores. Accumulated in f64 in a fixed
//! order: rows top to bottom, texels left to right, each texel adding its nine
//! RGB terms.
//!
//! # Irradiance
//! [`irradiance`] is R&H eq. 13, `E(n) = nᵀ M n`, with c1 = 0.429043,
//! c2 = 0.511664, c3 = 0.743125, c4 = 0.886227, c5 = 0.247708. It equals
//! `Σ Â_l L_lm Y_lm(n)` with `Â = (π, 2π/3, π/4)` (R&H eq. 8–9), i.e. the dot
//! product of `L` with [`cosine_transfer`]`(n)`.
//!
//! # Rotation
//! [`rotate`] gives the coefficients of the rotated function
//! `f'(d) = f(Rᵀd)` (the environment content moved by `R`, matching
//! `EnvMap::rotated` / `EnvMap::rotated_y`). Band 0 is invariant. Band 1 is a
//! vector: `(L11, L1-1, L10)` = const · (x, y, z) components, so it rotates by
//! `R` itself, i.e. in the stored order `(y, z, x)` by a permutation of `R`.
//! Band 2 is a traceless symmetric quadratic form `dᵀQd`; rotation is
//! `Q' = R Q Rᵀ`, which is exact. [`band2_matrix`] writes that map as the 5×5
//! matrix acting on `(L2-2, L2-1, L20, L21, L22)`.

use glam::{Mat3, Vec3};

use crate::scene::env::{texel_solid_angle_f64, EnvMap};

/// Nine RGB coefficients, order `L00, L1-1, L10, L11, L2-2, L2-1, L20, L21, L22`.
pub type Sh9 = [Vec3; 9];

/// Normalisation constants of the real SH basis (R&H 2001 eq. 3).
pub const K00: f32 = 0.282095;
pub const K1: f32 = 0.488603;
pub const K2: f32 = 1.092548;
pub const K20: f32 = 0.315392;
pub const K22: f32 = 0.546274;

/// R&H 2001 eq. 13 constants.
pub const C1: f32 = 0.429043;
pub const C2: f32 = 0.511664;
pub const C3: f32 = 0.743125;
pub const C4: f32 = 0.886227;
pub const C5: f32 = 0.247708;

/// Clamped-cosine convolution factors per band (R&H 2001 eq. 8–9): π, 2π/3, π/4.
pub const A_HAT: [f32; 3] = [
    std::f32::consts::PI,
    2.0 * std::f32::consts::PI / 3.0,
    std::f32::consts::PI / 4.0,
];

/// The nine basis functions at direction `d` (taken as given: pass unit vectors).
pub fn basis(d: Vec3) -> [f32; 9] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        K00,
        K1 * y,
        K1 * z,
        K1 * x,
        K2 * x * y,
        K2 * y * z,
        K20 * (3.0 * z * z - 1.0),
        K2 * x * z,
        K22 * (x * x - y * y),
    ]
}

/// A row's θ integrals (texel rows `θ0 = πy/H .. θ1 = π(y+1)/H`):
/// `∫ sinθ`, `∫ sin²θ`, `∫ sinθ cosθ`, `∫ sin³θ`, `∫ cos²θ sinθ`, `∫ sin²θ cosθ`.
fn row_integrals(y: u32, height: u32) -> [f64; 6] {
    let pi = std::f64::consts::PI;
    let (t0, t1) = (
        pi * f64::from(y) / f64::from(height),
        pi * f64::from(y + 1) / f64::from(height),
    );
    let (m, h) = (0.5 * (t0 + t1), 0.5 * (t1 - t0));
    let (s0, c0, s1, c1) = (t0.sin(), t0.cos(), t1.sin(), t1.cos());
    let a0 = 2.0 * m.sin() * h.sin(); // cos θ0 − cos θ1
    let a1 = h - (2.0 * m).cos() * (2.0 * h).sin() / 2.0;
    let ac = (2.0 * m).sin() * (2.0 * h).sin() / 2.0;
    let acc = a0 * (c0 * c0 + c0 * c1 + c1 * c1) / 3.0;
    let asc = 2.0 * m.cos() * h.sin() * (s1 * s1 + s1 * s0 + s0 * s0) / 3.0;
    [a0, a1, ac, a0 - acc, acc, asc]
}

/// A column's φ integrals (`φ = 2π(u − ½)`, `u = x/W .. (x+1)/W`):
/// `∫ 1`, `∫ sinφ`, `∫ cosφ`, `∫ sin²φ`, `∫ cos²φ`, `∫ sinφ cosφ`.
fn column_integrals(x: u32, width: u32) -> [f64; 6] {
    let tau = std::f64::consts::TAU;
    let (p0, p1) = (
        tau * (f64::from(x) / f64::from(width) - 0.5),
        tau * (f64::from(x + 1) / f64::from(width) - 0.5),
    );
    let (m, h) = (0.5 * (p0 + p1), 0.5 * (p1 - p0));
    let half = (2.0 * m).cos() * (2.0 * h).sin() / 2.0;
    [
        2.0 * h,
        2.0 * m.sin() * h.sin(),
        2.0 * m.cos() * h.sin(),
        h - half,
        h + half,
        (2.0 * m).sin() * (2.0 * h).sin() / 2.0,
    ]
}

/// The nine basis functions integrated over a texel's cell, `∫ Y_i dω`, from a
/// row's θ and a column's φ integrals. With `d = (sinθ sinφ, cosθ, −sinθ cosφ)`
/// and `dω = sinθ dθ dφ` every monomial of x, y, z up to degree 2 separates.
fn cell_integrals(r: &[f64; 6], c: &[f64; 6]) -> [f64; 9] {
    let [a0, a1, ac, a3, acc, asc] = *r;
    let [p0, ps, pc, pss, pcc, psc] = *c;
    let one = a0 * p0;
    let (x, y, z) = (a1 * ps, ac * p0, -a1 * pc);
    let (xy, yz, xz) = (asc * ps, -asc * pc, -a3 * psc);
    let (xx, yy, zz) = (a3 * pss, acc * p0, a3 * pcc);
    let k = |c: f32| f64::from(c);
    [
        k(K00) * one,
        k(K1) * y,
        k(K1) * z,
        k(K1) * x,
        k(K2) * xy,
        k(K2) * yz,
        k(K20) * (3.0 * zz - one),
        k(K2) * xz,
        k(K22) * (xx - yy),
    ]
}

/// `∫ Y_i dω` over texel `(x, y)` of a `width × height` lat-long map (module
/// doc); zeros outside the map.
pub fn texel_integrals(x: u32, y: u32, width: u32, height: u32) -> [f64; 9] {
    if x >= width || y >= height {
        return [0.0; 9];
    }
    cell_integrals(&row_integrals(y, height), &column_integrals(x, width))
}

/// Project an equirect environment onto the nine SH functions (module doc).
pub fn project(env: &EnvMap) -> Sh9 {
    let mut acc = [[0.0f64; 3]; 9];
    let columns: Vec<[f64; 6]> = (0..env.width)
        .map(|x| column_integrals(x, env.width))
        .collect();
    for y in 0..env.height {
        let row = row_integrals(y, env.height);
        for (x, column) in (0..env.width).zip(&columns) {
            let l = env.texel(x, y);
            let b = cell_integrals(&row, column);
            let (r, g, bl) = (f64::from(l.x), f64::from(l.y), f64::from(l.z));
            for (a, yi) in acc.iter_mut().zip(b) {
                a[0] += r * yi;
                a[1] += g * yi;
                a[2] += bl * yi;
            }
        }
    }
    acc.map(|a| Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32))
}

/// Irradiance at normal `n` (unit) from R&H 2001 eq. 13.
pub fn irradiance(l: &Sh9, n: Vec3) -> Vec3 {
    let (x, y, z) = (n.x, n.y, n.z);
    let [l00, l1m1, l10, l11, l2m2, l2m1, l20, l21, l22] = *l;
    l22 * (C1 * (x * x - y * y)) + l20 * (C3 * z * z) + l00 * C4 - l20 * C5
        + (l2m2 * (x * y) + l21 * (x * z) + l2m1 * (y * z)) * (2.0 * C1)
        + (l11 * x + l1m1 * y + l10 * z) * (2.0 * C2)
}

/// Unoccluded diffuse transfer vector `T_i = Â_l · Y_i(n)`:
/// `dot(L, T) = irradiance(L, n)`.
pub fn cosine_transfer(n: Vec3) -> [f32; 9] {
    let b = basis(n);
    let band = [0, 1, 1, 1, 2, 2, 2, 2, 2];
    std::array::from_fn(|i| A_HAT[band[i]] * b[i])
}

/// `Σ_i L_i · t_i` per channel (e.g. with a transfer vector).
pub fn dot(l: &Sh9, t: &[f32; 9]) -> Vec3 {
    l.iter()
        .zip(t)
        .fold(Vec3::ZERO, |acc, (li, ti)| acc + *li * *ti)
}

/// Band-1 rotation in the stored order `(L1-1, L10, L11)` = `(y, z, x)`:
/// the rows/columns of `R` permuted.
pub fn band1_matrix(r: Mat3) -> [[f32; 3]; 3] {
    // Component index in xyz for stored slot 0, 1, 2.
    const P: [usize; 3] = [1, 2, 0];
    std::array::from_fn(|i| std::array::from_fn(|j| r.col(P[j])[P[i]]))
}

/// Traceless symmetric matrix Q with `dᵀQd = Σ L2m Y2m(d)` on the unit sphere,
/// from band-2 coefficients `(L2-2, L2-1, L20, L21, L22)`.
fn band2_to_q(c: [f64; 5]) -> [[f64; 3]; 3] {
    let (k2, k20, k22) = (f64::from(K2), f64::from(K20), f64::from(K22));
    let [a, b, c20, d, e] = c;
    // Y20 = K20 (3z² − 1) = K20 (2z² − x² − y²) on the sphere.
    let xx = -k20 * c20 + k22 * e;
    let yy = -k20 * c20 - k22 * e;
    let zz = 2.0 * k20 * c20;
    let xy = 0.5 * k2 * a;
    let yz = 0.5 * k2 * b;
    let xz = 0.5 * k2 * d;
    [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]
}

/// Inverse of [`band2_to_q`] for a traceless symmetric Q.
fn q_to_band2(q: [[f64; 3]; 3]) -> [f64; 5] {
    let (k2, k20, k22) = (f64::from(K2), f64::from(K20), f64::from(K22));
    [
        2.0 * q[0][1] / k2,
        2.0 * q[1][2] / k2,
        q[2][2] / (2.0 * k20),
        2.0 * q[0][2] / k2,
        (q[0][0] - q[1][1]) / (2.0 * k22),
    ]
}

/// 5×5 band-2 rotation acting on `(L2-2, L2-1, L20, L21, L22)`: column j is the
/// image of unit vector e_j under `Q ↦ R Q Rᵀ`. Exact (no sampling).
pub fn band2_matrix(r: Mat3) -> [[f32; 5]; 5] {
    let rm: [[f64; 3]; 3] =
        std::array::from_fn(|i| std::array::from_fn(|j| f64::from(r.col(j)[i])));
    let mut m = [[0.0f32; 5]; 5];
    for j in 0..5 {
        let mut e = [0.0f64; 5];
        e[j] = 1.0;
        let q = band2_to_q(e);
        // R Q Rᵀ
        let rq: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|k| (0..3).map(|t| rm[i][t] * q[t][k]).sum())
        });
        let qr: [[f64; 3]; 3] = std::array::from_fn(|i| {
            std::array::from_fn(|k| (0..3).map(|t| rq[i][t] * rm[k][t]).sum())
        });
        let col = q_to_band2(qr);
        for i in 0..5 {
            m[i][j] = col[i] as f32;
        }
    }
    m
}

/// Coefficients of the environment rotated by `r` (content from `d` moves to
/// `r·d`), see the module doc. `r` should be a rotation (orthonormal, det +1).
pub fn rotate(l: &Sh9, r: Mat3) -> Sh9 {
    let m1 = band1_matrix(r);
    let m2 = band2_matrix(r);
    let mut out = [Vec3::ZERO; 9];
    out[0] = l[0];
    for i in 0..3 {
        out[1 + i] = (0..3).fold(Vec3::ZERO, |a, j| a + l[1 + j] * m1[i][j]);
    }
    for i in 0..5 {
        out[4 + i] = (0..5).fold(Vec3::ZERO, |a, j| a + l[4 + j] * m2[i][j]);
    }
    out
}

/// [`rotate`] about +Y by `degrees` (right-handed, counter-clockwise seen from
/// above), consistent with `EnvMap::rotated_y(degrees)`.
pub fn rotate_y(l: &Sh9, degrees: f32) -> Sh9 {
    rotate(l, Mat3::from_rotation_y(degrees.to_radians()))
}

/// Per-band energy `Σ_m L_lm²` per channel (rotation invariant).
pub fn band_energy(l: &Sh9) -> [Vec3; 3] {
    let e = |r: std::ops::Range<usize>| r.fold(Vec3::ZERO, |a, i| a + l[i] * l[i]);
    [e(0..1), e(1..4), e(4..9)]
}

/// Reference irradiance by direct summation, `Σ L(ω)·max(n·ω, 0)·dω` over all
/// texels (f64, same order as [`project`]).
pub fn brute_force_irradiance(env: &EnvMap, n: Vec3) -> Vec3 {
    brute_force_irradiance_many(env, &[n])
        .first()
        .copied()
        .unwrap_or(Vec3::ZERO)
}

/// [`brute_force_irradiance`] for many normals in one pass over the map.
pub fn brute_force_irradiance_many(env: &EnvMap, normals: &[Vec3]) -> Vec<Vec3> {
    let mut acc = vec![[0.0f64; 3]; normals.len()];
    let ns: Vec<[f32; 3]> = normals.iter().map(|n| n.to_array()).collect();
    for y in 0..env.height {
        let dw = texel_solid_angle_f64(y, env.width, env.height);
        for x in 0..env.width {
            let l = env.texel(x, y);
            let d = env.texel_direction(x, y);
            let (r, g, b) = (
                f64::from(l.x) * dw,
                f64::from(l.y) * dw,
                f64::from(l.z) * dw,
            );
            for (a, n) in acc.iter_mut().zip(&ns) {
                let c = n[0] * d.x + n[1] * d.y + n[2] * d.z;
                if c > 0.0 {
                    let c = f64::from(c);
                    a[0] += r * c;
                    a[1] += g * c;
                    a[2] += b * c;
                }
            }
        }
    }
    acc.iter()
        .map(|a| Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::env::{load, texel_solid_angle};
    use std::f64::consts::PI;
    use std::path::PathBuf;

    /// Well-spread unit vectors (Fibonacci sphere).
    fn fibonacci(n: usize) -> Vec<Vec3> {
        (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let a = i as f32 * 2.399_963_2; // golden angle
                Vec3::new(r * a.cos(), r * a.sin(), z)
            })
            .collect()
    }

    fn close(a: f32, b: f32, tol: f32) -> bool {
        (a - b).abs() <= tol
    }

    /// Exact real SH (l ≤ 2) from the closed forms with √ written out, as an
    /// independent reference for the rounded constants.
    fn exact_basis(d: Vec3) -> [f64; 9] {
        let (x, y, z) = (d.x as f64, d.y as f64, d.z as f64);
        let k00 = 0.5 * (1.0 / PI).sqrt();
        let k1 = (3.0 / (4.0 * PI)).sqrt();
        let k2 = 0.5 * (15.0 / PI).sqrt();
        let k20 = 0.25 * (5.0 / PI).sqrt();
        let k22 = 0.25 * (15.0 / PI).sqrt();
        [
            k00,
            k1 * y,
            k1 * z,
            k1 * x,
            k2 * x * y,
            k2 * y * z,
            k20 * (3.0 * z * z - 1.0),
            k2 * x * z,
            k22 * (x * x - y * y),
        ]
    }

    #[test]
    fn constants_match_closed_forms() {
        for d in fibonacci(20) {
            let (a, b) = (basis(d), exact_basis(d));
            for i in 0..9 {
                assert!((a[i] as f64 - b[i]).abs() < 2e-6, "{i}");
            }
        }
        assert!(close(C4, (PI as f32) * K00, 1e-6));
        assert!(close(2.0 * C2, A_HAT[1] * K1, 1e-5));
        assert!(close(2.0 * C1, A_HAT[2] * K2, 1e-5));
        assert!(close(C1, A_HAT[2] * K22, 1e-5));
        assert!(close(C3, 3.0 * A_HAT[2] * K20, 1e-5));
        assert!(close(C5, A_HAT[2] * K20, 1e-5));
    }

    #[test]
    fn constant_environment() {
        let c = Vec3::new(0.5, 1.0, 2.0);
        let l00 = c * (2.0 * PI.sqrt()) as f32;
        // Any size, down to one texel: L00 alone (the point samples of a 2×1
        // map gave L20 = −3.96, L22 = 6.86 for c = 1).
        for (w, h) in [(256, 128), (1, 1), (2, 1), (4, 2), (3, 5), (7, 3)] {
            let l = project(&EnvMap::uniform(c, w, h));
            assert!(
                ((l[0] - l00) / l00).abs().max_element() < 1e-6,
                "{w}×{h}: {:?}",
                l[0]
            );
            for (i, li) in l.iter().enumerate().skip(1) {
                assert!(
                    (*li / l00).abs().max_element() < 1e-6,
                    "{w}×{h}: L{i} = {li}"
                );
            }
            // Irradiance of a uniform environment is π·c for every normal.
            for n in fibonacci(50) {
                assert!(
                    ((irradiance(&l, n) - c * PI as f32) / c)
                        .abs()
                        .max_element()
                        < 2e-3,
                    "{w}×{h}"
                );
            }
        }
    }

    /// A map of two halves (upper sky 1, lower 0) at 2×2: its exact SH are
    /// those of the step function, which the cells reproduce exactly.
    #[test]
    fn a_tiny_two_tone_map_is_projected_exactly() {
        let mut env = EnvMap::uniform(Vec3::ZERO, 2, 2);
        env.texels[0] = Vec3::ONE;
        env.texels[1] = Vec3::ONE;
        let l = project(&env);
        // Upper hemisphere (y > 0): L00 = K00·2π, L1-1 (∝ y) = K1·π, others 0.
        let want = |i: usize| match i {
            0 => f64::from(K00) * 2.0 * PI,
            1 => f64::from(K1) * PI,
            _ => 0.0,
        };
        for (i, li) in l.iter().enumerate() {
            assert!((f64::from(li.x) - want(i)).abs() < 1e-6, "L{i} = {li}");
        }
    }

    /// Clamped cosine lobe max(d·a, 0).
    fn lobe(a: Vec3, w: u32, h: u32) -> EnvMap {
        EnvMap::from_fn(w, h, |d| Vec3::splat(d.dot(a).max(0.0)))
    }

    /// Analytic SH of max(d·a, 0) (Funk–Hecke): √π/2, √(π/3)·(a_y, a_z, a_x),
    /// then band 2 = (π/4)·Y2m(a) with exact constants (e.g. √(5π)/8 for L20
    /// when a = z).
    fn lobe_coeffs(a: Vec3) -> [f64; 9] {
        let y = exact_basis(a);
        let mut c = [0.0; 9];
        c[0] = PI.sqrt() / 2.0;
        let s = (PI / 3.0).sqrt();
        c[1] = s * a.y as f64;
        c[2] = s * a.z as f64;
        c[3] = s * a.x as f64;
        for i in 4..9 {
            c[i] = PI / 4.0 * y[i];
        }
        c
    }

    #[test]
    fn clamped_cosine_lobes() {
        let t = std::time::Instant::now();
        let a_list = [
            Vec3::X,
            Vec3::NEG_X,
            Vec3::Y,
            Vec3::NEG_Y,
            Vec3::Z,
            Vec3::NEG_Z,
            Vec3::new(0.3, -0.5, 0.8).normalize(),
        ];
        let mut worst = 0.0f64;
        for a in a_list {
            let l = project(&lobe(a, 1024, 512));
            let want = lobe_coeffs(a);
            for i in 0..9 {
                let err = (l[i].x as f64 - want[i]).abs() / want[0];
                worst = worst.max(err);
                assert!(err < 1e-3, "a={a} L{i}: {} vs {}", l[i].x, want[i]);
            }
        }
        // Spot-check the literal values for a = z.
        let want = lobe_coeffs(Vec3::Z);
        assert!((want[6] - (5.0 * PI).sqrt() / 8.0).abs() < 1e-6);
        println!(
            "cosine lobes at 1024x512: worst error {worst:.2e} relative to L00 ({:.0} ms for 7 projections)",
            t.elapsed().as_secs_f64() * 1e3
        );
    }

    /// One lit texel projects to its cell's integral of the basis, checked
    /// against a fine midpoint quadrature of the cell.
    #[test]
    fn single_texel_delta() {
        let (w, h) = (64, 32);
        for (x, y) in [(0, 0), (17, 9), (63, 31), (40, 16)] {
            let mut env = EnvMap::uniform(Vec3::ZERO, w, h);
            let rad = Vec3::new(3.0, 2.0, 0.5);
            env.texels[(y * w + x) as usize] = rad;
            let l = project(&env);
            let n = 64;
            let mut quad = [0.0f64; 9];
            for j in 0..n {
                let v = (y as f64 + (j as f64 + 0.5) / n as f64) / h as f64;
                let sin_t = (PI * v).sin();
                for i in 0..n {
                    let u = (x as f64 + (i as f64 + 0.5) / n as f64) / w as f64;
                    let d = crate::scene::env::direction(u as f32, v as f32);
                    let dw = sin_t * (PI / (h * n) as f64) * (2.0 * PI / (w * n) as f64);
                    for (q, b) in quad.iter_mut().zip(exact_basis(d)) {
                        *q += b * dw;
                    }
                }
            }
            let dw = f64::from(texel_solid_angle(y, w, h));
            for i in 0..9 {
                let want = rad * quad[i] as f32;
                let tol = 2e-4 * (rad * dw as f32).max_element();
                assert!(
                    (l[i] - want).abs().max_element() <= tol,
                    "texel ({x},{y}) L{i}: {} against {want}",
                    l[i]
                );
            }
            let cell = texel_integrals(x, y, w, h);
            assert!((cell[0] - f64::from(K00) * dw).abs() < 1e-6 * dw);
        }
    }

    #[test]
    fn transfer_dot_equals_irradiance() {
        let l: Sh9 = std::array::from_fn(|i| {
            Vec3::new(1.0 + i as f32, 0.5 - 0.1 * i as f32, (i as f32).sin())
        });
        for n in fibonacci(100) {
            let a = dot(&l, &cosine_transfer(n));
            let b = irradiance(&l, n);
            let scale = l.iter().map(|v| v.abs().max_element()).fold(0.0, f32::max);
            assert!((a - b).abs().max_element() <= 1e-5 * scale, "{a} {b}");
        }
    }

    fn assets() -> PathBuf {
        crate::assets::dir()
    }

    /// Maps whose light is spread out (sky, no visible sun disk). The brief's
    /// bound (mean per-normal relative error < 3 %) is asserted on these.
    /// The other four have a compact dominant source (sun: pedestrian_overpass,
    /// quarry, royal_esplanade; softboxes: studio) and measure 8.7–18.5 % mean,
    /// 34–105 % max per-normal relative error at 1024×512: order-2 SH cannot
    /// represent a near-point source (a pure point light gives 6.25 % of its
    /// peak irradiance of error even facing it). Reported to the lead rather
    /// than loosened; for them the rigorous worst-case bound below is asserted.
    const SMOOTH_MAPS: [&str; 2] = ["sunset.exr", "venice_sunset_1k.hdr"];

    /// Worst case over all non-negative lightings of the order-2 irradiance
    /// error, normalised by the mean irradiance over all normals: by the
    /// triangle inequality it is the point-light case, with
    /// E(c) = max(c, 0) (c = cos to the light, uniform in [−1, 1] over the
    /// sphere, mean E = 1/4) and E_SH(c) = 1/4 + c/2 + (5/16)(3c² − 1)/2.
    /// Returns (mean, max) of |E_SH − E| / (1/4).
    fn point_light_bound() -> (f64, f64) {
        let n = 200_000;
        let (mut sum, mut max) = (0.0f64, 0.0f64);
        for i in 0..n {
            let c = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
            let e_sh = 0.25 + 0.5 * c + 5.0 / 16.0 * (3.0 * c * c - 1.0) / 2.0;
            let err = (e_sh - c.max(0.0)).abs() / 0.25;
            sum += err;
            max = max.max(err);
        }
        (sum / n as f64, max)
    }

    #[test]
    fn rh_irradiance_vs_brute_force_on_real_maps() {
        let dir = assets();
        let normals = fibonacci(256);
        let (bound_mean, bound_max) = point_light_bound();
        println!(
            "point-light worst case (error / mean irradiance): mean {:.2}%, max {:.2}%",
            bound_mean * 100.0,
            bound_max * 100.0
        );
        let mut failures = Vec::new();
        for name in crate::assets::ENV_MAPS {
            let (env, _) = load(&dir.join("env").join(name)).unwrap();
            let t = std::time::Instant::now();
            let l = project(&env);
            let t_proj = t.elapsed().as_secs_f64() * 1e3;
            let t = std::time::Instant::now();
            let reference = brute_force_irradiance_many(&env, &normals);
            let t_bf = t.elapsed().as_secs_f64() * 1e3;
            let sh: Vec<Vec3> = normals.iter().map(|n| irradiance(&l, *n)).collect();
            // Brief's metric: per-normal relative error of the RGB vector.
            let rel: Vec<f64> = sh
                .iter()
                .zip(&reference)
                .map(|(e, r)| ((*e - *r).length() / r.length()) as f64)
                .collect();
            let mean = rel.iter().sum::<f64>() / rel.len() as f64;
            let max = rel.iter().fold(0.0f64, |a, b| a.max(*b));
            // R&H-style metric, per channel: |ΔE| / mean_n E.
            let (mut mean_n, mut max_n) = (0.0f64, 0.0f64);
            for c in 0..3 {
                let scale = reference.iter().map(|r| r[c] as f64).sum::<f64>() / rel.len() as f64;
                let errs: Vec<f64> = sh
                    .iter()
                    .zip(&reference)
                    .map(|(e, r)| (e[c] - r[c]).abs() as f64 / scale)
                    .collect();
                mean_n = mean_n.max(errs.iter().sum::<f64>() / errs.len() as f64);
                max_n = max_n.max(errs.iter().fold(0.0f64, |a, b| a.max(*b)));
            }
            println!(
                "{name}: per-normal relative error mean {:.2}% max {:.2}%; \
                 error / mean irradiance: mean {:.2}% max {:.2}% \
                 (projection {t_proj:.0} ms, brute force {t_bf:.0} ms)",
                mean * 100.0,
                max * 100.0,
                mean_n * 100.0,
                max_n * 100.0
            );
            if SMOOTH_MAPS.contains(&name) && mean >= 0.03 {
                failures.push(format!("{name}: mean {:.2}% >= 3%", mean * 100.0));
            }
            // Grid point-light bound is evaluated on a fine 1-D grid; allow
            // for the 256-normal sampling of the maps.
            if mean_n > bound_mean * 1.05 || max_n > bound_max * 1.05 {
                failures.push(format!("{name}: exceeds the point-light worst case"));
            }
        }
        assert!(failures.is_empty(), "{failures:?}");
    }

    /// Implementation check independent of truncation error: the irradiance of
    /// the order-2 *reconstruction* L̃(ω) = Σ L_i Y_i(ω), integrated by brute
    /// force, must equal R&H's closed form (Funk–Hecke).
    #[test]
    fn rh_irradiance_equals_irradiance_of_reconstruction() {
        let env = load(&assets().join("env/pedestrian_overpass_1k.hdr"))
            .unwrap()
            .0;
        let l = project(&env);
        let recon = EnvMap::from_fn(512, 256, |d| dot(&l, &basis(d)));
        let normals = fibonacci(64);
        let reference = brute_force_irradiance_many(&recon, &normals);
        let scale = l[0].max_element() * C4;
        let mut worst = 0.0f32;
        for (n, r) in normals.iter().zip(&reference) {
            worst = worst.max((irradiance(&l, *n) - *r).abs().max_element() / scale);
        }
        println!("R&H closed form vs brute force of the reconstruction: max {worst:.2e} of E00");
        assert!(worst < 1e-4, "{worst}");
    }

    fn rel_diff(a: &Sh9, b: &Sh9) -> f32 {
        let scale = a[0].abs().max_element().max(1e-20);
        a.iter()
            .zip(b)
            .map(|(x, y)| (*x - *y).abs().max_element())
            .fold(0.0, f32::max)
            / scale
    }

    #[test]
    fn rotate_y_matches_rotated_map() {
        let env = load(&assets().join("env/royal_esplanade_1k.hdr"))
            .unwrap()
            .0;
        let l = project(&env);
        for deg in [37.3f32, -101.7, 200.05] {
            let a = rotate_y(&l, deg);
            let b = project(&env.rotated_y(deg));
            let d = rel_diff(&a, &b);
            println!("rotate_y({deg}): max coefficient difference {d:.2e} of L00");
            assert!(d < 1e-4, "{deg}: {d}");
        }
    }

    fn lobe_sh(a: Vec3) -> Sh9 {
        lobe_coeffs(a).map(|c| Vec3::splat(c as f32))
    }

    #[test]
    fn general_rotation_against_analytic_lobes() {
        let r = Mat3::from_axis_angle(Vec3::new(0.2, -0.7, 0.4).normalize(), 1.234);
        for a in fibonacci(12) {
            let got = rotate(&lobe_sh(a), r);
            let want = lobe_sh(r * a);
            assert!(rel_diff(&got, &want) < 1e-5, "a = {a}");
        }
        // A projected (not analytic) lobe rotates onto the analytic rotated lobe.
        let a = Vec3::new(0.1, 0.9, -0.3).normalize();
        let got = rotate(&project(&lobe(a, 512, 256)), r);
        assert!(rel_diff(&got, &lobe_sh(r * a)) < 2e-3);
    }

    #[test]
    fn rotations_compose_and_preserve_energy() {
        let l: Sh9 =
            std::array::from_fn(|i| Vec3::new(0.3 * i as f32 - 1.0, (i as f32 * 1.7).cos(), 0.2));
        let r1 = Mat3::from_euler(glam::EulerRot::YXZ, 0.3, -1.1, 2.0);
        let r2 = Mat3::from_axis_angle(Vec3::new(1.0, 1.0, 0.0).normalize(), -0.77);
        let a = rotate(&rotate(&l, r1), r2);
        let b = rotate(&l, r2 * r1);
        assert!(rel_diff(&a, &b) < 1e-5);
        let back = rotate(&rotate(&l, r1), r1.transpose());
        assert!(rel_diff(&back, &l) < 1e-5);
        let e0 = band_energy(&l);
        let e1 = band_energy(&a);
        for band in 0..3 {
            assert!(
                ((e0[band] - e1[band]).abs() / e0[band].max(Vec3::splat(1e-6))).max_element()
                    < 1e-5
            );
        }
        // Band 1 is R permuted: rotating +Z by 90° about +Y gives +X.
        let m = band1_matrix(Mat3::from_rotation_y(std::f32::consts::FRAC_PI_2));
        // slot 1 (z) → slot 2 (x): column 1 should be e2.
        assert!(
            close(m[2][1], 1.0, 1e-6) && close(m[0][1], 0.0, 1e-6) && close(m[1][1], 0.0, 1e-6)
        );
        // Irradiance is frame independent: E_rot(R n) = E(n).
        for n in fibonacci(30) {
            let e = irradiance(&l, n);
            let er = irradiance(&rotate(&l, r1), r1 * n);
            assert!((e - er).abs().max_element() < 1e-4);
        }
    }

    #[test]
    fn brute_force_single() {
        // Uniform radiance 1 → π on any normal.
        let env = EnvMap::uniform(Vec3::ONE, 128, 64);
        let e = brute_force_irradiance(&env, Vec3::new(0.2, 0.9, -0.1).normalize());
        assert!(
            (e - Vec3::splat(PI as f32)).abs().max_element() < 2e-3,
            "{e}"
        );
    }
}
