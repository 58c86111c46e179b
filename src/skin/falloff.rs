//! What light through thin skin falls off by over the distance r it crosses
//! (light::transmission): the diffusion profile's R(r), or, with a medium,
//! the kernel whose integral over a slab's far side is the medium's walked
//! T(d) ÷ albedo: ∫_d^∞ R(r) 2πr dr = T(d) gives R(r) = −T′(r)/2πr.

use super::profile::Profile;
use glam::Vec3;

/// What the light through the skin falls off by over the distance r it
/// crosses (module doc).
#[derive(Clone, Debug)]
pub enum Falloff<'a> {
    /// The diffusion profile's R(r).
    Profile(&'a Profile),
    /// The decreasing envelope of a medium's slab transmission T(d) ÷ albedo
    /// ([`Falloff::slab`]).
    Slab { envelope: Vec<Vec3>, max_mm: f32 },
}

impl Falloff<'_> {
    /// From T(d) ÷ albedo at d = max·(i/(n − 1))² (skin::medium_tables), per
    /// channel. Its decreasing envelope (the largest T at or beyond each
    /// sample) is kept: a thin slab's scattered light still rises with d,
    /// while a kernel of light crossing r can only fall.
    pub fn slab(samples: &[Vec3], max_mm: f32) -> Falloff<'static> {
        let mut envelope = samples.to_vec();
        for i in (0..envelope.len().saturating_sub(1)).rev() {
            envelope[i] = envelope[i].max(envelope[i + 1]);
        }
        Falloff::Slab { envelope, max_mm }
    }

    /// Where it ends: at 4σ of the profile's widest Gaussian exp(−d²/2v) = e⁻⁸
    /// ≈ 3·10⁻⁴; the slab table's last sample.
    pub fn reach_mm(&self) -> f32 {
        match self {
            Falloff::Profile(p) => 4.0 * p.gaussians.last().map_or(0.0, |g| g.variance_mm2).sqrt(),
            Falloff::Slab { envelope, max_mm } if envelope.len() >= 2 => *max_mm,
            Falloff::Slab { .. } => 0.0,
        }
    }

    /// R(r) per channel; for a slab table −T′(r)/2πr, T linear in √d between
    /// samples as the GPU reads it.
    pub fn radial(&self, r: f32) -> Vec3 {
        match self {
            Falloff::Profile(p) => p.radial(r),
            Falloff::Slab { envelope, max_mm } => {
                let n = envelope.len();
                if n < 2 || !(r > 0.0 && r < *max_mm) {
                    return Vec3::ZERO;
                }
                let x = (r / max_mm).sqrt() * (n - 1) as f32;
                let i = (x as usize).min(n - 2);
                // T = a + (b − a)(x − i), x = (n − 1)√(r/max).
                let dx_dr = (n - 1) as f32 / (2.0 * (r * max_mm).sqrt());
                (envelope[i] - envelope[i + 1]) * dx_dr / (2.0 * std::f32::consts::PI * r)
            }
        }
    }

    /// Its settings in a cache key.
    pub fn key(&self) -> String {
        let bits = |v: Vec3| {
            v.to_array()
                .map(|x| format!("{:08x}", x.to_bits()))
                .concat()
        };
        match self {
            Falloff::Profile(p) => p
                .gaussians
                .iter()
                .map(|g| format!("{:08x}:{}", g.variance_mm2.to_bits(), bits(g.weights)))
                .collect::<Vec<_>>()
                .join(","),
            Falloff::Slab { envelope, max_mm } => format!(
                "slab:{:08x}:{}",
                max_mm.to_bits(),
                envelope
                    .iter()
                    .map(|&t| bits(t))
                    .collect::<Vec<_>>()
                    .join(",")
            ),
        }
    }
}
