//! The environment as CPU-side scene input: the source grammar (`source.rs`),
//! lat-long maps (`map.rs`), file decoding (`decode.rs`), cube maps (`cube.rs`)
//! and the analytic sky (`sky.rs`). Files depend on each other only downward:
//! `source` → `decode` → `cube` → `map`; `source` → `sky` → `map`; `error` names
//! `map`'s limits and wraps `sky`'s errors.

pub mod cube;
pub mod decode;
pub mod error;
pub mod map;
pub mod sky;
pub mod source;

pub use cube::cube_face_st;
pub use decode::{load, load_cube_faces};
pub use error::EnvError;
pub(crate) use map::texel_solid_angle_f64;
pub use map::{
    direction, direction_to_uv, sanitize, texel_solid_angle, EnvMap, SanitizeReport, HALF_MAX,
    MAX_TEXELS, MAX_WIDTH,
};
pub use sky::{SkyError, SkyParams};
pub use source::{resolve, EnvSource};
