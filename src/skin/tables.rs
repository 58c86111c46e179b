//! The specular term's GPU inputs (GPU Gems 3 §14.3): the Beckmann table D(N·H, m),
//! the specular albedo table A(cos θ, m) for energy conservation, both computed by
//! dermis at start-up (skin/specular.rs), and the map of (ρs, m) blended from the
//! face regions' parameters.

use super::specular::{self, Lobe};
use crate::atomic::write_atomic;
use crate::cache::{default_cache_dir, fnv1a64_parts, hex};
use crate::error::Result;
use crate::frame_inputs::FrameInputs;
use crate::gpu::{Context, Image, ImageDesc, Sampler};
use crate::graph::upload::upload_texture;
use crate::graph::SimplePass;
use crate::scene::file::{SpecularRegion, REGION_COUNT};
use crate::scene::texture::Texture;
use ash::vk;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// 256² keeps linear interpolation of D within ~0.5 % over the lobe at m = 0.3.
pub const BECKMANN_SIZE: usize = 256;
/// 64 × 64, as recommended by the ρdt accuracy tests (skin/specular.rs).
pub const ALBEDO_SIZE: usize = 64;

/// d'Eon's PH(N·H, m) = π·D (specular::beckmann_ph), endpoint-inclusive: row
/// m = j/(n−1), column N·H = i/(n−1) (see `specular::table_point`). m = 0 is a
/// Dirac lobe: stored as 0.
pub fn beckmann_table(n: usize) -> Vec<f32> {
    (0..n * n)
        .map(|k| {
            let (c, m) = (
                specular::table_point(k % n, n),
                specular::table_point(k / n, n),
            );
            if m > 0.0 {
                specular::beckmann_ph(c, m)
            } else {
                0.0
            }
        })
        .collect()
}

/// The specular's directional albedo A(cos θ, m) (specular::specular_albedo_lut,
/// n × n) with its cosine-weighted mean over incidence Ā(m)
/// (specular::hemispherical_albedo: what the environment's SH irradiance, whose
/// incidence angles are lost, gives the specular) beside it in every texel of a
/// row: interleaved (A, Ā), so the final pass reads both in one fetch. Both of
/// the lobe's (skin::SkinSettings::lobe).
pub fn albedo_table(n: usize, lobe: Lobe) -> Vec<f32> {
    let a = lobe.albedo_lut(n, n, 256, 64);
    let mean: Vec<f32> = (0..n)
        .into_par_iter()
        .map(|j| lobe.hemispherical_albedo(specular::table_point(j, n)))
        .collect();
    a.iter()
        .enumerate()
        .flat_map(|(k, &a)| [a, mean[k / n]])
        .collect()
}

/// Bump when [`albedo_table`]'s values change for the same lobe and size
/// (its quadrature, the lobes' formulas): the cached files' key includes it.
const ALBEDO_TABLE_VERSION: u32 = 1;

/// [`albedo_table`] made once per process and kept in `cache_dir`: its 200 M
/// integrand evaluations are about a second of CPU at every start-up
/// otherwise.
pub fn cached_albedo_table(n: usize, lobe: Lobe, cache_dir: &Path) -> Arc<[f32]> {
    static MADE: Mutex<Vec<(PathBuf, Arc<[f32]>)>> = Mutex::new(Vec::new());
    let path = albedo_table_file(n, lobe, cache_dir);
    let made =
        |m: &Vec<(PathBuf, Arc<[f32]>)>| m.iter().find(|(p, _)| *p == path).map(|(_, t)| t.clone());
    if let Some(t) = made(&MADE.lock().unwrap_or_else(|e| e.into_inner())) {
        return t;
    }
    let table: Arc<[f32]> = load_or_compute_albedo_table(&path, n, lobe).into();
    MADE.lock()
        .unwrap_or_else(|e| e.into_inner())
        .push((path, table.clone()));
    table
}

/// `specular-albedo-<key>.json` in `cache_dir`, the key a hash of the lobe,
/// the size and [`ALBEDO_TABLE_VERSION`].
fn albedo_table_file(n: usize, lobe: Lobe, cache_dir: &Path) -> PathBuf {
    let form: u8 = match lobe {
        Lobe::Ks { .. } => 0,
        Lobe::Dielectric { .. } => 1,
    };
    let key = fnv1a64_parts([
        &ALBEDO_TABLE_VERSION.to_le_bytes()[..],
        &[form],
        &lobe.parameter().to_bits().to_le_bytes(),
        &(n as u64).to_le_bytes(),
    ]);
    cache_dir.join(format!("specular-albedo-{}.json", hex(key)))
}

/// The table in `path`, else computed and stored there. A file that does not
/// parse, has the wrong length or a negative value is a warning and is
/// replaced; one that cannot be written is a warning.
fn load_or_compute_albedo_table(path: &Path, n: usize, lobe: Lobe) -> Vec<f32> {
    if let Ok(bytes) = std::fs::read(path) {
        match serde_json::from_slice::<Vec<f32>>(&bytes) {
            Ok(t) if t.len() == 2 * n * n && t.iter().all(|v| v.is_finite() && *v >= 0.0) => {
                return t
            }
            Ok(t) => log::warn!(
                "specular: ignoring {}: {} values, not {} finite and non-negative",
                path.display(),
                t.len(),
                2 * n * n
            ),
            Err(e) => log::warn!("specular: ignoring {}: {e}", path.display()),
        }
    }
    let t = albedo_table(n, lobe);
    let stored = path
        .parent()
        .map_or(Ok(()), std::fs::create_dir_all)
        .map_err(|e| e.to_string())
        .and_then(|()| serde_json::to_vec(&t).map_err(|e| e.to_string()))
        .and_then(|bytes| write_atomic(path, bytes).map_err(|e| e.to_string()));
    if let Err(e) = stored {
        log::warn!("specular: cannot cache {}: {e}", path.display());
    }
    t
}

pub struct SpecularTables {
    pub beckmann: Arc<Image>,
    /// [`albedo_table`]: (A(cos θ, m), Ā(m)) of the lobe, RG32F.
    pub albedo: Arc<Image>,
    /// (ρs, m) per region-map texel, blended across region borders
    /// (specular::region_params_map), RGBA16F.
    pub params: Arc<Image>,
    /// Linear where the device filters R32F and RG32F, else nearest.
    pub sampler: Arc<Sampler>,
}

impl SpecularTables {
    /// `lobe`: the specular lobe the albedo table integrates.
    pub fn new(
        ctx: &Arc<Context>,
        regions: &[SpecularRegion],
        lobe: Lobe,
        region_map: &Texture,
        linear: Arc<Sampler>,
        nearest: Arc<Sampler>,
    ) -> Result<Self> {
        let table = |name: &str, (w, h): (usize, usize), format, values: Vec<f32>| {
            let desc = ImageDesc::new(w as u32, h as u32, format);
            upload_texture(ctx, name, desc, bytemuck::cast_slice(&values))
        };
        let params: Vec<[f32; 2]> = (0..REGION_COUNT)
            .map(|i| {
                regions
                    .get(i)
                    .map_or([specular::DEFAULT_RHO_S, specular::DEFAULT_M], |r| {
                        [r.rho_s, r.m]
                    })
            })
            .collect();
        let (w, h) = (region_map.width, region_map.height);
        let map: Vec<u8> = specular::region_params_map(w, h, &region_map.rgba8, &params)
            .iter()
            .flat_map(|&[rho_s, m]| [rho_s, m, 0.0, 1.0])
            .flat_map(|v| half::f16::from_f32(v).to_le_bytes())
            .collect();
        Ok(Self {
            beckmann: table(
                "beckmann table",
                (BECKMANN_SIZE, BECKMANN_SIZE),
                vk::Format::R32_SFLOAT,
                beckmann_table(BECKMANN_SIZE),
            )?,
            albedo: table(
                "specular albedo table",
                (ALBEDO_SIZE, ALBEDO_SIZE),
                vk::Format::R32G32_SFLOAT,
                cached_albedo_table(ALBEDO_SIZE, lobe, &default_cache_dir()).to_vec(),
            )?,
            params: upload_texture(
                ctx,
                "specular parameters",
                ImageDesc::new(w, h, vk::Format::R16G16B16A16_SFLOAT),
                &map,
            )?,
            sampler: if ctx.supports_linear_filter(vk::Format::R32_SFLOAT)
                && ctx.supports_linear_filter(vk::Format::R32G32_SFLOAT)
            {
                linear
            } else {
                nearest
            },
        })
    }

    /// Declares the five bindings of common/ks_specular.glsl, in its order: the
    /// Beckmann and albedo tables, the region parameter, intensity and roughness maps.
    pub fn bind<'g>(&self, pass: SimplePass<'g>, inputs: &FrameInputs) -> SimplePass<'g> {
        let s = &inputs.samplers;
        pass.texture(&self.beckmann, &self.sampler)
            .texture(&self.albedo, &self.sampler)
            .texture(&self.params, &s.nearest)
            .texture(&inputs.specular, &s.linear)
            .texture(&inputs.roughness, &s.linear)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_albedo_table_holds_a_and_its_mean_per_row() {
        let n = 8;
        for lobe in [Lobe::PAPER, Lobe::Dielectric { ior: 1.4 }] {
            let t = albedo_table(n, lobe);
            let a = lobe.albedo_lut(n, n, 256, 64);
            assert_eq!(t.len(), 2 * n * n);
            for (k, pair) in t.chunks_exact(2).enumerate() {
                assert_eq!(pair[0], a[k]);
                let m = specular::table_point(k / n, n);
                assert_eq!(pair[1], lobe.hemispherical_albedo(m), "texel {k}");
            }
        }
        // The paper's table is d'Eon's at his F0.
        let ks = specular::specular_albedo_lut(n, n, 256, 64, specular::F0_SKIN);
        assert_eq!(albedo_table(n, Lobe::PAPER)[2], ks[1]);
    }

    #[test]
    fn the_albedo_table_is_kept_on_disk_and_a_damaged_file_is_replaced() {
        let dir = std::env::temp_dir().join(format!("dermis-albedo-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let (n, lobe) = (5, Lobe::Dielectric { ior: 1.4 });
        let path = albedo_table_file(n, lobe, &dir);
        assert_ne!(
            path,
            albedo_table_file(n, Lobe::Dielectric { ior: 1.41 }, &dir)
        );
        assert_ne!(path, albedo_table_file(n, Lobe::Ks { f0: 1.4 }, &dir));
        assert_ne!(path, albedo_table_file(n + 1, lobe, &dir));
        let want = albedo_table(n, lobe);
        let read =
            |p: &Path| serde_json::from_slice::<Vec<f32>>(&std::fs::read(p).unwrap()).unwrap();
        // Computed and stored exactly.
        assert_eq!(load_or_compute_albedo_table(&path, n, lobe), want);
        assert_eq!(read(&path), want);
        // What the file holds is what a later start-up gets.
        let marked = vec![0.5f32; 2 * n * n];
        std::fs::write(&path, serde_json::to_vec(&marked).unwrap()).unwrap();
        assert_eq!(load_or_compute_albedo_table(&path, n, lobe), marked);
        // A truncated, short, foreign or impossible file is computed afresh
        // and replaced.
        let negative = serde_json::to_vec(&vec![-0.5f32; 2 * n * n]).unwrap();
        for damage in [&b"[0.5, 0.25"[..], b"[0.5]", b"not json", &negative] {
            std::fs::write(&path, damage).unwrap();
            assert_eq!(load_or_compute_albedo_table(&path, n, lobe), want);
            assert_eq!(read(&path), want);
        }
        // The process's memo answers for the same file.
        let a = cached_albedo_table(n, lobe, &dir);
        std::fs::remove_file(&path).unwrap();
        assert!(Arc::ptr_eq(&a, &cached_albedo_table(n, lobe, &dir)));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
