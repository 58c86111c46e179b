//! Importance sampling of an equirect [`EnvMap`] by luminance × texel solid angle.
//!
//! The map is treated as piecewise constant: every direction inside texel
//! `(x, y)` carries that texel's radiance. Texel `(x, y)` is picked with
//! probability `w(x, y) / Σw`, `w = Y(texel)·Ω(y)` (Rec. 709 luminance `Y`, exact
//! texel solid angle `Ω`), by the 2D piecewise-constant distribution of PBRT
//! (Pharr, Jakob & Humphreys, *Physically Based Rendering*, 3rd ed. §13.6.7): a
//! marginal CDF over rows, then the chosen row's conditional CDF over columns.
//! Inside the texel the direction is uniform in solid angle (φ uniform, cos θ
//! uniform), so the density in solid angle is `p(ω) = Y(texel) / Σw`.
//!
//! A map with no light at all (`Σw = 0`) falls back to uniform sphere sampling.
//!
//! Directions are in the map's own frame (`scene::env::map`'s convention); the
//! integrator turns them into world directions.

use std::f32::consts::PI;

use glam::Vec3;

use crate::scene::env::{direction_to_uv, texel_solid_angle_f64, EnvMap};
use crate::scene::texture::LUMINANCE;

/// The sampling distribution of one environment map.
pub struct EnvSampler {
    env: EnvMap,
    /// `height + 1` entries: the CDF over rows, 0 … 1.
    marginal: Vec<f64>,
    /// `height` rows of `width + 1` entries: each row's CDF over columns, 0 … 1.
    conditional: Vec<f64>,
    /// `Σ Y·Ω` over the map; 0 for a black map (uniform sampling then).
    total: f64,
}

impl EnvSampler {
    /// The distribution of `env` (a sanitized map: no negative or non-finite texels).
    pub fn new(env: EnvMap) -> EnvSampler {
        let (w, h) = (env.width as usize, env.height as usize);
        let mut conditional = Vec::with_capacity(h * (w + 1));
        let mut row_weights = Vec::with_capacity(h);
        for y in 0..h {
            let omega = texel_solid_angle_f64(y as u32, env.width, env.height);
            let start = conditional.len();
            let mut sum = 0.0f64;
            conditional.push(0.0);
            for x in 0..w {
                sum += f64::from(luminance(env.texel(x as u32, y as u32)));
                conditional.push(sum);
            }
            normalize_cdf(&mut conditional[start..]);
            row_weights.push(sum * omega);
        }
        let mut marginal = Vec::with_capacity(h + 1);
        let mut total = 0.0f64;
        marginal.push(0.0);
        for rw in row_weights {
            total += rw;
            marginal.push(total);
        }
        normalize_cdf(&mut marginal);
        let total = if total.is_finite() && total > 0.0 {
            total
        } else {
            0.0
        };
        EnvSampler {
            env,
            marginal,
            conditional,
            total,
        }
    }

    /// Whether the map is black (nothing to sample).
    pub fn is_black(&self) -> bool {
        self.total == 0.0
    }

    /// A direction (map frame, unit) for the uniform numbers `u1, u2 ∈ [0, 1)`,
    /// its density in solid angle and the radiance it carries.
    pub fn sample(&self, u1: f32, u2: f32) -> (Vec3, f32, Vec3) {
        if self.total == 0.0 {
            let dir = uniform_sphere(u1, u2);
            return (dir, 1.0 / (4.0 * PI), self.radiance(dir));
        }
        let (w, h) = (self.env.width as usize, self.env.height as usize);
        let (y, fy) = pick(&self.marginal, f64::from(u1));
        let (x, fx) = pick(
            &self.conditional[y * (w + 1)..(y + 1) * (w + 1)],
            f64::from(u2),
        );
        // Uniform in solid angle inside the texel: cos θ uniform between the
        // row's edges, φ uniform across the column.
        let c0 = (std::f64::consts::PI * y as f64 / h as f64).cos();
        let c1 = (std::f64::consts::PI * (y + 1) as f64 / h as f64).cos();
        let cos_theta = (c0 + fy * (c1 - c0)) as f32;
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let phi = 2.0 * PI * ((x as f64 + fx) / w as f64 - 0.5) as f32;
        let (sp, cp) = phi.sin_cos();
        let dir = Vec3::new(sin_theta * sp, cos_theta, -sin_theta * cp);
        let texel = self.env.texel(x as u32, y as u32);
        (dir, self.texel_pdf(texel), texel)
    }

    /// Density in solid angle with which [`EnvSampler::sample`] returns `dir`
    /// (map frame, need not be unit length).
    pub fn pdf(&self, dir: Vec3) -> f32 {
        if self.total == 0.0 {
            return 1.0 / (4.0 * PI);
        }
        self.texel_pdf(self.radiance(dir))
    }

    /// The radiance arriving from `dir` (map frame): the texel that holds it.
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        let uv = direction_to_uv(dir);
        let (w, h) = (self.env.width, self.env.height);
        let x = ((uv.x * w as f32) as u32).min(w - 1);
        let y = ((uv.y * h as f32) as u32).min(h - 1);
        self.env.texel(x, y)
    }

    /// `Y / Σw`: the density of every direction in a texel of this radiance.
    fn texel_pdf(&self, texel: Vec3) -> f32 {
        (f64::from(luminance(texel)) / self.total) as f32
    }
}

/// Rec. 709 luminance (negative values count as 0).
pub fn luminance(rgb: Vec3) -> f32 {
    rgb.dot(LUMINANCE).max(0.0)
}

/// Divides a running sum (first entry 0) by its last entry; an all-zero one
/// becomes uniform steps.
fn normalize_cdf(cdf: &mut [f64]) {
    let n = cdf.len() - 1;
    let sum = cdf[n];
    for (i, c) in cdf.iter_mut().enumerate() {
        *c = if sum > 0.0 && sum.is_finite() {
            *c / sum
        } else {
            i as f64 / n as f64
        };
    }
    cdf[n] = 1.0;
}

/// The bin `i` of a CDF (`cdf[i] ≤ u < cdf[i + 1]`, never an empty bin) and
/// where `u` lies inside it, in `[0, 1)`.
fn pick(cdf: &[f64], u: f64) -> (usize, f64) {
    let n = cdf.len() - 1;
    let u = u.clamp(0.0, 1.0 - f64::EPSILON);
    let i = (cdf.partition_point(|&c| c <= u) - 1).min(n - 1);
    let width = cdf[i + 1] - cdf[i];
    let f = if width > 0.0 {
        (u - cdf[i]) / width
    } else {
        0.5
    };
    (i, f.clamp(0.0, 1.0 - f64::EPSILON))
}

/// Uniform direction on the unit sphere.
fn uniform_sphere(u1: f32, u2: f32) -> Vec3 {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u2).sin_cos();
    Vec3::new(r * c, r * s, z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::reference::sequence::Rng;
    use crate::scene::env::direction;

    /// A 32 × 16 map of radiance spread over `decades`; with `black`, a black
    /// row and black columns (zero-probability texels).
    fn test_map(decades: f32, black: bool) -> EnvMap {
        let mut rng = Rng::new(3);
        let mut env = EnvMap::uniform(Vec3::ZERO, 32, 16);
        for y in 0..16 {
            for x in 0..32 {
                if black && (y == 5 || x % 7 == 3) {
                    continue;
                }
                let c = Vec3::new(rng.next(), rng.next(), rng.next());
                env.texels[y * 32 + x] = c * 10f32.powf(decades * (rng.next() - 0.5));
            }
        }
        env
    }

    #[test]
    fn pdf_integrates_to_one() {
        // Midpoint rule on a 7 × 5 refinement of the texel grid (exact cell
        // solid angles): exact for a density that is constant per texel.
        let integrate = |s: &EnvSampler| {
            let (w, h) = (32 * 7, 16 * 5);
            let mut sum = 0.0f64;
            for y in 0..h {
                for x in 0..w {
                    let d = direction((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
                    sum += f64::from(s.pdf(d)) * texel_solid_angle_f64(y, w, h);
                }
            }
            sum
        };
        let env = test_map(4.0, true);
        let s = EnvSampler::new(env.clone());
        let i = integrate(&s);
        let black = EnvMap::uniform(Vec3::ZERO, 32, 16);
        let b = integrate(&EnvSampler::new(black.clone()));
        println!(
            "∫ pdf dω − 1 = {:.1e} (luminance map), {:.1e} (black map)",
            i - 1.0,
            b - 1.0
        );
        assert!((i - 1.0).abs() < 1e-5 && (b - 1.0).abs() < 1e-5, "{i} {b}");
    }

    #[test]
    fn histogram_follows_luminance_times_solid_angle() {
        let env = test_map(4.0, true);
        let s = EnvSampler::new(env.clone());
        let weight = |x: u32, y: u32| {
            f64::from(luminance(env.texel(x, y))) * texel_solid_angle_f64(y, 32, 16)
        };
        let total: f64 = (0..16)
            .flat_map(|y| (0..32).map(move |x| (x, y)))
            .map(|(x, y)| weight(x, y))
            .sum();
        let n = 1 << 21;
        let mut counts = vec![0u32; 32 * 16];
        let mut rng = Rng::new(11);
        let mut on_edge = 0;
        for _ in 0..n {
            let (d, pdf, radiance) = s.sample(rng.next(), rng.next());
            assert!((d.length() - 1.0).abs() < 1e-5);
            // The density and radiance reported are those of the texel that
            // holds the direction, but for directions rounded onto a texel edge.
            if radiance != s.radiance(d) {
                on_edge += 1;
                continue;
            }
            assert_eq!(pdf, s.pdf(d));
            let uv = direction_to_uv(d);
            let (x, y) = (
                (uv.x * 32.0) as usize % 32,
                ((uv.y * 16.0) as usize).min(15),
            );
            counts[y * 32 + x] += 1;
        }
        // Each count against its binomial expectation, in standard deviations.
        let mut worst = 0.0f64;
        for y in 0..16 {
            for x in 0..32 {
                let p = weight(x, y) / total;
                let c = f64::from(counts[(y * 32 + x) as usize]);
                if p == 0.0 {
                    assert_eq!(c, 0.0, "texel ({x}, {y}) has no light but was sampled");
                    continue;
                }
                let sd = (n as f64 * p * (1.0 - p)).sqrt();
                worst = worst.max((c - n as f64 * p).abs() / sd);
            }
        }
        println!(
            "histogram vs Y·Ω: worst texel {worst:.2} standard deviations; \
             {on_edge} of {n} samples on a texel edge"
        );
        assert!(worst < 5.0, "{worst}");
        assert!(on_edge < 20, "{on_edge}");
    }

    #[test]
    fn samples_are_uniform_inside_texels() {
        // E[f/p] = ∫ f for an f that varies inside texels (on a map with no black
        // texel, so p > 0 everywhere, and a narrow range, so f/p varies little):
        // ∫ max(0, y)·x² dω = ∫_0^{π/2} cos θ sin³θ dθ · ∫ sin²φ dφ = π/4.
        let env = test_map(0.5, false);
        let s = EnvSampler::new(env.clone());
        let mut rng = Rng::new(5);
        let n = 1 << 20;
        let (mut sum, mut sum_sq) = (0.0f64, 0.0f64);
        for _ in 0..n {
            let (d, pdf, _) = s.sample(rng.next(), rng.next());
            let y = f64::from(d.y.max(0.0) * d.x * d.x / pdf);
            sum += y;
            sum_sq += y * y;
        }
        let mean = sum / n as f64;
        let std_err = ((sum_sq / n as f64 - mean * mean) / n as f64).sqrt();
        let exact = std::f64::consts::PI / 4.0;
        println!("E[f/p] = {mean:.5} ± {std_err:.5}, exact π/4 = {exact:.5}");
        assert!(
            (mean - exact).abs() < 4.0 * std_err && std_err < 2e-3 * exact,
            "{mean}"
        );
    }

    #[test]
    fn black_map_samples_the_sphere_uniformly() {
        let env = EnvMap::uniform(Vec3::ZERO, 16, 8);
        let s = EnvSampler::new(env.clone());
        let mut rng = Rng::new(2);
        let n = 100_000;
        let (mut mean, mut y2) = (Vec3::ZERO, 0.0);
        for _ in 0..n {
            let (d, pdf, radiance) = s.sample(rng.next(), rng.next());
            assert_eq!((pdf, radiance), (1.0 / (4.0 * PI), Vec3::ZERO));
            mean += d / n as f32;
            y2 += d.y * d.y / n as f32;
        }
        assert!(mean.length() < 0.01, "{mean}");
        assert!((y2 - 1.0 / 3.0).abs() < 0.01, "{y2}");
    }
}
