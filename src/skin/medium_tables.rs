//! What the skin passes take from a medium (skin::medium), computed once by the
//! random walk (skin::walk) and cached by the medium's key: its albedo, its
//! R(r) fitted by the chain's six Gaussians (skin::fit), and its transmission
//! through a slab by thickness, T(d), as a table the translucent pass reads.

use crate::atomic::write_atomic;
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
/// Photons per channel and slab thickness: T = 0.1 is held to ±1.7 %.
pub const SLAB_PHOTONS: usize = 1 << 15;
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
        let transmittance = (0..SLAB_SAMPLES)
            .map(|i| {
                let d = f64::from(max_thickness_mm) * sample_position(i);
                [0, 1, 2]
                    .map(|c| walk::slab(medium, c, d, photons(c, SLAB_PHOTONS)).scattered as f32)
            })
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

/// Where sample i of [`SLAB_SAMPLES`] lies, as a share of the largest
/// thickness: (i/(n − 1))².
fn sample_position(i: usize) -> f64 {
    (i as f64 / (SLAB_SAMPLES - 1) as f64).powi(2)
}

/// Eight diffusion lengths of the widest channel, 4 to 40 mm: T(d) has fallen
/// to e⁻⁸ of its diffusion tail there.
fn max_thickness(medium: &Medium) -> f32 {
    (8.0 * medium.dmfp().max_element()).clamp(4.0, 40.0)
}

/// The cache file's key: the medium, the walk's settings and [`VERSION`].
pub fn cache_key(medium: &Medium) -> String {
    let text = format!(
        "v{VERSION};{};{RADIAL_PHOTONS};{RADIAL_BINS};{SLAB_SAMPLES};{SLAB_PHOTONS};{GAUSSIANS};{COLLISION_BUDGET}",
        medium.key()
    );
    // FNV-1a 64.
    let h = text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    });
    format!("{h:016x}")
}
