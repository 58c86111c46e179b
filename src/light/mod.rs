//! Environment lighting: spherical harmonics (Ramamoorthi & Hanrahan 2001; the
//! paper's section III), and the bright sources taken out of the map as lights
//! (`extract`). Environment maps and the sky are in `scene::env`.

pub mod direct;
pub mod extract;
pub mod interreflection;
pub mod lighting;
pub mod occlusion;
pub mod prefilter;
pub mod reference;
pub mod sh;
pub mod sh_pass;
pub mod shadow;
pub mod skybox;
pub mod transmission;
pub mod visibility;

/// The tag of the lighting passes (SH, prefilter, shadows, direct lighting).
pub const TAG: &str = "lighting";
