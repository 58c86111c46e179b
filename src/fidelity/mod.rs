//! `dermis reference`: how close the GPU renderer comes to the CPU reference
//! renderers (light::reference, skin::reference). The lighting gap compares the
//! direct term with a path-traced reference; the diffusion gap compares the
//! texture-space chain with the exact diffusion over the surface.

pub mod diffusion_gap;
pub mod lighting_gap;
