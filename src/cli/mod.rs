//! The commands of the `dermis` binary: one module per group, one function per
//! command; `main.rs` parses and dispatches.

/// `println!` that never panics: standard output closed by its reader (`dermis
/// … | head -1`) or failing drops what is printed from then on, and the work
/// goes on (every file is still written whole; the exit status is the work's).
macro_rules! outln {
    ($($t:tt)*) => { $crate::cli::stdout(format_args!("{}\n", format_args!($($t)*))) };
}

/// `print!` as [`outln!`] does it.
macro_rules! out {
    ($($t:tt)*) => { $crate::cli::stdout(format_args!($($t)*)) };
}

pub mod compare;
pub mod inspect;
pub mod manual;
pub mod medium;
pub mod reference;
pub mod render;
pub mod sweep;
pub mod view;

use std::io::Write;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

/// Set once standard output could not be written: nothing more is tried.
static STDOUT_GONE: AtomicBool = AtomicBool::new(false);

/// Writes to standard output, flushed; a closed pipe (EPIPE) drops this and
/// all later output silently, any other failure with one warning.
pub fn stdout(text: std::fmt::Arguments) {
    if STDOUT_GONE.load(Ordering::Relaxed) {
        return;
    }
    let mut o = std::io::stdout().lock();
    if let Err(e) = o.write_fmt(text).and_then(|()| o.flush()) {
        if !STDOUT_GONE.swap(true, Ordering::Relaxed) && e.kind() != std::io::ErrorKind::BrokenPipe
        {
            let _ = writeln!(
                std::io::stderr(),
                "warning: cannot write to standard output ({e}); the rest of it is dropped"
            );
        }
    }
}

/// Environment variables and exit codes, shown by every command's `--help`.
pub const AFTER_HELP: &str = "\
Environment:
  DERMIS_DEVICE=SUBSTRING   device to use (as --device)
  DERMIS_VALIDATION=1       Khronos validation + synchronization validation (as --validation)
  DERMIS_ASSETS=DIR         the assets folder (default scene, CC0 maps), searched first
  DERMIS_NO_BUILD_ASSETS=1  never fall back on the build's checkout for assets
  DERMIS_CACHE_DIR=DIR      per-vertex transfer, media and specular tables, pipeline cache (default $XDG_CACHE_HOME/dermis or ~/.cache/dermis)
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
/// not a folder (nor ends in '/'), its extension is one of `exts` (lowercase,
/// no dot), its folder exists and a file can be created there. Otherwise an
/// input error (exit 2) naming the flag and path. A symbolic link is checked
/// (and later written) through.
fn check_output(flag: &str, path: &Path, exts: &[&str]) -> dermis::Result<()> {
    use std::os::unix::ffi::OsStrExt;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let target = dermis::atomic::resolve_links(path);
    let folder = target.parent().map_or(Path::new("/"), or_cwd);
    if path.as_os_str().as_bytes().ends_with(b"/") || target.is_dir() {
        Err("is a folder; give a file name".into())
    } else if !ext.is_some_and(|e| exts.contains(&e.as_str())) {
        Err(format!(
            "unsupported output format (use .{})",
            exts.join(" or .")
        ))
    } else if folder.exists() && !folder.is_dir() {
        Err(format!("{} is not a folder", folder.display()))
    } else if !folder.is_dir() {
        Err(format!("the folder {} does not exist", folder.display()))
    } else if let Err(e) = dermis::atomic::probe(&target) {
        Err(format!("cannot create a file in {}: {e}", folder.display()))
    } else {
        Ok(())
    }
    .map_err(|why| bad_output(flag, path, &why))
}

/// Checks, before any work, that `flag`'s folder `dir` exists or can be
/// created: neither it nor the nearest existing path above it is a file, and
/// files can be created in that nearest folder.
fn check_out_dir(flag: &str, dir: &Path) -> dermis::Result<()> {
    match dir.ancestors().map(or_cwd).find(|a| a.exists()) {
        Some(a) if !a.is_dir() && a == dir => Err(bad_output(flag, dir, "is a file, not a folder")),
        Some(a) if !a.is_dir() => Err(bad_output(
            flag,
            dir,
            &format!("cannot be created: {} is a file", a.display()),
        )),
        Some(a) => dermis::atomic::probe(&a.join("probe")).map_err(|e| {
            bad_output(
                flag,
                dir,
                &format!("cannot create a file in {}: {e}", a.display()),
            )
        }),
        None => Ok(()),
    }
}

/// Refuses two output flags naming one file (they would overwrite each
/// other): the same path, or links to one file.
fn check_distinct(outputs: &[(&str, Option<&Path>)]) -> dermis::Result<()> {
    let identity = |p: &Path| {
        let t = dermis::atomic::resolve_links(p);
        let folder = t.parent().map_or(Path::new("/"), or_cwd);
        std::fs::canonicalize(folder)
            .map(|f| f.join(t.file_name().unwrap_or_default()))
            .unwrap_or(t)
    };
    let given: Vec<(&str, &Path, std::path::PathBuf)> = outputs
        .iter()
        .filter_map(|(flag, p)| p.map(|p| (*flag, p, identity(p))))
        .collect();
    for (i, (flag, path, id)) in given.iter().enumerate() {
        if let Some((first, first_path, _)) = given[..i].iter().find(|(_, _, other)| other == id) {
            return Err(dermis::Error::Input(format!(
                "{first} {} and {flag} {} name one file: give each output its own",
                first_path.display(),
                path.display()
            )));
        }
    }
    Ok(())
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
