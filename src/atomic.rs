//! Files written whole: each to a temporary name in its folder, then renamed
//! into place, so a reader (or a killed sweep) never sees half a file.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// `dir/.name.tmp-PID` → `dir/name`, keeping the extension last (the plot
/// backends choose the format by it).
pub fn temporary(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map_or_else(String::new, |n| n.to_string_lossy().into_owned());
    let tmp = match name.rsplit_once('.') {
        Some((stem, ext)) => format!(".{stem}.tmp-{}.{ext}", std::process::id()),
        None => format!(".{name}.tmp-{}", std::process::id()),
    };
    path.with_file_name(tmp)
}

/// Renames `tmp` over `path`.
pub fn commit(tmp: &Path, path: &Path) -> Result<()> {
    std::fs::rename(tmp, path).map_err(|source| Error::Io {
        path: path.display().to_string(),
        source,
    })
}

/// Writes `bytes` to `path` through a temporary file, flushed to disk before
/// the rename; on failure the temporary file is removed and `path` is as it was.
pub fn write_atomic(path: &Path, bytes: impl AsRef<[u8]>) -> Result<()> {
    use std::io::Write;
    let tmp = temporary(path);
    let written = std::fs::File::create(&tmp)
        .and_then(|mut f| f.write_all(bytes.as_ref()).and_then(|()| f.sync_all()));
    if let Err(source) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::Io {
            path: path.display().to_string(),
            source,
        });
    }
    commit(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporaries_keep_the_extension_and_folder() {
        let t = temporary(Path::new("out/sweep.json"));
        assert_eq!(t.parent(), Some(Path::new("out")));
        assert_eq!(t.extension().unwrap(), "json");
        let name = t.file_name().unwrap().to_string_lossy().into_owned();
        assert!(name.starts_with(".sweep.tmp-"), "{name}");
    }

    #[test]
    fn atomic_writes_leave_only_the_file() {
        let d = std::env::temp_dir().join(format!("dermis-atomic-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        write_atomic(&d.join("a.csv"), "x\n").unwrap();
        write_atomic(&d.join("a.csv"), "y\n").unwrap();
        let names: Vec<String> = std::fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["a.csv"]);
        assert_eq!(std::fs::read_to_string(d.join("a.csv")).unwrap(), "y\n");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
