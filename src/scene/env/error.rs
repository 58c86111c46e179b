//! [`EnvError`]: everything that can go wrong loading or resolving an environment.
//! Its own file because it wraps the sky's [`SkyError`] while the sky builds on
//! `map.rs` (keeps the files acyclic).

use std::path::PathBuf;

use super::map::{MAX_TEXELS, MAX_WIDTH};
use super::sky::SkyError;

/// Errors from loading or resolving an environment. Every message is one line
/// and names the file (or the source string) and the problem.
#[derive(Debug, thiserror::Error)]
pub enum EnvError {
    #[error("{path}: file not found")]
    NotFound { path: PathBuf },
    #[error("{path}: cannot read file: {detail}")]
    Io { path: PathBuf, detail: String },
    #[error("{path}: unknown extension (expected .hdr or .exr)")]
    UnknownExtension { path: PathBuf },
    #[error("{path}: truncated or corrupt data: {detail}")]
    Corrupt { path: PathBuf, detail: String },
    #[error(
        "{path}: unsupported aspect ratio {width}x{height} \
         (expected 2:1 equirect, 4:3 horizontal cross or 3:4 vertical cross)"
    )]
    Aspect {
        path: PathBuf,
        width: u64,
        height: u64,
    },
    #[error(
        "{path}: image size {width}x{height} is too large \
         (at most {MAX_WIDTH} wide and {MAX_TEXELS} texels)"
    )]
    TooLarge {
        path: PathBuf,
        width: u64,
        height: u64,
    },
    #[error("{path}: no R, G, B channels found in any layer")]
    NoRgb { path: PathBuf },
    #[error("{path}: bad cube face: {detail}")]
    CubeFace { path: PathBuf, detail: String },
    #[error("environment source '{source_str}': {detail}")]
    BadSource { source_str: String, detail: String },
    #[error("environment size {width}x{height} is invalid (need 1..={MAX_WIDTH} wide, at most {MAX_TEXELS} texels)")]
    BadSize { width: u32, height: u32 },
    #[error("sky: {0}")]
    Sky(#[from] SkyError),
}

impl From<EnvError> for crate::error::Error {
    fn from(e: EnvError) -> Self {
        crate::error::Error::BadInput(Box::new(e))
    }
}
