//! The skin diffusion profile as a sum of Gaussians, and the 1-D blur kernels
//! that the texture-space blur chain applies (CPU reference for the GPU passes).
//!
//! Sources:
//! - Yang, Wang & Zuo 2012, eqs. 2–5 and Fig. 2 (the six-Gaussian skin fit);
//! - d'Eon & Luebke, "Advanced Techniques for Realistic Real-Time Skin
//!   Rendering", GPU Gems 3 ch. 14, §14.4 (the sum-of-Gaussians skin fit) and
//!   §14.5 (the separable 7-tap convolution shader). Listings are cited by
//!   function name; figure/listing numbers are not verified here.
//!
//! Units: distances in mm, variances in mm²; blur kernels are expressed in
//! units of the Gaussian's standard deviation σ, and [`convolve_1d`] takes σ in
//! texels. See `docs/design/skin.md` for the measured kernel errors.

use glam::Vec3;
use std::f32::consts::PI;

/// One Gaussian of the profile: `w · G(v, r)` with per-channel (R, G, B) weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gaussian {
    /// Variance v in mm².
    pub variance_mm2: f32,
    /// Weight per colour channel (R, G, B).
    pub weights: Vec3,
}

/// A radial diffusion profile R(r) ≈ Σ wᵢ G(vᵢ, r) (eq. 2).
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    /// Gaussians in ascending order of variance.
    pub gaussians: Vec<Gaussian>,
}

/// Why a profile failed [`Profile::validate`].
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ProfileError {
    #[error("the profile has no Gaussians")]
    Empty,
    #[error("Gaussian {index}: variance {variance} mm² is not finite and positive")]
    BadVariance { index: usize, variance: f32 },
    #[error(
        "Gaussian {index}: variance {variance} mm² does not exceed the previous {previous} mm²"
    )]
    NotAscending {
        index: usize,
        previous: f32,
        variance: f32,
    },
    #[error("Gaussian {index}: weight {weight} in channel {channel} is negative or not finite")]
    BadWeight {
        index: usize,
        channel: usize,
        weight: f32,
    },
    #[error("channel {channel}: weights sum to {sum}, not 1 (tolerance {WEIGHT_SUM_TOLERANCE})")]
    WeightSum { channel: usize, sum: f32 },
}

/// Tolerance on the per-channel weight sums in [`Profile::validate`].
pub const WEIGHT_SUM_TOLERANCE: f32 = 1e-3;

/// The six-Gaussian skin fit: (variance mm², R, G, B weights).
/// Yang et al. 2012 Fig. 2, reproducing GPU Gems 3 §14.4 (d'Eon & Luebke's fit of
/// Donner & Jensen's three-layer skin profile). Each column sums to exactly 1.000:
/// R 0.233+0.100+0.118+0.113+0.358+0.078, G 0.455+0.336+0.198+0.007+0.004,
/// B 0.649+0.344+0.007.
pub const SKIN_TABLE: [(f32, [f32; 3]); 6] = [
    (0.0064, [0.233, 0.455, 0.649]),
    (0.0484, [0.100, 0.336, 0.344]),
    (0.187, [0.118, 0.198, 0.0]),
    (0.567, [0.113, 0.007, 0.007]),
    (1.99, [0.358, 0.004, 0.0]),
    (7.41, [0.078, 0.0, 0.0]),
];

impl Profile {
    /// The six-Gaussian skin profile of [`SKIN_TABLE`].
    pub fn skin() -> Self {
        Profile {
            gaussians: SKIN_TABLE
                .iter()
                .map(|&(v, w)| Gaussian {
                    variance_mm2: v,
                    weights: Vec3::from_array(w),
                })
                .collect(),
        }
    }

    /// Per-channel sum of the weights (R, G, B).
    pub fn weight_sums(&self) -> Vec3 {
        self.gaussians.iter().map(|g| g.weights).sum()
    }

    /// Checks: at least one Gaussian; finite positive variances in strictly
    /// ascending order (the blur chain needs v_k > v_{k-1}); finite non-negative
    /// weights; per-channel weight sums within [`WEIGHT_SUM_TOLERANCE`] of 1.
    pub fn validate(&self) -> Result<(), ProfileError> {
        if self.gaussians.is_empty() {
            return Err(ProfileError::Empty);
        }
        let mut previous = 0.0_f32;
        for (index, g) in self.gaussians.iter().enumerate() {
            let variance = g.variance_mm2;
            if !(variance.is_finite() && variance > 0.0) {
                return Err(ProfileError::BadVariance { index, variance });
            }
            if variance <= previous {
                return Err(ProfileError::NotAscending {
                    index,
                    previous,
                    variance,
                });
            }
            previous = variance;
            for (channel, &weight) in g.weights.to_array().iter().enumerate() {
                if !(weight.is_finite() && weight >= 0.0) {
                    return Err(ProfileError::BadWeight {
                        index,
                        channel,
                        weight,
                    });
                }
            }
        }
        for (channel, &sum) in self.weight_sums().to_array().iter().enumerate() {
            if (sum - 1.0).abs() > WEIGHT_SUM_TOLERANCE {
                return Err(ProfileError::WeightSum { channel, sum });
            }
        }
        Ok(())
    }

    /// R(r) = Σ wᵢ G(vᵢ, r) per channel (eq. 2), r in mm, result in 1/mm².
    pub fn radial(&self, r_mm: f32) -> Vec3 {
        self.gaussians
            .iter()
            .map(|g| g.weights * gaussian(g.variance_mm2, r_mm))
            .sum()
    }

    /// Transmittance through a slab of thickness `d_mm` (translucent shadow maps,
    /// d'Eon & Luebke §14.5.3; Jimenez et al. 2010): light entering at a point
    /// of the far surface and leaving r away on the near one travels
    /// √(r² + d²), and G(v, √(r² + d²)) = G(v, r)·exp(−d²/2v), so the profile
    /// integrated over the near surface is T(d) = Σ wᵢ exp(−d²/2vᵢ) per channel
    /// (1 at d = 0). A zero variance (blur width 0) transmits only at d = 0.
    pub fn transmittance(&self, d_mm: f32) -> Vec3 {
        self.gaussians
            .iter()
            .map(|g| g.weights * slab_factor(g.variance_mm2, d_mm))
            .sum()
    }

    /// Standard deviations (mm) of the incremental blurs of the chain:
    /// σ_k = √(v_k − v_{k−1}) with v_0 = 0, so that blurring blur k−1 by σ_k
    /// gives blur k (eq. 5: G(v₁) * G(v₂) = G(v₁ + v₂)). Assumes ascending
    /// variances (see [`Profile::validate`]); a non-increasing step gives 0.
    pub fn increments(&self) -> Vec<f32> {
        let mut previous = 0.0_f32;
        self.gaussians
            .iter()
            .map(|g| {
                let d = (g.variance_mm2 - previous).max(0.0);
                previous = g.variance_mm2;
                d.sqrt()
            })
            .collect()
    }
}

/// The 2-D radial Gaussian of eq. 3: G(v, r) = exp(−r²/2v) / (2πv).
/// v in mm², r in mm; integrates to 1 over the plane.
pub fn gaussian(variance_mm2: f32, r_mm: f32) -> f32 {
    (-r_mm * r_mm / (2.0 * variance_mm2)).exp() / (2.0 * PI * variance_mm2)
}

/// exp(−d²/2v): what one Gaussian of variance v keeps through thickness d
/// (`transmittance` in shaders-glsl/skin.frag mirrors it).
fn slab_factor(variance_mm2: f32, d_mm: f32) -> f32 {
    if variance_mm2 > 0.0 {
        (-d_mm * d_mm / (2.0 * variance_mm2)).exp()
    } else if d_mm <= 0.0 {
        1.0
    } else {
        0.0
    }
}

/// d'Eon's 7-tap offsets, in units of σ (GPU Gems 3 §14.5, convolution shader).
pub const DEON7_OFFSETS_SIGMA: [f32; 7] = [-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0];
/// d'Eon's 7-tap weights as printed (GPU Gems 3 §14.5). They sum to
/// 1.001, not 1; [`Kernel::deon7`] normalises them.
pub const DEON7_WEIGHTS: [f32; 7] = [0.006, 0.061, 0.242, 0.383, 0.242, 0.061, 0.006];

/// Default half-width of [`Kernel::accurate`] in σ: the tail beyond 4σ holds
/// 6e-5 of the mass and the kernel's edge value is 3e-4 of its peak.
pub const ACCURATE_EXTENT_SIGMA: f32 = 4.0;
/// Default maximum tap spacing of [`Kernel::accurate`] in σ.
pub const ACCURATE_MAX_SPACING_SIGMA: f32 = 0.5;

/// A symmetric 1-D blur kernel: taps at `offsets_sigma[i] · σ` with `weights[i]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Kernel {
    pub offsets_sigma: Vec<f32>,
    pub weights: Vec<f32>,
}

impl Kernel {
    /// d'Eon's 7 taps at −3σ…3σ (GPU Gems 3 §14.5), with the printed
    /// weights divided by their sum 1.001. Unnormalised, every pass would gain
    /// 0.1 %, and the chain compounds it: blur k sits behind 2k passes (U and V),
    /// so blur 6 would come out 1.2 % too bright.
    pub fn deon7() -> Self {
        let sum: f32 = DEON7_WEIGHTS.iter().sum();
        Kernel {
            offsets_sigma: DEON7_OFFSETS_SIGMA.to_vec(),
            weights: DEON7_WEIGHTS.iter().map(|w| w / sum).collect(),
        }
    }

    /// Uniform taps from −extent to +extent (in σ), spaced at most
    /// `max_spacing_sigma` (the spacing is extent/n for the smallest whole n that
    /// fits, so both ends are taps), weighted by the Gaussian's value at each tap
    /// and normalised to sum to 1.
    ///
    /// Point values, not the Gaussian's integral over each tap's interval: the
    /// interval integrals form a box-filtered Gaussian whose variance is
    /// σ² + s²/12 (Sheppard's correction), 2 % too wide at s = 0.5σ, while point
    /// samples keep the variance at σ² to within 1e-6 for s ≤ σ.
    /// Typical use: `Kernel::accurate(ACCURATE_MAX_SPACING_SIGMA, ACCURATE_EXTENT_SIGMA)`.
    pub fn accurate(max_spacing_sigma: f32, extent_sigma: f32) -> Self {
        assert!(
            max_spacing_sigma > 0.0 && extent_sigma > 0.0,
            "spacing and extent must be positive"
        );
        let n = (extent_sigma / max_spacing_sigma - 1e-6).ceil().max(1.0) as i32;
        let spacing = extent_sigma / n as f32;
        let offsets_sigma: Vec<f32> = (-n..=n).map(|k| k as f32 * spacing).collect();
        let raw: Vec<f64> = offsets_sigma
            .iter()
            .map(|&x| (-0.5 * f64::from(x) * f64::from(x)).exp())
            .collect();
        let sum: f64 = raw.iter().sum();
        Kernel {
            offsets_sigma,
            weights: raw.iter().map(|w| (w / sum) as f32).collect(),
        }
    }

    /// Number of taps.
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// True when the kernel has no taps.
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    /// Sum of the weights.
    pub fn weight_sum(&self) -> f32 {
        self.weights.iter().sum()
    }

    /// Variance of the taps, in σ² units: Σ wᵢ xᵢ² / Σ wᵢ (1 for an exact Gaussian).
    pub fn variance_sigma2(&self) -> f32 {
        let m2: f32 = self
            .offsets_sigma
            .iter()
            .zip(&self.weights)
            .map(|(x, w)| w * x * x)
            .sum();
        m2 / self.weight_sum()
    }
}

/// One separable blur pass along a row, as the GPU pass does it:
/// `out[i] = Σ_k w_k · sample(i + offset_k · σ)`, where `sample` interpolates
/// linearly between the two nearest texels (bilinear filtering along one axis)
/// and clamps indices to the edge (CLAMP_TO_EDGE). Texel i's centre is at i.
///
/// Note that linear interpolation at a fractional position adds spread of its
/// own (a tap at fraction f adds variance f(1−f) texel², 1/6 on average), which
/// matters when σ is a few texels; `docs/design/skin.md` lists the measured errors.
/// GPUs also quantise the interpolation fraction (8 bits on most hardware and
/// lavapipe); this reference does not.
pub fn convolve_1d(signal: &[f32], kernel: &Kernel, sigma_texels: f32) -> Vec<f32> {
    let n = signal.len();
    if n == 0 {
        return Vec::new();
    }
    let last = n as i64 - 1;
    let fetch = |i: i64| signal[i.clamp(0, last) as usize];
    (0..n)
        .map(|i| {
            kernel
                .offsets_sigma
                .iter()
                .zip(&kernel.weights)
                .map(|(&o, &w)| {
                    let p = i as f32 + o * sigma_texels;
                    let p0 = p.floor();
                    let f = p - p0;
                    let i0 = p0 as i64;
                    w * ((1.0 - f) * fetch(i0) + f * fetch(i0 + 1))
                })
                .sum()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 1-D Gaussian of standard deviation s at x (the separable factor of eq. 3).
    fn g1(s: f64, x: f64) -> f64 {
        (-x * x / (2.0 * s * s)).exp() / ((2.0 * std::f64::consts::PI).sqrt() * s)
    }

    /// Max |out − exact| over the row, divided by the exact peak.
    fn max_err_of_peak(out: &[f32], exact: &[f64]) -> f64 {
        let peak = exact.iter().cloned().fold(0.0, f64::max);
        out.iter()
            .zip(exact)
            .map(|(&o, &e)| (f64::from(o) - e).abs())
            .fold(0.0, f64::max)
            / peak
    }

    /// Blur a unit impulse at the centre of a row and compare with the sampled
    /// 1-D Gaussian of σ texels.
    fn delta_error(kernel: &Kernel, sigma: f32) -> f64 {
        let n = (2.0 * (6.0 * sigma + 8.0)) as usize | 1;
        let c = n / 2;
        let mut signal = vec![0.0; n];
        signal[c] = 1.0;
        let out = convolve_1d(&signal, kernel, sigma);
        let exact: Vec<f64> = (0..n)
            .map(|i| g1(f64::from(sigma), i as f64 - c as f64))
            .collect();
        max_err_of_peak(&out, &exact)
    }

    /// Blur a sampled Gaussian of σ_in texels (a band-limited input, like the
    /// previous level of the chain) and compare with the exact Gaussian of
    /// variance σ_in² + σ².
    fn smooth_error(kernel: &Kernel, sigma_in: f32, sigma: f32) -> f64 {
        let s_in = f64::from(sigma_in);
        let s_out = (s_in * s_in + f64::from(sigma) * f64::from(sigma)).sqrt();
        let n = (2.0 * (6.0 * s_out + 8.0)) as usize | 1;
        let c = n as f64 / 2.0 - 0.5;
        let signal: Vec<f32> = (0..n).map(|i| g1(s_in, i as f64 - c) as f32).collect();
        let out = convolve_1d(&signal, kernel, sigma);
        let exact: Vec<f64> = (0..n).map(|i| g1(s_out, i as f64 - c)).collect();
        max_err_of_peak(&out, &exact)
    }

    const SIGMAS: [f32; 8] = [1.5, 2.0, 3.0, 4.7, 7.3, 10.0, 14.1, 20.0];

    #[test]
    fn skin_table_is_valid_and_channels_sum_to_one() {
        let p = Profile::skin();
        assert_eq!(p.validate(), Ok(()));
        let s = p.weight_sums();
        for c in s.to_array() {
            assert!((c - 1.0).abs() < 1e-6, "channel sums {s}");
        }
    }

    #[test]
    fn validation_catches_bad_tables() {
        let mut p = Profile::skin();
        p.gaussians.swap(1, 2);
        assert!(matches!(
            p.validate(),
            Err(ProfileError::NotAscending { index: 2, .. })
        ));
        let mut p = Profile::skin();
        p.gaussians[5].weights.x += 0.01;
        assert!(matches!(
            p.validate(),
            Err(ProfileError::WeightSum { channel: 0, .. })
        ));
        assert_eq!(
            Profile { gaussians: vec![] }.validate(),
            Err(ProfileError::Empty)
        );
    }

    #[test]
    fn radial_profile_integrates_to_one_over_the_plane() {
        // ∫ 2πr R(r) dr, midpoint rule with dr = 0.1 µm out to 30 mm
        // (11σ of the widest Gaussian).
        let p = Profile::skin();
        let dr = 1e-4_f64;
        let mut total = [0.0_f64; 3];
        for k in 0..300_000 {
            let r = (k as f64 + 0.5) * dr;
            let rr = p.radial(r as f32).to_array();
            for c in 0..3 {
                total[c] += 2.0 * std::f64::consts::PI * r * f64::from(rr[c]) * dr;
            }
        }
        for (c, t) in total.iter().enumerate() {
            assert!((t - 1.0).abs() < 1e-3, "channel {c}: ∫R = {t}");
        }
    }

    #[test]
    fn transmittance_is_the_profile_through_a_slab() {
        let p = Profile::skin();
        assert!((p.transmittance(0.0) - Vec3::ONE).abs().max_element() < 1e-3);
        // Integrating the 3-D profile over the plane at distance d (polar
        // coordinates, r to 60 mm) gives the same as the closed form.
        for d in [0.5f32, 1.0, 2.0, 5.0] {
            let (n, r_max) = (60_000, 60.0f64);
            let dr = r_max / n as f64;
            let mut integral = [0.0f64; 3];
            for k in 0..n {
                let r = (k as f64 + 0.5) * dr;
                let dist = (r * r + (d as f64).powi(2)).sqrt() as f32;
                let radial = p.radial(dist);
                for (c, v) in integral.iter_mut().enumerate() {
                    *v += 2.0 * std::f64::consts::PI * r * radial[c] as f64 * dr;
                }
            }
            let t = p.transmittance(d);
            println!("T({d} mm) = {:.5} {:.6} {:.3e}", t.x, t.y, t.z);
            for c in 0..3 {
                let err = (integral[c] - t[c] as f64).abs();
                assert!(
                    err <= 1e-4 * t[c] as f64 + 1e-9,
                    "d {d} c {c}: {integral:?} vs {t}"
                );
            }
        }
        // Thicker transmits less, red most (the widest Gaussians are red).
        let (a, b) = (p.transmittance(1.0), p.transmittance(2.0));
        assert!(b.cmplt(a).all() && b.x > b.y && b.y > b.z);
        let flat = Profile {
            gaussians: vec![Gaussian {
                variance_mm2: 0.0,
                weights: Vec3::ONE,
            }],
        };
        assert_eq!(
            (flat.transmittance(0.0), flat.transmittance(0.1)),
            (Vec3::ONE, Vec3::ZERO)
        );
    }

    #[test]
    fn gaussian_matches_eq3_by_hand() {
        // G(1, 0) = 1/2π; G(2, 2) = e^-1 / 4π.
        assert!((gaussian(1.0, 0.0) - 1.0 / (2.0 * PI)).abs() < 1e-7);
        assert!((gaussian(2.0, 2.0) - (-1.0f32).exp() / (4.0 * PI)).abs() < 1e-7);
    }

    #[test]
    fn increments_reproduce_the_variances() {
        let p = Profile::skin();
        let inc = p.increments();
        assert_eq!(inc.len(), 6);
        let mut acc = 0.0_f32;
        for (s, g) in inc.iter().zip(&p.gaussians) {
            acc += s * s;
            assert!((acc - g.variance_mm2).abs() < 1e-5 * g.variance_mm2.max(1.0));
        }
        // First increment is √0.0064 = 0.08 mm.
        assert!((inc[0] - 0.08).abs() < 1e-6);
    }

    #[test]
    fn kernels_sum_to_one() {
        let a = Kernel::accurate(ACCURATE_MAX_SPACING_SIGMA, ACCURATE_EXTENT_SIGMA);
        assert_eq!(a.len(), 17); // −4σ…4σ at 0.5σ
        assert!((a.weight_sum() - 1.0).abs() < 1e-6);
        let d = Kernel::deon7();
        assert!((d.weight_sum() - 1.0).abs() < 1e-6);
        let raw: f32 = DEON7_WEIGHTS.iter().sum();
        assert!((raw - 1.001).abs() < 1e-6, "printed weights sum to {raw}");
    }

    #[test]
    fn accurate_kernel_matches_the_gaussian_in_sigma_units() {
        // Taps as samples of a density: w_k / spacing vs the unit Gaussian.
        let k = Kernel::accurate(ACCURATE_MAX_SPACING_SIGMA, ACCURATE_EXTENT_SIGMA);
        let s = f64::from(k.offsets_sigma[1] - k.offsets_sigma[0]);
        let peak = g1(1.0, 0.0);
        let err = k
            .offsets_sigma
            .iter()
            .zip(&k.weights)
            .map(|(&x, &w)| (f64::from(w) / s - g1(1.0, f64::from(x))).abs())
            .fold(0.0, f64::max)
            / peak;
        let var = k.variance_sigma2();
        let d = Kernel::deon7();
        println!(
            "accurate: density error {:.4} % of peak, variance {var:.6} σ²; deon7 variance {:.4} σ²",
            100.0 * err,
            d.variance_sigma2()
        );
        assert!(err < 5e-3);
        assert!((var - 1.0).abs() < 1e-3);
    }

    #[test]
    fn blur_of_a_smooth_input_matches_the_exact_gaussian() {
        // Input as smooth as the kernel (σ_in = σ), the situation of the chain,
        // where blur k runs on blur k−1.
        let k = Kernel::accurate(ACCURATE_MAX_SPACING_SIGMA, ACCURATE_EXTENT_SIGMA);
        let d = Kernel::deon7();
        println!("σ_in = σ: error in % of peak");
        for &s in &SIGMAS {
            let ea = smooth_error(&k, s, s);
            let ed = smooth_error(&d, s, s);
            println!(
                "  σ {s:5.1} texels: accurate {:.3} %, deon7 {:.3} %",
                100.0 * ea,
                100.0 * ed
            );
            if s >= 2.0 {
                assert!(ea < 5e-3, "σ {s}: {ea}");
            }
        }
    }

    #[test]
    fn delta_response_report() {
        // An impulse is the worst input for sparse taps: with spacing above a
        // texel the output is a comb. Reported, not asserted (see docs/design/skin.md).
        let k = Kernel::accurate(ACCURATE_MAX_SPACING_SIGMA, ACCURATE_EXTENT_SIGMA);
        let d = Kernel::deon7();
        println!("impulse input: error in % of peak");
        for &s in &SIGMAS {
            let dense = Kernel::accurate(ACCURATE_MAX_SPACING_SIGMA.min(0.5 / s), 4.0);
            println!(
                "  σ {s:5.1} texels: accurate(0.5σ) {:.3} %, accurate(≤0.5 texel, {} taps) {:.3} %, deon7 {:.3} %",
                100.0 * delta_error(&k, s),
                dense.len(),
                100.0 * delta_error(&dense, s),
                100.0 * delta_error(&d, s)
            );
        }
    }

    #[test]
    fn chained_increments_equal_one_blur_of_the_total_variance() {
        // The skin chain in 1-D at 0.025 mm per texel (σ_1 = 3.2 texels), on an
        // input that is itself a Gaussian of σ_0 = 3 texels. Level k must match
        // the exact Gaussian of variance σ_0² + v_k, as eq. 5 promises.
        let mm_per_texel = 0.025_f32;
        let s0 = 3.0_f64;
        let p = Profile::skin();
        let total = f64::from(p.gaussians[5].variance_mm2).sqrt() / f64::from(mm_per_texel);
        let n = (2.0 * (6.0 * total + 8.0)) as usize | 1;
        let c = n as f64 / 2.0 - 0.5;
        let mut row: Vec<f32> = (0..n).map(|i| g1(s0, i as f64 - c) as f32).collect();
        let k = Kernel::accurate(ACCURATE_MAX_SPACING_SIGMA, ACCURATE_EXTENT_SIGMA);
        for (inc, g) in p.increments().iter().zip(&p.gaussians) {
            row = convolve_1d(&row, &k, inc / mm_per_texel);
            let v = s0 * s0 + f64::from(g.variance_mm2) / f64::from(mm_per_texel).powi(2);
            let exact: Vec<f64> = (0..n).map(|i| g1(v.sqrt(), i as f64 - c)).collect();
            let err = max_err_of_peak(&row, &exact);
            println!(
                "chain level v = {} mm²: {:.3} % of peak",
                g.variance_mm2,
                100.0 * err
            );
            assert!(err < 5e-3, "level {}: {err}", g.variance_mm2);
        }
    }
}
