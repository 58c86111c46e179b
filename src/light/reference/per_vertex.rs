//! The reference irradiance at every vertex of a mesh.

use rayon::prelude::*;

use super::integrate::{Estimate, Integrator, Settings};
use crate::scene::env::EnvMap;
use crate::scene::mesh::Mesh;
use crate::scene::Light;

/// E at every vertex of `mesh` (its position and vertex normal, which also
/// lifts the shadow rays) under `env` turned by `rotation_deg` about +Y (as
/// `environment.rotation_deg`), scaled by `intensity`, plus `lights`, with the
/// mesh itself as the only occluder. One BVH for the call; vertices run in
/// parallel, each with its own random stream (vertex index and `settings.seed`),
/// so the result does not depend on the thread count. A vertex without a
/// finite position and normal gets [`Estimate::NONE`].
pub fn per_vertex(
    mesh: &Mesh,
    env: &EnvMap,
    rotation_deg: f32,
    intensity: f32,
    lights: &[Light],
    settings: &Settings,
) -> Vec<Estimate> {
    let integrator = Integrator::new(mesh, env, rotation_deg, intensity, lights, settings);
    (0..mesh.vertex_count())
        .into_par_iter()
        .map(|i| {
            let p = mesh.positions[i];
            match mesh.normals.get(i).and_then(|n| n.try_normalize()) {
                Some(n) if p.is_finite() => integrator.irradiance(p, n, n, i as u64),
                _ => Estimate::NONE,
            }
        })
        .collect()
}
