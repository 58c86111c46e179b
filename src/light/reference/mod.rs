//! A CPU reference for diffuse irradiance and for the `--view direct` image:
//! Monte Carlo integration of the environment map (multiple importance
//! sampling of the map and the cosine lobe, shadow rays against the mesh) and
//! the explicit lights, sampled until the estimate's standard error is below
//! 0.5 %. docs/design/lighting.md, "Reference integrator".
//!
//! - [`per_vertex`]: E at every vertex of a mesh;
//! - [`render_view`]: `albedo/π · E` per pixel through the scene's camera, the
//!   environment behind;
//! - [`EnvSampler`]: importance sampling of an equirect map by luminance.
//!
//! Files: `env_sampler.rs`, `integrate.rs` (the estimator, [`Settings`],
//! [`Estimate`]), `per_vertex.rs`, `image.rs`, `texture.rs` (bilinear lookups as
//! the GPU's samplers do them), `sequence.rs` (random numbers).

mod env_sampler;
mod image;
mod integrate;
mod per_vertex;
mod sequence;
#[cfg(test)]
mod test_meshes;
mod texture;

pub use env_sampler::{luminance, EnvSampler};
pub use image::{render_view, render_view_with, ReferenceImage};
pub use integrate::{Estimate, Settings};
pub use per_vertex::per_vertex;
pub use texture::{bilinear, rgba8};
