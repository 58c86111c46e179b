//! The repository's own assets (`assets/`, see its README: the Lee Perry-Smith scan,
//! CC BY 3.0, CC0 environment maps, the default scene), located for the default
//! scene, tests, benches and examples. One helper for unit and integration tests
//! alike: a missing asset fails the test that needs it, naming the file.

use std::path::{Path, PathBuf};

/// The `assets/` directory of this checkout.
pub fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets")
}

/// `assets/<relative>`, which must exist.
///
/// # Panics
/// When the file is missing, with its path: the repository carries every asset.
pub fn path(relative: &str) -> PathBuf {
    let p = dir().join(relative);
    assert!(
        p.exists(),
        "asset {} is missing: the repository carries it (assets/README.md)",
        p.display()
    );
    p
}

/// The six CC0 environment maps of `assets/env/`.
pub const ENV_MAPS: [&str; 6] = [
    "royal_esplanade_1k.hdr",
    "venice_sunset_1k.hdr",
    "pedestrian_overpass_1k.hdr",
    "quarry_01_1k.hdr",
    "studio.exr",
    "sunset.exr",
];

/// The Lee Perry-Smith scan's directory.
pub fn scan() -> PathBuf {
    path("head/lee-perry-smith")
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_listed_asset_is_present() {
        for name in super::ENV_MAPS {
            assert!(super::path(&format!("env/{name}")).is_file());
        }
        assert!(super::scan().join("LeePerrySmith.glb").is_file());
    }

    #[test]
    #[should_panic(expected = "is missing")]
    fn a_missing_asset_fails_loudly() {
        super::path("env/no-such-map.hdr");
    }
}
