//! A CPU reference for diffuse irradiance:
//! Monte Carlo integration of the environment map (multiple importance
//! sampling of the map and the cosine lobe, shadow rays against the mesh) and
//! the explicit lights, sampled until the estimate's standard error is below
//! 0.5 %. docs/lighting.md, "Reference integrator".
//!
//! - [`per_vertex`]: E at every vertex of a mesh;
//! - [`EnvSampler`]: importance sampling of an equirect map by luminance.
//!
//! Files: `env_sampler.rs`, `integrate.rs` (the estimator, [`Settings`],
//! [`Estimate`]), `per_vertex.rs`, `sequence.rs` (random numbers).

mod env_sampler;
mod integrate;
mod per_vertex;
mod sequence;
#[cfg(test)]
mod test_meshes;

pub use env_sampler::{luminance, EnvSampler};
pub use integrate::{Estimate, Settings};
pub use per_vertex::per_vertex;
