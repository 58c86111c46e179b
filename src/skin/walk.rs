//! The medium's own reference: a Monte Carlo random walk of photons in a
//! homogeneous medium (skin::medium) behind a smooth dielectric boundary
//! (Fresnel reflection and total internal reflection; Henyey–Greenstein phase),
//! after Wang, Jacques & Zheng 1995 (MCML) for layered tissue. It gives, per
//! channel:
//! - the radial diffuse reflectance R(r) of a half-space lit at one point by
//!   light arriving diffusely (cosine-distributed outside, refracted in), and
//!   the medium's albedo: the share of light entering that leaves again;
//! - the light a slab d mm thick lit from behind at normal incidence lets
//!   through: the scattered share and the unscattered (ballistic) one.
//!
//! Light reflected at entry is not counted: that is the specular's. Counts are
//! per photon entering.

use crate::skin::medium::Medium;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Photons per rayon task (each task seeds its own generator from its index,
/// so results do not depend on the thread count).
const CHUNK: usize = 4096;
/// A walk longer than this many collisions counts as absorbed (marble's walks
/// average a few thousand).
const MAX_COLLISIONS: u32 = 1_000_000;

/// R(r) of one channel on a histogram of exit radii.
#[derive(Clone, Debug, PartialEq)]
pub struct Radial {
    /// Bin edges, mm, from 0; quadratic spacing (fine near the entry point).
    pub edges: Vec<f64>,
    /// Mean R over each bin, mm⁻² per photon entering, of the light scattered
    /// more than once (single scattering is `single`).
    pub density: Vec<f64>,
    /// Share of the photons entering that leave anywhere (∫2πr R dr over all
    /// r, single scattering included).
    pub albedo: f64,
    /// Share of the photons entering that leave after one scattering: a
    /// narrow peak about the entry, singular at r = 0 (Jensen et al. 2001's
    /// single-scattering term).
    pub single: f64,
    /// Of the multiply scattered light, the share that left beyond the last edge.
    pub beyond: f64,
}

/// A slab's transmission of one channel, per photon entering.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slab {
    /// Left through the far side after scattering at least once.
    pub scattered: f64,
    /// Left through the far side without scattering.
    pub ballistic: f64,
    /// Left back through the lit side.
    pub reflected: f64,
}

/// xoshiro256+ (Blackman & Vigna 2018), seeded by SplitMix64.
struct Rng([u64; 4]);

impl Rng {
    fn new(seed: u64) -> Rng {
        let mut z = seed;
        let mut next = || {
            z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut x = z;
            x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            x ^ (x >> 31)
        };
        Rng([next(), next(), next(), next()])
    }

    /// Uniform in [0, 1).
    fn next(&mut self) -> f64 {
        let s = &mut self.0;
        let result = s[0].wrapping_add(s[3]);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        (result >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// Unpolarised Fresnel reflectance of light inside a medium of index `eta`
/// meeting the boundary at `cos_i` (1 past the critical angle), or of light
/// outside (`eta` < 1 for the ratio outside/inside). Born & Wolf.
pub fn fresnel_dielectric(cos_i: f64, eta_ratio: f64) -> f64 {
    // eta_ratio = n_incident / n_transmitted.
    let sin_t2 = eta_ratio * eta_ratio * (1.0 - cos_i * cos_i);
    if sin_t2 >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    let rs = (eta_ratio * cos_i - cos_t) / (eta_ratio * cos_i + cos_t);
    let rp = (cos_i - eta_ratio * cos_t) / (cos_i + eta_ratio * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// One channel of a medium: what a walk needs.
#[derive(Clone, Copy, Debug)]
struct Channel {
    sigma_t: f64,
    albedo: f64,
    g: f64,
    eta: f64,
}

impl Channel {
    fn of(medium: &Medium, c: usize) -> Channel {
        let (sa, ss, g) = medium.channel(c);
        Channel {
            sigma_t: sa + ss,
            albedo: ss / (sa + ss),
            g,
            eta: f64::from(medium.ior),
        }
    }
}

/// Where a walk ended.
enum End {
    /// Left through the plane z = 0 at (x, y) after `collisions` scatterings.
    Top(f64, f64, u32),
    /// Left through z = thickness.
    Bottom {
        scattered: bool,
    },
    Absorbed,
}

/// A direction scattered from `d` by Henyey–Greenstein's phase function of
/// anisotropy g (sampled as in pbrt-v3, `HenyeyGreenstein::Sample_p`).
fn scatter(d: [f64; 3], g: f64, rng: &mut Rng) -> [f64; 3] {
    let (u1, u2) = (rng.next(), rng.next());
    let cos_t = if g.abs() < 1e-3 {
        1.0 - 2.0 * u1
    } else {
        let s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u1);
        (1.0 + g * g - s * s) / (2.0 * g)
    };
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = 2.0 * PI * u2;
    // An orthonormal frame about d (Duff et al. 2017).
    let sign = 1f64.copysign(d[2]);
    let a = -1.0 / (sign + d[2]);
    let b = d[0] * d[1] * a;
    let t = [1.0 + sign * d[0] * d[0] * a, sign * b, -sign * d[0]];
    let bt = [b, sign + d[1] * d[1] * a, -d[1]];
    let (x, y) = (sin_t * phi.cos(), sin_t * phi.sin());
    [0, 1, 2].map(|i| x * t[i] + y * bt[i] + cos_t * d[i])
}

/// One photon from (0, 0, 0) going `d` (d.z > 0) in a medium between z = 0
/// and z = `thickness` (∞: a half-space).
fn walk(ch: Channel, mut d: [f64; 3], thickness: f64, rng: &mut Rng) -> End {
    let mut p = [0.0f64; 3];
    let mut collisions = 0;
    while collisions < MAX_COLLISIONS {
        let s = -(1.0 - rng.next()).ln() / ch.sigma_t;
        let z = p[2] + s * d[2];
        let leaving = if z < 0.0 {
            Some(0.0)
        } else if z > thickness {
            Some(thickness)
        } else {
            None
        };
        if let Some(plane) = leaving {
            let t = (plane - p[2]) / d[2];
            p = [p[0] + t * d[0], p[1] + t * d[1], plane];
            if rng.next() < fresnel_dielectric(d[2].abs(), ch.eta) {
                // Reflected back in; the free path starts anew (memoryless).
                d[2] = -d[2];
                continue;
            }
            return if plane == 0.0 {
                End::Top(p[0], p[1], collisions)
            } else {
                End::Bottom {
                    scattered: collisions > 0,
                }
            };
        }
        p = [p[0] + s * d[0], p[1] + s * d[1], z];
        if rng.next() >= ch.albedo {
            return End::Absorbed;
        }
        d = scatter(d, ch.g, rng);
        collisions += 1;
    }
    End::Absorbed
}

/// A direction refracted into the medium from light arriving diffusely
/// (cosine-distributed) outside; `None` where the boundary reflects it.
fn diffuse_entry(eta: f64, rng: &mut Rng) -> Option<[f64; 3]> {
    let (u1, u2) = (rng.next(), rng.next());
    let cos_o = (1.0 - u1).sqrt();
    if rng.next() < fresnel_dielectric(cos_o, 1.0 / eta) {
        return None;
    }
    let sin_i = (1.0 - cos_o * cos_o).max(0.0).sqrt() / eta;
    let cos_i = (1.0 - sin_i * sin_i).sqrt();
    let phi = 2.0 * PI * u2;
    Some([sin_i * phi.cos(), sin_i * phi.sin(), cos_i])
}

/// Bin edges for channel `ch`: quadratic from 0 to ten diffusion lengths
/// 1/σtr (and at least ten mean free paths).
fn edges(medium: &Medium, c: usize, bins: usize) -> Vec<f64> {
    let tr = f64::from(medium.sigma_tr()[c]);
    let st = f64::from(medium.sigma_t_prime()[c]);
    let r_max = (10.0 / tr).max(10.0 / st).min(500.0);
    (0..=bins)
        .map(|i| r_max * (i as f64 / bins as f64).powi(2))
        .collect()
}

/// R(r) of channel `c` from `photons` photons entering (rounded up to whole
/// chunks) into `bins` bins; `entry_normal`: light enters along the normal
/// (searchlight) instead of diffusely.
pub fn radial(
    medium: &Medium,
    c: usize,
    photons: usize,
    bins: usize,
    entry_normal: bool,
) -> Radial {
    let ch = Channel::of(medium, c);
    let edges = edges(medium, c, bins);
    let chunks = photons.div_ceil(CHUNK);
    let r_max = *edges.last().unwrap_or(&0.0);
    let (counts, entered, left, single) = (0..chunks)
        .into_par_iter()
        .map(|k| {
            let mut rng = Rng::new(((c as u64) << 40) ^ k as u64 ^ 0x5eed);
            let mut counts = vec![0u64; bins];
            let (mut entered, mut left, mut single) = (0u64, 0u64, 0u64);
            for _ in 0..CHUNK {
                let d = if entry_normal {
                    Some([0.0, 0.0, 1.0])
                } else {
                    diffuse_entry(ch.eta, &mut rng)
                };
                let Some(d) = d else { continue };
                entered += 1;
                if let End::Top(x, y, collisions) = walk(ch, d, f64::INFINITY, &mut rng) {
                    left += 1;
                    if collisions <= 1 {
                        single += 1;
                        continue;
                    }
                    let r = (x * x + y * y).sqrt();
                    if r < r_max {
                        // Quadratic edges: bin = ⌊bins·√(r/r_max)⌋.
                        let i = ((r / r_max).sqrt() * bins as f64) as usize;
                        counts[i.min(bins - 1)] += 1;
                    }
                }
            }
            (counts, entered, left, single)
        })
        .reduce(
            || (vec![0u64; bins], 0, 0, 0),
            |(mut a, ea, la, sa), (b, eb, lb, sb)| {
                a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                (a, ea + eb, la + lb, sa + sb)
            },
        );
    let n = entered.max(1) as f64;
    let density = counts
        .iter()
        .zip(edges.windows(2))
        .map(|(&k, e)| k as f64 / (n * PI * (e[1] * e[1] - e[0] * e[0])))
        .collect();
    let inside: u64 = counts.iter().sum();
    let multiple = left - single;
    Radial {
        edges,
        density,
        albedo: left as f64 / n,
        single: single as f64 / n,
        beyond: if multiple > 0 {
            (multiple - inside) as f64 / multiple as f64
        } else {
            0.0
        },
    }
}

/// Channel `c`'s transmission through a slab `thickness` mm thick, lit from
/// behind at normal incidence, from `photons` photons entering.
pub fn slab(medium: &Medium, c: usize, thickness: f64, photons: usize) -> Slab {
    let counts = slab_counts(medium, c, thickness, 0..photons.div_ceil(CHUNK));
    counts.share()
}

/// The same, walking photons in growing batches until `scattered` of them
/// have left scattered through the far side (relative noise 1/√`scattered`)
/// or `max_photons` have entered.
pub fn slab_to_count(
    medium: &Medium,
    c: usize,
    thickness: f64,
    scattered: u64,
    max_photons: usize,
) -> Slab {
    let max_chunks = max_photons.div_ceil(CHUNK).max(1);
    let mut total = SlabCounts::default();
    let mut done = 0;
    let mut batch = 4;
    while done < max_chunks && total.scattered < scattered {
        let next = (done + batch).min(max_chunks);
        total.add(slab_counts(medium, c, thickness, done..next));
        done = next;
        batch *= 2;
    }
    total.share()
}

/// Photons counted by where they left a slab.
#[derive(Clone, Copy, Debug, Default)]
struct SlabCounts {
    scattered: u64,
    ballistic: u64,
    reflected: u64,
    entered: u64,
}

impl SlabCounts {
    fn add(&mut self, o: SlabCounts) {
        self.scattered += o.scattered;
        self.ballistic += o.ballistic;
        self.reflected += o.reflected;
        self.entered += o.entered;
    }

    fn share(&self) -> Slab {
        let n = self.entered.max(1) as f64;
        Slab {
            scattered: self.scattered as f64 / n,
            ballistic: self.ballistic as f64 / n,
            reflected: self.reflected as f64 / n,
        }
    }
}

/// The photons of chunks `chunks` (each seeded by its index).
fn slab_counts(
    medium: &Medium,
    c: usize,
    thickness: f64,
    chunks: std::ops::Range<usize>,
) -> SlabCounts {
    let ch = Channel::of(medium, c);
    let seed = ((c as u64) << 40) ^ thickness.to_bits().rotate_left(7) ^ 0x51ab;
    chunks
        .into_par_iter()
        .map(|k| {
            let mut rng = Rng::new(seed ^ ((k as u64) << 20));
            let mut n = SlabCounts {
                entered: CHUNK as u64,
                ..SlabCounts::default()
            };
            for _ in 0..CHUNK {
                match walk(ch, [0.0, 0.0, 1.0], thickness, &mut rng) {
                    End::Bottom { scattered: true } => n.scattered += 1,
                    End::Bottom { scattered: false } => n.ballistic += 1,
                    End::Top(..) => n.reflected += 1,
                    End::Absorbed => {}
                }
            }
            n
        })
        .reduce(SlabCounts::default, |mut a, b| {
            a.add(b);
            a
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skin::medium::{
        dipole_radial, dipole_total_reflectance, internal_reflection_a, van_de_hulst_inverse,
    };
    use glam::Vec3;

    fn grey(sigma_a: f32, sigma_s_prime: f32, ior: f32) -> Medium {
        Medium::new(Vec3::splat(sigma_a), Vec3::splat(sigma_s_prime), 0.0, ior)
    }

    #[test]
    fn fresnel_by_hand() {
        // Normal incidence: ((n − 1)/(n + 1))² both ways; TIR past asin(1/1.4).
        let f0 = (0.4f64 / 2.4).powi(2);
        assert!((fresnel_dielectric(1.0, 1.4) - f0).abs() < 1e-12);
        assert!((fresnel_dielectric(1.0, 1.0 / 1.4) - f0).abs() < 1e-12);
        assert_eq!(fresnel_dielectric(0.5, 1.4), 1.0);
        assert!(fresnel_dielectric(0.75, 1.4) < 1.0);
        assert!(fresnel_dielectric(0.3, 1.0) < 1e-15);
    }

    /// An index-matched half-space lit diffusely reflects van de Hulst's
    /// albedo: Christensen & Burley's fit of his tables, inverted, gives back
    /// the single-scattering albedo within 2 % (measured: 0.7 % at α = 0.5,
    /// under 0.2 % from 0.8 up).
    #[test]
    fn total_reflectance_matches_van_de_hulst() {
        for alpha in [0.5f32, 0.8, 0.95, 0.99] {
            let m = grey(1.0 - alpha, alpha, 1.0);
            let a = radial(&m, 0, 1 << 17, 64, false).albedo;
            let back = van_de_hulst_inverse(a);
            assert!(
                (back - f64::from(alpha)).abs() < 0.02 * f64::from(alpha),
                "α {alpha}: A {a} inverts to {back}"
            );
        }
    }

    /// Where diffusion holds (α′ near 1), the boundary-corrected dipole's total
    /// reflectance of the light entering along the normal (Jensen et al. 2001,
    /// eq. 8; 1.2 % apart) and its R(r) one to two and a half diffusion lengths
    /// out (eq. 4; 0.6-8 % apart, the walk's noise included).
    #[test]
    fn high_albedo_matches_the_dipole() {
        let m = grey(0.01, 1.0, 1.4);
        let r = radial(&m, 0, 1 << 18, 200, true);
        let a = internal_reflection_a(1.4);
        let total = dipole_total_reflectance(1.0 / 1.01, a);
        assert!(
            (r.albedo - total).abs() < 0.05 * total,
            "{} against {total}",
            r.albedo
        );
        let tr = f64::from(m.sigma_tr().x);
        for (e, &density) in r.edges.windows(2).zip(&r.density) {
            let mid = 0.5 * (e[0] + e[1]);
            if (1.0..=2.5).contains(&(mid * tr)) {
                let dipole = dipole_radial(0.01, 1.0, 1.4, mid);
                assert!(
                    (density - dipole).abs() < 0.15 * dipole,
                    "r {mid:.2} mm: {density:e} against {dipole:e}"
                );
            }
        }
    }

    #[test]
    fn radial_histogram_holds_the_albedo() {
        let m = grey(0.05, 1.0, 1.4);
        let r = radial(&m, 0, 1 << 16, 100, false);
        let held: f64 = r
            .edges
            .windows(2)
            .zip(&r.density)
            .map(|(e, d)| d * PI * (e[1] * e[1] - e[0] * e[0]))
            .sum();
        let multiple = r.albedo - r.single;
        assert!(
            (held - multiple * (1.0 - r.beyond)).abs() < 1e-9,
            "{held} {r:?}"
        );
        assert!(r.single > 0.0 && r.single < 0.5 * r.albedo, "{r:?}");
        assert!(r.beyond < 0.01, "{}", r.beyond);
    }

    #[test]
    fn slabs_thin_and_thick() {
        let m = grey(0.17, 0.88, 1.4);
        // A slab of no thickness lets the beam that entered out through the
        // far boundary, the internal reflections between the two summed:
        // (1 − F)(1 + F² + F⁴ + …) = 1/(1 + F), F = ((η − 1)/(η + 1))².
        let thin = slab(&m, 0, 1e-9, 1 << 16);
        let f = (0.4f64 / 2.4).powi(2);
        let boundary = 1.0 / (1.0 + f);
        assert!(thin.scattered < 1e-3, "{thin:?}");
        assert!(
            (thin.ballistic - boundary).abs() < 0.01,
            "{thin:?} against {boundary}"
        );
        // Thick: nothing through; a ballistic beam falls as e^(−σt d).
        let thick = slab(&m, 0, 40.0, 1 << 14);
        assert!(thick.scattered + thick.ballistic < 1e-4, "{thick:?}");
        let one = slab(&m, 0, 1.0, 1 << 17);
        let beam = (1.0 - f) * (-1.05f64).exp();
        assert!(
            (one.ballistic - beam).abs() < 0.02 * beam,
            "{one:?} against {beam}"
        );
        // Energy: nothing is lost but what is absorbed.
        assert!(one.scattered + one.ballistic + one.reflected < 1.0);
    }
}
