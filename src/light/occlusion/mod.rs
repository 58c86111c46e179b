//! Per-vertex SH visibility transfer: by CPU ray casting or by the paper's cube
//! maps on the GPU, and its disk cache.
//!
//! # What is computed
//! Yang, Wang & Zuo 2012 eq. 12–13: the diffuse irradiance at a vertex is
//! `E = ∫_S L(ω) V(ω) max(N·ω, 0) dω = Σ_i L_i T_i` with the transfer vector
//! ```text
//! T_i = ∫_S V(ω) · max(N·ω, 0) · y_i(ω) dω ,   i = 0..8
//! ```
//! (`y_i` = [`sh::basis`](crate::light::sh::basis), world axes). With `V ≡ 1`,
//! `T = sh::cosine_transfer(N)` ([`unoccluded`], the `--occlusion off` case).
//! The paper evaluates `V` by rasterising a cube map at each vertex
//! ([`raster`]); [`raytrace()`] instead casts rays against a BVH of the mesh's
//! triangles (any-hit queries).
//!
//! # Files
//! `transfer.rs` ([`Transfer`]), `raytrace.rs` (the CPU estimator), `lobe.rs`
//! (the environment specular's occlusion: the visibility's SH, read through a
//! lobe about the mirror direction), `bvh.rs`
//! (the [`Bvh`] it queries), `raster.rs` (the GPU method), `cache.rs` (the disk
//! cache, [`cache_key`]); [`transfer_for`] picks one, cache first.

mod bvh;
mod cache;
mod lobe;
pub mod raster;
mod raytrace;
#[cfg(test)]
pub(crate) mod testutil;
mod transfer;

pub use bvh::{Bvh, Hit};
pub use cache::{
    cache_key, default_cache_dir, load_cached, rgb_cached, store_cached, store_failures,
};
pub use lobe::{
    above, kappa, lobe_raytrace, lobe_visibility, lobe_visibility_for, open as open_lobe, zonal,
};
pub(crate) use raytrace::directions;
pub use raytrace::{raytrace, RayOptions};
pub use transfer::{unoccluded, RgbTransfer, Transfer};

use std::sync::Arc;

use crate::error::Result;
use crate::gpu::Context;
use crate::scene::file::Occlusion;
use crate::scene::mesh::Mesh;
use raster::RasterOptions;

/// `mode`'s method name and cache settings; `None` for `Off` (computed, never cached).
fn method(mode: Occlusion) -> Option<(&'static str, String)> {
    match mode {
        Occlusion::Off => None,
        Occlusion::Raytrace => Some(("raytrace", RayOptions::default().cache_settings())),
        Occlusion::Raster => Some(("raster", RasterOptions::default().cache_settings())),
    }
}

/// The cache key of `mode`'s transfer of `mesh` (the mesh, the method and its
/// settings); `None` for `Off`.
pub fn transfer_key(mesh: &Mesh, mode: Occlusion) -> Option<String> {
    method(mode).map(|(method, settings)| cache_key(mesh, method, &settings))
}

/// The per-vertex SH transfer for `mode` (unoccluded for `Off`), from the disk
/// cache when it holds it ([`transfer_key`]).
pub fn transfer_for(ctx: &Arc<Context>, mesh: &Mesh, mode: Occlusion) -> Result<Transfer> {
    let Some((method, settings)) = method(mode) else {
        return Ok(unoccluded(mesh));
    };
    let key = cache_key(mesh, method, &settings);
    let dir = default_cache_dir();
    if let Some(t) = load_cached(&dir, &key) {
        log::info!(
            "occlusion: cached {method} transfer {key} from {}",
            dir.display()
        );
        return Ok(t);
    }
    let started = std::time::Instant::now();
    let t = match mode {
        Occlusion::Raster => raster::raster(ctx, mesh, &RasterOptions::default(), true)?,
        _ => raytrace(mesh, &RayOptions::default(), true),
    };
    log::info!(
        "occlusion: {method} for {} vertices in {:.2} s",
        mesh.vertex_count(),
        started.elapsed().as_secs_f64()
    );
    if let Err(e) = store_cached(&dir, &key, &t) {
        log::warn!("occlusion: cannot cache in {}: {e}", dir.display());
    }
    Ok(t)
}
