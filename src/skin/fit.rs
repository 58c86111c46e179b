//! A medium's radial reflectance fitted by the blur chain's sum of Gaussians:
//! K variances shared by the three channels (the chain blurs each level once
//! for all channels), per-channel non-negative weights, minimising d'Eon &
//! Luebke's r-weighted L2 error ∫ r (R(r) − Σ wᵢ G(vᵢ, r))² dr (GPU Gems 3
//! §14.4.2) of each channel's multiply scattered profile, normalised to unit
//! integral. The single-scattering peak (skin::walk::Radial::single) is
//! singular at r = 0 — the criterion diverges on it — and far narrower than a
//! texel: its light joins the narrowest Gaussian. Weights by non-negative least
//! squares for given variances, variances by Nelder–Mead on their logarithms.

use crate::skin::profile::{Gaussian, Profile};
use crate::skin::walk::Radial;
use glam::Vec3;
use std::f64::consts::PI;

/// Narrowest and widest variance the fit may choose, mm²: d'Eon's narrowest
/// 0.0064 mm² over 2.5, and σ = 10 mm (the widest blur the chain's coarsest
/// levels hold on a face).
pub const VARIANCE_RANGE: (f64, f64) = (0.0025, 100.0);

/// The fitted profile and how well it fits.
#[derive(Clone, Debug)]
pub struct Fit {
    /// Weights summing to 1 per channel.
    pub profile: Profile,
    /// Per channel √(∫r(R − R̂)²dr / ∫r R² dr) of the normalised profiles.
    pub error: Vec3,
}

/// One channel's target: bins (r0, r1) and the normalised R over each.
struct Target {
    bins: Vec<(f64, f64)>,
    values: Vec<f64>,
    /// Each bin's weight in the error: its mid radius times its width.
    weights: Vec<f64>,
    norm: f64,
    /// The single-scattering share of the light leaving.
    single: f64,
}

impl Target {
    fn new(r: &Radial) -> Target {
        let held = (r.albedo - r.single) * (1.0 - r.beyond);
        let scale = if held > 0.0 { 1.0 / held } else { 0.0 };
        let bins: Vec<(f64, f64)> = r.edges.windows(2).map(|e| (e[0], e[1])).collect();
        let values: Vec<f64> = r.density.iter().map(|d| d * scale).collect();
        let weights: Vec<f64> = bins.iter().map(|(a, b)| 0.5 * (a + b) * (b - a)).collect();
        let norm = values
            .iter()
            .zip(&weights)
            .map(|(v, w)| w * v * v)
            .sum::<f64>()
            .max(1e-300);
        Target {
            bins,
            values,
            weights,
            norm,
            single: if r.albedo > 0.0 {
                r.single / r.albedo
            } else {
                0.0
            },
        }
    }

    /// Gaussian k's mean over each bin: (e^(−r0²/2v) − e^(−r1²/2v)) / (π(r1² − r0²)).
    fn design(&self, variances: &[f64]) -> Vec<Vec<f64>> {
        variances
            .iter()
            .map(|&v| {
                self.bins
                    .iter()
                    .map(|&(a, b)| {
                        ((-a * a / (2.0 * v)).exp() - (-b * b / (2.0 * v)).exp())
                            / (PI * (b * b - a * a))
                    })
                    .collect()
            })
            .collect()
    }

    /// Non-negative weights minimising the weighted error, and that error
    /// relative to the target's norm.
    fn solve(&self, variances: &[f64]) -> (Vec<f64>, f64) {
        let a = self.design(variances);
        let k = variances.len();
        // Normal equations of the weighted problem.
        let mut ata = vec![vec![0.0; k]; k];
        let mut atb = vec![0.0; k];
        for i in 0..k {
            for j in 0..k {
                ata[i][j] = (0..self.bins.len())
                    .map(|n| self.weights[n] * a[i][n] * a[j][n])
                    .sum();
            }
            atb[i] = (0..self.bins.len())
                .map(|n| self.weights[n] * a[i][n] * self.values[n])
                .sum();
        }
        let weights = nnls(&ata, &atb);
        let err: f64 = (0..self.bins.len())
            .map(|n| {
                let model: f64 = (0..k).map(|i| weights[i] * a[i][n]).sum();
                self.weights[n] * (model - self.values[n]).powi(2)
            })
            .sum();
        (weights, (err / self.norm).sqrt())
    }
}

/// min ‖Ax − b‖² over x ≥ 0 from the normal equations (AᵀA, Aᵀb): Lawson &
/// Hanson 1974's active-set method (Solving Least Squares Problems, ch. 23).
fn nnls(ata: &[Vec<f64>], atb: &[f64]) -> Vec<f64> {
    let k = atb.len();
    let scale = atb.iter().fold(0.0f64, |s, v| s.max(v.abs())).max(1e-300);
    let tolerance = 1e-12 * scale;
    let mut x = vec![0.0; k];
    let mut passive = vec![false; k];
    let gradient = |x: &[f64]| -> Vec<f64> {
        (0..k)
            .map(|i| atb[i] - (0..k).map(|j| ata[i][j] * x[j]).sum::<f64>())
            .collect()
    };
    // Each outer step frees one variable; a guard against cycling.
    for _ in 0..3 * k {
        let w = gradient(&x);
        let Some(j) = (0..k)
            .filter(|&i| !passive[i] && w[i] > tolerance)
            .max_by(|&a, &b| w[a].total_cmp(&w[b]))
        else {
            break;
        };
        passive[j] = true;
        loop {
            let idx: Vec<usize> = (0..k).filter(|&i| passive[i]).collect();
            let m = idx
                .iter()
                .map(|&i| idx.iter().map(|&j| ata[i][j]).collect())
                .collect();
            let rhs = idx.iter().map(|&i| atb[i]).collect();
            let Some(z) = solve_linear(m, rhs) else {
                // A singular set: drop the variable just freed.
                passive[j] = false;
                break;
            };
            if z.iter().all(|&v| v > 0.0) {
                x = vec![0.0; k];
                idx.iter().zip(&z).for_each(|(&i, &v)| x[i] = v);
                break;
            }
            // Step from x toward z until a variable reaches 0; it leaves the set.
            let alpha = idx
                .iter()
                .zip(&z)
                .filter(|(_, &v)| v <= 0.0)
                .map(|(&i, &v)| x[i] / (x[i] - v))
                .fold(f64::INFINITY, f64::min);
            for (&i, &v) in idx.iter().zip(&z) {
                x[i] += alpha * (v - x[i]);
                if x[i] <= 1e-15 * scale.max(1.0) {
                    x[i] = 0.0;
                    passive[i] = false;
                }
            }
        }
    }
    x
}

/// Gaussian elimination with partial pivoting; `None` when singular.
fn solve_linear(mut m: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    let scale = m
        .iter()
        .flatten()
        .fold(0.0f64, |s, v| s.max(v.abs()))
        .max(1e-300);
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))?;
        if m[p][c].abs() < 1e-13 * scale {
            return None;
        }
        m.swap(c, p);
        b.swap(c, p);
        let (pivot_rows, rest) = m.split_at_mut(c + 1);
        let pivot = &pivot_rows[c];
        for (k, row) in rest.iter_mut().enumerate() {
            let f = row[c] / pivot[c];
            row.iter_mut()
                .zip(pivot)
                .skip(c)
                .for_each(|(x, p)| *x -= f * p);
            b[c + 1 + k] -= f * b[c];
        }
    }
    let mut x = vec![0.0; n];
    for c in (0..n).rev() {
        let s: f64 = (c + 1..n).map(|j| m[c][j] * x[j]).sum();
        x[c] = (b[c] - s) / m[c][c];
    }
    Some(x)
}

/// Sorted variances from free parameters (logarithms), clamped to the range.
fn variances(p: &[f64]) -> Vec<f64> {
    let (lo, hi) = (VARIANCE_RANGE.0.ln(), VARIANCE_RANGE.1.ln());
    let mut v: Vec<f64> = p.iter().map(|x| x.clamp(lo, hi).exp()).collect();
    v.sort_by(f64::total_cmp);
    // The chain needs strictly increasing variances.
    for i in 1..v.len() {
        if v[i] <= v[i - 1] * 1.01 {
            v[i] = v[i - 1] * 1.01;
        }
    }
    v
}

/// Nelder–Mead (Lagarias et al. 1998's standard coefficients) from `start`.
fn nelder_mead(f: &dyn Fn(&[f64]) -> f64, start: &[f64], step: f64, iterations: usize) -> Vec<f64> {
    let n = start.len();
    let mut simplex: Vec<(Vec<f64>, f64)> = (0..=n)
        .map(|i| {
            let mut x = start.to_vec();
            if i > 0 {
                x[i - 1] += step;
            }
            let y = f(&x);
            (x, y)
        })
        .collect();
    for _ in 0..iterations {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let centroid: Vec<f64> = (0..n)
            .map(|j| simplex[..n].iter().map(|s| s.0[j]).sum::<f64>() / n as f64)
            .collect();
        let along = |t: f64| -> Vec<f64> {
            (0..n)
                .map(|j| centroid[j] + t * (simplex[n].0[j] - centroid[j]))
                .collect()
        };
        let reflected = along(-1.0);
        let fr = f(&reflected);
        if fr < simplex[0].1 {
            let expanded = along(-2.0);
            let fe = f(&expanded);
            simplex[n] = if fe < fr {
                (expanded, fe)
            } else {
                (reflected, fr)
            };
        } else if fr < simplex[n - 1].1 {
            simplex[n] = (reflected, fr);
        } else {
            let t = if fr < simplex[n].1 { -0.5 } else { 0.5 };
            let contracted = along(t);
            let fc = f(&contracted);
            if fc < fr.min(simplex[n].1) {
                simplex[n] = (contracted, fc);
            } else {
                let best = simplex[0].0.clone();
                for s in simplex.iter_mut().skip(1) {
                    s.0 = (0..n).map(|j| best[j] + 0.5 * (s.0[j] - best[j])).collect();
                    s.1 = f(&s.0);
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    simplex.swap_remove(0).0
}

/// Fits `k` Gaussians to the three channels' R(r).
pub fn fit_profile(radial: &[Radial; 3], k: usize) -> Fit {
    let targets = radial.each_ref().map(Target::new);
    let cost = |p: &[f64]| -> f64 {
        let v = variances(p);
        targets.iter().map(|t| t.solve(&v).1.powi(2)).sum()
    };
    // Start log-spaced over the channels' reach: from a tenth of the
    // narrowest channel's first bins to its widest's diffusion length.
    let reach = |t: &Target| t.bins.last().map_or(1.0, |b| b.1) / 10.0;
    let widest = targets.iter().map(reach).fold(0.0f64, f64::max);
    let (lo, hi) = ((0.05f64).ln(), (widest * widest).ln());
    let start: Vec<f64> = (0..k)
        .map(|i| lo + (hi - lo) * i as f64 / (k.max(2) - 1) as f64)
        .collect();
    let mut p = start;
    // Restarts shake Nelder–Mead out of a collapsed simplex.
    for _ in 0..4 {
        p = nelder_mead(&cost, &p, 0.5, 400);
    }
    fit_with(&targets, &variances(&p))
}

/// The reference's dense profile: [`REFERENCE_GAUSSIANS`] variances spaced by
/// a factor of two over [`VARIANCE_RANGE`], weights by least squares — a
/// representation of R(r) far closer than the chain's six (the exact-diffusion
/// reference integrates sums of Gaussians).
pub fn fit_reference(radial: &[Radial; 3]) -> Fit {
    let targets = radial.each_ref().map(Target::new);
    let (lo, hi) = VARIANCE_RANGE;
    let n = REFERENCE_GAUSSIANS;
    let v: Vec<f64> = (0..n)
        .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
        .collect();
    let mut fit = fit_with(&targets, &v);
    // Gaussians no channel uses cost the reference their reach for nothing.
    fit.profile
        .gaussians
        .retain(|g| g.weights.max_element() > 0.0);
    fit
}

/// Gaussians of [`fit_reference`]: a factor √(100/0.0025)^(2/15) ≈ 2.1 in
/// variance between neighbours.
pub const REFERENCE_GAUSSIANS: usize = 16;

/// Weights for variances `v`, normalised to 1 per channel: the multiply
/// scattered light's by its share, the single-scattering share added to the
/// narrowest Gaussian.
fn fit_with(targets: &[Target; 3], v: &[f64]) -> Fit {
    let solved = targets.each_ref().map(|t| t.solve(v));
    let sums = solved
        .each_ref()
        .map(|(w, _)| w.iter().sum::<f64>().max(1e-300));
    let weight = |c: usize, i: usize| {
        let single = targets[c].single;
        let w = (1.0 - single) * solved[c].0[i] / sums[c];
        (if i == 0 { w + single } else { w }) as f32
    };
    let gaussians = v
        .iter()
        .enumerate()
        .map(|(i, &variance)| Gaussian {
            variance_mm2: variance as f32,
            weights: Vec3::from_array([0, 1, 2].map(|c| weight(c, i))),
        })
        .collect();
    let mut profile = Profile { gaussians };
    // Each channel's weights sum to 1 exactly in f32 (Profile::validate).
    for c in 0..3 {
        let s: f32 = profile.gaussians.iter().map(|g| g.weights[c]).sum();
        if let Some(last) = profile
            .gaussians
            .iter_mut()
            .rev()
            .find(|g| g.weights[c] > 0.0)
        {
            last.weights[c] += 1.0 - s;
        }
    }
    Fit {
        error: Vec3::from_array(solved.each_ref().map(|(_, e)| *e as f32)),
        profile,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A radial histogram of an exact sum of Gaussians.
    fn radial_of(profile: &Profile, c: usize) -> Radial {
        let edges: Vec<f64> = (0..=300)
            .map(|i| 20.0 * (i as f64 / 300.0).powi(2))
            .collect();
        let density = edges
            .windows(2)
            .map(|e| {
                profile
                    .gaussians
                    .iter()
                    .map(|g| {
                        let v = f64::from(g.variance_mm2);
                        f64::from(g.weights[c])
                            * ((-e[0] * e[0] / (2.0 * v)).exp() - (-e[1] * e[1] / (2.0 * v)).exp())
                            / (PI * (e[1] * e[1] - e[0] * e[0]))
                    })
                    .sum()
            })
            .collect();
        Radial {
            edges,
            density,
            albedo: 1.0,
            single: 0.0,
            beyond: 0.0,
        }
    }

    #[test]
    fn nnls_by_hand() {
        // min (x − 1)² + (y + 1)² over x, y ≥ 0: (1, 0).
        let x = nnls(&[vec![1.0, 0.0], vec![0.0, 1.0]], &[1.0, -1.0]);
        assert_eq!(x, vec![1.0, 0.0]);
        // A = [[1, 1], [1, 2]] (AᵀA = [[2, 3], [3, 5]]), b = (1, 0): the
        // unconstrained (2, −1) is infeasible; on x ≥ 0 the best is y = 0,
        // x = Aᵀb₀/‖a₀‖² = 1/2.
        let x = nnls(&[vec![2.0, 3.0], vec![3.0, 5.0]], &[1.0, 1.0]);
        assert!((x[0] - 0.5).abs() < 1e-12 && x[1] == 0.0, "{x:?}");
    }

    /// d'Eon & Luebke's own six Gaussians are a sum of six Gaussians: the fit
    /// finds a profile as close as the histogram allows.
    #[test]
    fn the_fit_recovers_a_sum_of_gaussians() {
        let skin = Profile::skin();
        let radial = [0, 1, 2].map(|c| radial_of(&skin, c));
        let started = std::time::Instant::now();
        let fit = fit_profile(&radial, 6);
        eprintln!("fit in {:?}: error {:?}", started.elapsed(), fit.error);
        fit.profile.validate().unwrap();
        assert!(fit.error.max_element() < 0.02, "{:?}", fit.error);
    }
}
