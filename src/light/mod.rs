//! Environment lighting: spherical harmonics (Ramamoorthi & Hanrahan 2001; the
//! paper's section III). Environment maps and the sky are in `scene::env`.

pub mod direct;
pub mod occlusion;
pub mod occlusion_raster;
pub mod prefilter;
pub mod sh;
pub mod sh_pass;
pub mod shadow;
pub mod skybox;

use crate::error::Result;
use crate::gpu::Context;
use crate::scene::file::Occlusion;
use crate::scene::mesh::Mesh;
use occlusion::{RayOptions, Transfer};
use occlusion_raster::RasterOptions;
use std::sync::Arc;

/// The per-vertex SH transfer for `mode` (unoccluded for `Off`), from the disk
/// cache when it holds it (keyed by the mesh, the method and its settings).
pub fn transfer_for(ctx: &Arc<Context>, mesh: &Mesh, mode: Occlusion) -> Result<Transfer> {
    let (method, settings) = match mode {
        Occlusion::Off => return Ok(occlusion::unoccluded(mesh)),
        Occlusion::Raytrace => ("raytrace", RayOptions::default().cache_settings()),
        Occlusion::Raster => ("raster", RasterOptions::default().cache_settings()),
    };
    let key = occlusion::cache_key(mesh, method, &settings);
    let dir = occlusion::default_cache_dir();
    if let Some(t) = occlusion::load_cached(&dir, &key) {
        log::info!(
            "occlusion: cached {method} transfer {key} from {}",
            dir.display()
        );
        return Ok(t);
    }
    let started = std::time::Instant::now();
    let t = match mode {
        Occlusion::Raster => occlusion_raster::raster(ctx, mesh, &RasterOptions::default(), true)?,
        _ => occlusion::raytrace(mesh, &RayOptions::default(), true),
    };
    log::info!(
        "occlusion: {method} for {} vertices in {:.2} s",
        mesh.vertex_count(),
        started.elapsed().as_secs_f64()
    );
    if let Err(e) = occlusion::store_cached(&dir, &key, &t) {
        log::warn!("occlusion: cannot cache in {}: {e}", dir.display());
    }
    Ok(t)
}
