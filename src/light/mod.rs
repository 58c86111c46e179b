//! Environment lighting: environment maps and the built-in sky, spherical
//! harmonics (Ramamoorthi & Hanrahan 2001; the paper's section III).

pub mod envmap;
pub mod occlusion;
pub mod prefilter;
pub mod sh;
pub mod sh_pass;
pub mod shadow;
pub mod sky;
