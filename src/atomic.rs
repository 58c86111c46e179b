//! Files written whole: each to a temporary name in its folder, flushed, then
//! renamed into place, so a reader (or a killed run) never sees half a file and
//! a failed write leaves the previous file as it was and no temporary behind.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// `dir/.name.tmp-PID-N.ext` for `dir/name.ext`: hidden, unique within this
/// process, in the same folder (a rename within one file system is atomic).
fn temporary(path: &Path) -> PathBuf {
    static COUNT: AtomicU64 = AtomicU64::new(0);
    let n = COUNT.fetch_add(1, Ordering::Relaxed);
    let id = format!("tmp-{}-{n}", std::process::id());
    let name = path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let tmp = match name.rsplit_once('.') {
        Some((stem, ext)) if !stem.is_empty() => format!(".{stem}.{id}.{ext}"),
        _ => format!(".{name}.{id}"),
    };
    path.with_file_name(tmp)
}

/// Writes `bytes` to `path` atomically (see [`write_atomic_with`]).
pub fn write_atomic(path: &Path, bytes: impl AsRef<[u8]>) -> Result<()> {
    write_atomic_with(path, |f| f.write_all(bytes.as_ref()))
}

/// Writes what `write` puts into a temporary file (seekable: encoders may go
/// back) to `path`: flushed to disk, then renamed over `path`. On any failure
/// the temporary file is removed and `path` is as it was.
pub fn write_atomic_with(
    path: &Path,
    write: impl FnOnce(&mut std::fs::File) -> std::io::Result<()>,
) -> Result<()> {
    let tmp = temporary(path);
    let written = std::fs::File::create(&tmp).and_then(|mut f| {
        write(&mut f)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, path)
    });
    written.map_err(|source| {
        let _ = std::fs::remove_file(&tmp);
        Error::Io {
            path: path.display().to_string(),
            source,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("dermis-atomic-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(d: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn temporaries_are_hidden_unique_and_keep_the_folder() {
        let (a, b) = (
            temporary(Path::new("out/sweep.json")),
            temporary(Path::new("out/sweep.json")),
        );
        assert_ne!(a, b);
        assert_eq!(a.parent(), Some(Path::new("out")));
        assert_eq!(a.extension().unwrap(), "json");
        let name = a.file_name().unwrap().to_string_lossy().into_owned();
        assert!(name.starts_with(".sweep.tmp-"), "{name}");
    }

    #[test]
    fn atomic_writes_leave_only_the_file() {
        let d = folder("whole");
        write_atomic(&d.join("a.csv"), "x\n").unwrap();
        write_atomic(&d.join("a.csv"), "y\n").unwrap();
        assert_eq!(names(&d), ["a.csv"]);
        assert_eq!(std::fs::read_to_string(d.join("a.csv")).unwrap(), "y\n");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn an_interrupted_write_keeps_the_old_file_and_no_temporary() {
        let d = folder("interrupted");
        let path = d.join("report.json");
        write_atomic(&path, "old").unwrap();
        // Half the new content written, then the writer fails (a full disk).
        let e = write_atomic_with(&path, |f| {
            f.write_all(b"{\"half\": ")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert!(e.to_string().contains("report.json"), "{e}");
        assert_eq!(e.exit_code(), 2);
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
        assert_eq!(names(&d), ["report.json"]);
        // Into a folder that does not exist: an error, nothing created.
        assert!(write_atomic(&d.join("no/such.json"), "x").is_err());
        assert_eq!(names(&d), ["report.json"]);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_failed_rename_removes_the_temporary() {
        // The target is a non-empty folder: the rename fails after the write.
        let d = folder("rename");
        std::fs::create_dir_all(d.join("out.png/inside")).unwrap();
        assert!(write_atomic(&d.join("out.png"), "png").is_err());
        assert_eq!(names(&d), ["out.png"]);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
