//! [`SceneError`]: what can go wrong reading scene input.

use std::path::{Path, PathBuf};

/// Everything that can go wrong reading scene input (scene file, mesh, textures).
/// Each message is a single line that starts with the offending file.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be opened or read.
    #[error("{}: cannot read file: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// TOML syntax or a field of the wrong name or type (line and column are 1-based).
    #[error("{}: line {line}, column {column}: {message}", path.display())]
    Toml {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    /// A scene value out of its valid range; the message names the key.
    #[error("{}: {message}", path.display())]
    Invalid { path: PathBuf, message: String },
    /// A mesh file that cannot be used.
    #[error("{}: {message}", path.display())]
    Mesh { path: PathBuf, message: String },
    /// The repository's assets (the default scene) are nowhere dermis looked.
    #[error("{0}")]
    Assets(String),
    /// A texture file that cannot be used.
    #[error("{}: {message}", path.display())]
    Texture { path: PathBuf, message: String },
}

impl From<SceneError> for crate::error::Error {
    fn from(e: SceneError) -> Self {
        crate::error::Error::BadInput(Box::new(e))
    }
}

impl SceneError {
    pub(crate) fn invalid(path: &Path, message: impl AsRef<str>) -> SceneError {
        SceneError::Invalid {
            path: path.to_path_buf(),
            message: one_line(message.as_ref()),
        }
    }

    pub(crate) fn mesh(path: &Path, message: impl AsRef<str>) -> SceneError {
        SceneError::Mesh {
            path: path.to_path_buf(),
            message: one_line(message.as_ref()),
        }
    }

    pub(crate) fn texture(path: &Path, message: impl AsRef<str>) -> SceneError {
        SceneError::Texture {
            path: path.to_path_buf(),
            message: one_line(message.as_ref()),
        }
    }
}

/// Collapses any run of whitespace (including newlines) to one space.
pub(super) fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}
