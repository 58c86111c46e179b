//! Where dermis keeps what it computes once and reuses: the occlusion
//! transfers, the media's tables.

use std::path::PathBuf;

/// `$DERMIS_CACHE_DIR`, else `$XDG_CACHE_HOME/dermis` (if absolute), else
/// `$HOME/.cache/dermis`, else `<temp dir>/dermis-cache`.
pub fn default_cache_dir() -> PathBuf {
    let var = |k: &str| {
        std::env::var_os(k)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    if let Some(d) = var("DERMIS_CACHE_DIR") {
        return d;
    }
    if let Some(d) = var("XDG_CACHE_HOME").filter(|d| d.is_absolute()) {
        return d.join("dermis");
    }
    if let Some(h) = var("HOME") {
        return h.join(".cache").join("dermis");
    }
    std::env::temp_dir().join("dermis-cache")
}
