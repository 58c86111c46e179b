//! What the skin passes take from a medium (skin::medium), computed once by the
//! random walk (skin::walk) and cached by the medium's key: its albedo, its
//! R(r) fitted by the chain's six Gaussians (skin::fit), and its transmission
//! through a slab by thickness, T(d), as a table the translucent pass reads.

use crate::atomic::write_atomic;
use crate::cache::{fnv1a64, hex};
use crate::skin::fit::{fit_profile, fit_reference, Fit};
use crate::skin::medium::Medium;
use crate::skin::profile::{Gaussian, Profile};
use crate::skin::walk::{self, Radial};
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::Mutex;

/// Photons entering per channel for R(r): its histogram's bins near the
/// profile's reach hold thousands each.
pub const RADIAL_PHOTONS: usize = 1 << 20;
/// Bins of R(r), quadratic from 0 to ten diffusion lengths (skin::walk).
pub const RADIAL_BINS: usize = 256;
/// Samples of T(d), quadratic from 0 to [`MediumTables::max_thickness_mm`]:
/// dense where T rises from 0 over the first diffusion length.
pub const SLAB_SAMPLES: usize = 48;
/// Each sample of T(d) walks photons until this many left through the far
/// side scattered (±2 % noise), or [`SLAB_MAX_PHOTONS`] entered.
pub const SLAB_COUNT: u64 = 2500;
/// See [`SLAB_COUNT`]: T = 1e-4 is still held to ±5 % (thin absorbing
/// channels walk a few collisions a photon).
pub const SLAB_MAX_PHOTONS: usize = 1 << 22;
/// Collisions a channel's walks may take, about: a medium of reduced albedo
/// α′ walks ~1/(1 − α′) collisions a photon, so near-white media (marble,
/// milk) walk fewer photons (no fewer than 1/64 of the count).
const COLLISION_BUDGET: f64 = 6e7;
/// Gaussians of the fit: the chain's six.
pub const GAUSSIANS: usize = 6;
/// Bumped whenever what is computed changes, so old caches are not read.
const VERSION: u32 = 1;

/// A medium's tables.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MediumTables {
    /// The share of light entering that leaves again, per channel: the skin's
    /// colour where no albedo map is given.
    pub albedo: [f32; 3],
    /// The fit's variances (mm²) and per-channel weights (each channel sums to 1).
    pub gaussians: Vec<(f32, [f32; 3])>,
    /// The fit's relative r-weighted L2 error per channel (skin::fit).
    pub fit_error: [f32; 3],
    /// R(r) as a dense sum of Gaussians (skin::fit::fit_reference), what the
    /// exact-diffusion reference convolves with.
    pub reference_gaussians: Vec<(f32, [f32; 3])>,
    /// Its error, as `fit_error`.
    pub reference_error: [f32; 3],
    /// T(d) at d = max·(i/(n − 1))²: the light through a slab lit from behind
    /// that leaves its far side scattered, per photon entering, per channel.
    pub transmittance: Vec<[f32; 3]>,
    /// Thickness of the last sample, mm; beyond, T is taken as 0.
    pub max_thickness_mm: f32,
    /// Seconds the walks took when the tables were made.
    pub walk_seconds: f32,
    /// Seconds the two fits took.
    pub fit_seconds: f32,
}

impl MediumTables {
    /// Made once per process; from the cache in `cache_dir`, else computed
    /// (seconds) and stored there; a cache that cannot be written is a warning.
    pub fn load_or_compute(medium: &Medium, cache_dir: &Path) -> MediumTables {
        static MADE: Mutex<Vec<(String, MediumTables)>> = Mutex::new(Vec::new());
        let key = cache_key(medium);
        let made = |m: &Vec<(String, MediumTables)>| {
            m.iter().find(|(k, _)| *k == key).map(|(_, t)| t.clone())
        };
        if let Some(t) = made(&MADE.lock().unwrap_or_else(|e| e.into_inner())) {
            return t;
        }
        let tables = Self::from_cache_or_walk(medium, cache_dir, &key);
        MADE.lock()
            .unwrap_or_else(|e| e.into_inner())
            .push((key, tables.clone()));
        tables
    }

    fn from_cache_or_walk(medium: &Medium, cache_dir: &Path, key: &str) -> MediumTables {
        let path = cache_dir.join(format!("medium-{key}.json"));
        if let Ok(text) = std::fs::read_to_string(&path) {
            match serde_json::from_str::<MediumTables>(&text) {
                Ok(t) => {
                    log::info!("medium: loaded {}", path.display());
                    return t;
                }
                Err(e) => log::warn!("medium: ignoring {}: {e}", path.display()),
            }
        }
        let tables = MediumTables::compute(medium);
        let stored = std::fs::create_dir_all(cache_dir)
            .map_err(|e| e.to_string())
            .and_then(|()| serde_json::to_vec(&tables).map_err(|e| e.to_string()))
            .and_then(|bytes| write_atomic(&path, bytes).map_err(|e| e.to_string()));
        if let Err(e) = stored {
            log::warn!("medium: cannot cache {}: {e}", path.display());
        }
        tables
    }

    /// The walk and the fit.
    pub fn compute(medium: &Medium) -> MediumTables {
        let started = std::time::Instant::now();
        let photons = |c: usize, n: usize| {
            let collisions = 1.0 / (1.0 - f64::from(medium.reduced_albedo()[c])).max(1e-6);
            ((COLLISION_BUDGET / collisions) as usize).clamp(n / 64, n)
        };
        let radial: [Radial; 3] = [0, 1, 2]
            .map(|c| walk::radial(medium, c, photons(c, RADIAL_PHOTONS), RADIAL_BINS, false));
        let fitting = std::time::Instant::now();
        let Fit { profile, error } = fit_profile(&radial, GAUSSIANS);
        let reference = fit_reference(&radial);
        let fit_seconds = fitting.elapsed().as_secs_f32();
        let max_thickness_mm = max_thickness(medium);
        let channels = [0, 1, 2]
            .map(|c| transmittance(medium, c, max_thickness_mm, photons(c, SLAB_MAX_PHOTONS)));
        let transmittance = (0..SLAB_SAMPLES)
            .map(|i| channels.each_ref().map(|t| t[i]))
            .collect();
        MediumTables {
            albedo: radial.each_ref().map(|r| r.albedo as f32),
            gaussians: table_of(&profile),
            fit_error: error.to_array(),
            reference_gaussians: table_of(&reference.profile),
            reference_error: reference.error.to_array(),
            transmittance,
            max_thickness_mm,
            walk_seconds: started.elapsed().as_secs_f32() - fit_seconds,
            fit_seconds,
        }
    }

    /// The fitted profile (weights summing to 1 per channel).
    pub fn profile(&self) -> Profile {
        profile_of(&self.gaussians)
    }

    /// The dense profile the exact-diffusion reference convolves with.
    pub fn reference_profile(&self) -> Profile {
        profile_of(&self.reference_gaussians)
    }

    /// T(d) ÷ albedo at the samples: what the final pass's transmitted light
    /// is multiplied by the albedo after (the medium's own, or the map's
    /// colour on the medium's shape).
    pub fn transmittance_over_albedo(&self) -> Vec<Vec3> {
        let albedo = Vec3::from(self.albedo).max(Vec3::splat(1e-6));
        self.transmittance
            .iter()
            .map(|&t| Vec3::from(t) / albedo)
            .collect()
    }

    /// T(d), linear between the samples (in √d, as translucent.frag reads
    /// them), 0 past the last.
    pub fn transmittance_at(&self, d_mm: f32) -> Vec3 {
        let n = self.transmittance.len();
        if n < 2 || d_mm.is_nan() || d_mm < 0.0 || d_mm > self.max_thickness_mm {
            return Vec3::ZERO;
        }
        let x = (d_mm / self.max_thickness_mm).sqrt() * (n - 1) as f32;
        let i = (x as usize).min(n - 2);
        let f = x - i as f32;
        Vec3::from(self.transmittance[i]).lerp(Vec3::from(self.transmittance[i + 1]), f)
    }
}

fn table_of(p: &Profile) -> Vec<(f32, [f32; 3])> {
    p.gaussians
        .iter()
        .map(|g| (g.variance_mm2, g.weights.to_array()))
        .collect()
}

fn profile_of(table: &[(f32, [f32; 3])]) -> Profile {
    Profile {
        gaussians: table
            .iter()
            .map(|&(v, w)| Gaussian {
                variance_mm2: v,
                weights: Vec3::from(w),
            })
            .collect(),
    }
}

/// Channel `c`'s T(d) at the samples. Where it has fallen below
/// [`TAIL_SHARE`] of its peak, the rest follows diffusion's tail,
/// T ∝ e^(−σtr d) (Jensen et al. 2001's σtr), instead of walking millions of
/// photons for nothing.
fn transmittance(medium: &Medium, c: usize, max_mm: f32, max_photons: usize) -> Vec<f32> {
    let tr = medium.sigma_tr()[c];
    let mut t: Vec<f32> = Vec::with_capacity(SLAB_SAMPLES);
    let mut peak = 0.0f32;
    for i in 0..SLAB_SAMPLES {
        let d = max_mm * sample_position(i) as f32;
        let value = match t.last() {
            Some(&last) if i > 1 && last < TAIL_SHARE * peak => {
                let previous = max_mm * sample_position(i - 1) as f32;
                last * (-tr * (d - previous)).exp()
            }
            _ => {
                let slab = walk::slab_to_count(medium, c, f64::from(d), SLAB_COUNT, max_photons);
                slab.scattered as f32
            }
        };
        peak = peak.max(value);
        t.push(value);
    }
    t
}

/// See [`transmittance`].
const TAIL_SHARE: f32 = 1e-3;

/// Where sample i of [`SLAB_SAMPLES`] lies, as a share of the largest
/// thickness: (i/(n − 1))².
fn sample_position(i: usize) -> f64 {
    (i as f64 / (SLAB_SAMPLES - 1) as f64).powi(2)
}

/// Six diffusion lengths of the widest channel, 4 to 24 mm: T(d) has fallen
/// to e⁻⁶ of its diffusion tail there, and thin skin (an ear, a nostril's
/// wing) is a few millimetres.
fn max_thickness(medium: &Medium) -> f32 {
    (6.0 * medium.dmfp().max_element()).clamp(4.0, 24.0)
}

/// The cache file's key: the medium, the walk's settings and [`VERSION`].
pub fn cache_key(medium: &Medium) -> String {
    let text = format!(
        "v{VERSION};{};{RADIAL_PHOTONS};{RADIAL_BINS};{SLAB_SAMPLES};{SLAB_COUNT};{SLAB_MAX_PHOTONS};{GAUSSIANS};{COLLISION_BUDGET};{TAIL_SHARE}",
        medium.key()
    );
    hex(fnv1a64(text.as_bytes()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skin1_tables() {
        let m = Medium::new(
            Vec3::new(0.032, 0.17, 0.48),
            Vec3::new(0.74, 0.88, 1.01),
            0.0,
            1.4,
        );
        // Made once per machine (the GPU test in tests/it/transmission.rs reads
        // the same cache); the checks below walk afresh.
        let t = MediumTables::load_or_compute(&m, &crate::cache::default_cache_dir());
        println!(
            "skin1: albedo {:?}, fit error {:?}, reference fit error {:?}, walks {:.2} s, fits {:.2} s",
            t.albedo, t.fit_error, t.reference_error, t.walk_seconds, t.fit_seconds
        );
        t.profile().validate().unwrap();
        t.reference_profile().validate().unwrap();
        assert_eq!(t.gaussians.len(), GAUSSIANS);
        // The table at its own samples, and T between 0.5 and 5 mm against
        // independent walks (other seeds: 1/√4000 noise each).
        for d in [0.5f32, 1.0, 2.0, 3.0, 5.0] {
            let table = t.transmittance_at(d);
            let walked = [0, 1, 2].map(|c| {
                walk::slab_to_count(&m, c, f64::from(d) + 1e-7, 16_000, 1 << 24).scattered
            });
            println!("T({d} mm): table {table:.4?}, walked {walked:.4?}");
            for c in 0..3 {
                let w = walked[c] as f32;
                assert!(
                    (table[c] - w).abs() < 0.05 * w,
                    "d {d} channel {c}: {} against {w}",
                    table[c]
                );
            }
        }
        assert_eq!(t.transmittance_at(t.max_thickness_mm * 1.01), Vec3::ZERO);
        assert_eq!(t.transmittance_at(f32::NAN), Vec3::ZERO);
    }

    #[test]
    fn the_cache_is_read_back_and_keyed_by_the_medium() {
        let m = Medium::new(Vec3::splat(0.5), Vec3::splat(1.0), 0.0, 1.4);
        let other = Medium { ior: 1.3, ..m };
        assert_ne!(cache_key(&m), cache_key(&other));
        let dir = std::env::temp_dir().join(format!("dermis-medium-test-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let made = MediumTables::from_cache_or_walk(&m, &dir, &cache_key(&m));
        let path = dir.join(format!("medium-{}.json", cache_key(&m)));
        assert!(path.is_file());
        let read = MediumTables::from_cache_or_walk(&m, &dir, &cache_key(&m));
        assert_eq!(made, read);
        // A corrupt cache is ignored and made anew.
        std::fs::write(&path, "{").unwrap();
        let again = MediumTables::from_cache_or_walk(&m, &dir, &cache_key(&m));
        assert_eq!(again.albedo, made.albedo);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
