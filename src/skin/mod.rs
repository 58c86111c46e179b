//! The paper's skin model: the sum-of-Gaussians diffusion profile and the
//! Kelemen/Szirmay-Kalos specular term (d'Eon & Luebke, GPU Gems 3 ch. 14).

pub mod profile;
pub mod specular;
