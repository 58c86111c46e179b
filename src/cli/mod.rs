//! The commands of the `dermis` binary: one module per group, one function per
//! command; `main.rs` parses and dispatches.

pub mod compare;
pub mod inspect;
pub mod medium;
pub mod reference;
pub mod render;
pub mod sweep;
pub mod view;

use std::path::Path;

/// Environment variables and exit codes, shown by every command's `--help`.
pub const AFTER_HELP: &str = "\
Environment:
  DERMIS_DEVICE=SUBSTRING   device to use (as --device)
  DERMIS_VALIDATION=1       Khronos validation + synchronization validation (as --validation)
  DERMIS_ASSETS=DIR         the assets folder (default scene, CC0 maps), searched first
  DERMIS_NO_BUILD_ASSETS=1  never fall back on the build's checkout for assets
  DERMIS_CACHE_DIR=DIR      per-vertex transfer and media tables cache (default $XDG_CACHE_HOME/dermis or ~/.cache/dermis)
  RUST_LOG=LEVEL            log filter (overrides -v)
  LP_NUM_THREADS=N          lavapipe's rasterizer threads (recorded in reports)
  DISPLAY                   the X display `dermis view` opens its window on

Exit status:
  0 success, 2 bad input (files, sizes, options), 1 anything else (device, driver,
  window system); compare and interleave with --fail-on-regression: 3 when a pass
  regressed; with --validation: 4 when the validation layer reported any warning or
  error (the run report counts them, validation_messages).";

fn to_json(path: &Path, value: &impl serde::Serialize) -> dermis::Result<String> {
    serde_json::to_string_pretty(value)
        .map_err(|e| dermis::Error::Input(format!("{}: {e}", path.display())))
}

/// Whole or not at all: a temporary file renamed into place.
fn write_file(path: &Path, text: &str) -> dermis::Result<()> {
    dermis::atomic::write_atomic(path, text)
}

/// Checks, before any work, that `flag`'s file `path` can be written: it is
/// not a folder, its extension is one of `exts` (lowercase, no dot) and its
/// folder exists. Otherwise an input error (exit 2) naming the flag and path.
fn check_output(flag: &str, path: &Path, exts: &[&str]) -> dermis::Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let folder = path.parent().map_or(Path::new("/"), or_cwd);
    if path.is_dir() {
        Err("is a folder; give a file name".into())
    } else if !ext.is_some_and(|e| exts.contains(&e.as_str())) {
        Err(format!(
            "unsupported output format (use .{})",
            exts.join(" or .")
        ))
    } else if !folder.is_dir() {
        Err(format!("the folder {} does not exist", folder.display()))
    } else {
        Ok(())
    }
    .map_err(|why| bad_output(flag, path, &why))
}

/// Checks, before any work, that `flag`'s folder `dir` exists or can be
/// created: neither it nor the nearest existing path above it is a file.
fn check_out_dir(flag: &str, dir: &Path) -> dermis::Result<()> {
    match dir.ancestors().map(or_cwd).find(|a| a.exists()) {
        Some(a) if !a.is_dir() && a == dir => Err(bad_output(flag, dir, "is a file, not a folder")),
        Some(a) if !a.is_dir() => Err(bad_output(
            flag,
            dir,
            &format!("cannot be created: {} is a file", a.display()),
        )),
        _ => Ok(()),
    }
}

/// The relative path "" (the parent of `x.png`) as ".".
fn or_cwd(p: &Path) -> &Path {
    if p.as_os_str().is_empty() {
        Path::new(".")
    } else {
        p
    }
}

fn bad_output(flag: &str, path: &Path, why: &str) -> dermis::Error {
    dermis::Error::Input(format!("{flag} {}: {why}", path.display()))
}

fn read_text(path: &Path) -> dermis::Result<String> {
    std::fs::read_to_string(path).map_err(|source| dermis::Error::Io {
        path: path.display().to_string(),
        source,
    })
}
