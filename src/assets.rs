//! The repository's own assets (`assets/`, see its README: the Lee Perry-Smith scan,
//! CC BY 3.0, CC0 environment maps, the default scene).
//!
//! The binary finds them by [`find`], searching in order (README, "Assets"):
//! 1. `$DERMIS_ASSETS` (a folder);
//! 2. `assets/` in the current directory (a checkout);
//! 3. beside the executable: `<exe dir>/assets`, then `<exe dir>/../share/dermis/assets`;
//! 4. the checkout the binary was built in (its path compiled in), unless
//!    `DERMIS_NO_BUILD_ASSETS=1`.
//!
//! The first folder that holds the file wins; none is an input error listing
//! where it looked. Tests, benches and examples use [`dir`] and [`path`]: this
//! checkout, a missing asset failing the test that needs it, naming the file.

use std::path::{Path, PathBuf};

/// The assets folder to search first.
pub const ASSETS_VAR: &str = "DERMIS_ASSETS";
/// `1`: never fall back on the build's checkout (a binary run elsewhere).
pub const NO_BUILD_ASSETS_VAR: &str = "DERMIS_NO_BUILD_ASSETS";

/// The `assets/` directory of this checkout (compiled in).
pub fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets")
}

/// `assets/<relative>` of this checkout, which must exist (tests).
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

/// The folders [`find`] searches, in order, made absolute.
pub fn search_path() -> Vec<PathBuf> {
    let mut dirs = Vec::new();
    if let Some(d) = std::env::var_os(ASSETS_VAR).filter(|d| !d.is_empty()) {
        dirs.push(PathBuf::from(d));
    }
    dirs.push(PathBuf::from("assets"));
    if let Some(exe_dir) = std::env::current_exe()
        .ok()
        .and_then(|e| e.parent().map(Path::to_path_buf))
    {
        dirs.push(exe_dir.join("assets"));
        if let Some(prefix) = exe_dir.parent() {
            dirs.push(prefix.join("share/dermis/assets"));
        }
    }
    if std::env::var_os(NO_BUILD_ASSETS_VAR).is_none_or(|v| v != "1") {
        dirs.push(dir());
    }
    dirs.into_iter()
        .map(|d| std::path::absolute(&d).unwrap_or(d))
        .collect()
}

/// `<folder>/<relative>` for the first folder of [`search_path`] that holds it
/// (absolute); else a message naming every folder searched.
///
/// `$DERMIS_ASSETS` set to something that is not a folder (a typo) is an error
/// rather than a silent fallback on the other folders.
pub fn find(relative: &str) -> Result<PathBuf, String> {
    if let Some(d) = std::env::var_os(ASSETS_VAR).filter(|d| !d.is_empty()) {
        let d = PathBuf::from(d);
        if !d.is_dir() {
            return Err(format!(
                "{ASSETS_VAR}={} is not a folder: set it to the assets folder of a dermis \
                 checkout, or unset it to search ./assets, beside the executable and the build's \
                 checkout",
                d.display()
            ));
        }
    }
    find_in(&search_path(), relative)
}

/// [`find`] over the given folders.
pub fn find_in(dirs: &[PathBuf], relative: &str) -> Result<PathBuf, String> {
    dirs.iter()
        .map(|d| d.join(relative))
        .find(|p| p.is_file())
        .ok_or_else(|| {
            let searched: Vec<String> = dirs.iter().map(|d| d.display().to_string()).collect();
            format!(
                "asset {relative} not found; searched {} (set {ASSETS_VAR} to the assets \
                 folder of a dermis checkout, or use --scene builtin)",
                searched.join(", ")
            )
        })
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
    use std::path::PathBuf;

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

    #[test]
    fn the_search_takes_the_first_folder_holding_the_file() {
        let empty = std::env::temp_dir().join(format!("dermis-assets-{}", std::process::id()));
        std::fs::create_dir_all(&empty).unwrap();
        let dirs = [empty.clone(), super::dir()];
        assert_eq!(
            super::find_in(&dirs, "default.toml").unwrap(),
            super::dir().join("default.toml")
        );
        let e = super::find_in(&[empty.clone(), PathBuf::from("/no/such")], "default.toml")
            .unwrap_err();
        assert!(
            e.contains(&empty.display().to_string()) && e.contains("/no/such"),
            "{e}"
        );
        assert!(e.contains(super::ASSETS_VAR), "{e}");
    }
}
