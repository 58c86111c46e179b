//! Disk cache of transfers.
//!
//! [`cache_key`] is FNV-1a 64 over the mesh bytes plus method and settings;
//! [`store_cached`] / [`load_cached`] write `<dir>/<key>.transfer` (format in
//! [`store_cached`]); unreadable or corrupt files are ignored with a warning.

use std::path::{Path, PathBuf};

use glam::Vec3;

use super::transfer::{RgbTransfer, Transfer};
use crate::scene::mesh::Mesh;

use crate::cache::{fnv1a64_from as fnv1a, hex, FNV_OFFSET};

/// Stable cache key (16 hex digits) of the mesh's positions, normals and
/// indices, the occlusion `method` and its `settings` string. Each field is
/// preceded by its length so that byte runs cannot shift between fields.
pub fn cache_key(mesh: &Mesh, method: &str, settings: &str) -> String {
    let mut h = fnv1a(FNV_OFFSET, b"dermis-transfer-v1");
    let field = |h: &mut u64, len: usize, bytes: &mut dyn Iterator<Item = [u8; 4]>| {
        *h = fnv1a(*h, &(len as u64).to_le_bytes());
        for b in bytes {
            *h = fnv1a(*h, &b);
        }
    };
    let vec_bytes = |v: &Vec3| v.to_array().map(f32::to_le_bytes);
    field(
        &mut h,
        mesh.positions.len(),
        &mut mesh.positions.iter().flat_map(vec_bytes),
    );
    field(
        &mut h,
        mesh.normals.len(),
        &mut mesh.normals.iter().flat_map(vec_bytes),
    );
    field(
        &mut h,
        mesh.indices.len(),
        &mut mesh.indices.iter().map(|i| i.to_le_bytes()),
    );
    for s in [method, settings] {
        h = fnv1a(h, &(s.len() as u64).to_le_bytes());
        h = fnv1a(h, s.as_bytes());
    }
    hex(h)
}

pub use crate::cache::default_cache_dir;

const MAGIC: &[u8; 8] = b"DRMSTRNS";
const VERSION: u32 = 1;

/// Keys become file names: only ASCII letters, digits, `-` and `_`.
fn cache_path(dir: &Path, key: &str) -> Option<PathBuf> {
    let ok = !key.is_empty()
        && key.len() <= 128
        && key
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_');
    ok.then(|| dir.join(format!("{key}.transfer")))
}

fn encode(key: &str, t: &Transfer) -> Vec<u8> {
    let mut buf = Vec::with_capacity(32 + key.len() + t.coeffs.len() * 36);
    buf.extend_from_slice(MAGIC);
    buf.extend_from_slice(&VERSION.to_le_bytes());
    buf.extend_from_slice(&(key.len() as u32).to_le_bytes());
    buf.extend_from_slice(key.as_bytes());
    buf.extend_from_slice(&(t.coeffs.len() as u64).to_le_bytes());
    for c in t.coeffs.iter().flatten() {
        buf.extend_from_slice(&c.to_le_bytes());
    }
    let sum = fnv1a(FNV_OFFSET, &buf);
    buf.extend_from_slice(&sum.to_le_bytes());
    buf
}

/// Parses a cache file; `Err` says what is wrong.
fn decode(key: &str, bytes: &[u8]) -> Result<Transfer, String> {
    let body_len = bytes
        .len()
        .checked_sub(8)
        .ok_or("shorter than its checksum")?;
    let (body, sum) = bytes.split_at(body_len);
    if fnv1a(FNV_OFFSET, body).to_le_bytes() != sum {
        return Err("checksum mismatch (truncated or corrupt)".into());
    }
    let mut pos = 0usize;
    let mut take = |n: usize| -> Result<&[u8], String> {
        let b = body.get(pos..pos.saturating_add(n)).ok_or("truncated")?;
        pos += n;
        Ok(b)
    };
    if take(8)? != MAGIC {
        return Err("not a dermis transfer cache file".into());
    }
    let u32_at = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    let version = u32_at(take(4)?);
    if version != VERSION {
        return Err(format!("version {version}, expected {VERSION}"));
    }
    let key_len = u32_at(take(4)?) as usize;
    if take(key_len)? != key.as_bytes() {
        return Err("stored key differs".into());
    }
    let n = take(8)?;
    let n = u64::from_le_bytes(std::array::from_fn(|i| n[i]));
    let data = &body[pos.min(body.len())..];
    if n.checked_mul(36) != Some(data.len() as u64) {
        return Err(format!(
            "{n} vertices need {} bytes, found {}",
            n.saturating_mul(36),
            data.len()
        ));
    }
    let coeffs: Vec<[f32; 9]> = data
        .chunks_exact(36)
        .map(|v| std::array::from_fn(|i| f32::from_le_bytes(std::array::from_fn(|j| v[4 * i + j]))))
        .collect();
    if coeffs.iter().flatten().any(|c| !c.is_finite()) {
        return Err("non-finite coefficient".into());
    }
    Ok(Transfer { coeffs })
}

/// Reads `<dir>/<key>.transfer`. A missing file is `None` silently; an
/// unreadable, truncated or corrupt one is `None` with a warning.
pub fn load_cached(dir: &Path, key: &str) -> Option<Transfer> {
    let Some(path) = cache_path(dir, key) else {
        log::warn!("occlusion cache: invalid key {key:?}");
        return None;
    };
    let bytes = match std::fs::read(&path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return None,
        Err(e) => {
            log::warn!("occlusion cache: cannot read {}: {e}", path.display());
            return None;
        }
    };
    match decode(key, &bytes) {
        Ok(t) => {
            log::info!("occlusion cache: loaded {}", path.display());
            Some(t)
        }
        Err(e) => {
            log::warn!("occlusion cache: ignoring {}: {e}", path.display());
            None
        }
    }
}

/// Writes `<dir>/<key>.transfer` (creating `dir`) atomically (crate::atomic):
/// readers never see a partial file, a failed write leaves no temporary. Format, little endian:
/// `"DRMSTRNS"`, u32 version (1), u32 key length, key bytes, u64 vertex count,
/// `9 × count` f32 coefficients, then the u64 FNV-1a of all preceding bytes.
pub fn store_cached(dir: &Path, key: &str, t: &Transfer) -> crate::Result<()> {
    let stored = (|| {
        let path = cache_path(dir, key)
            .ok_or_else(|| crate::Error::Input(format!("invalid cache key {key:?}")))?;
        std::fs::create_dir_all(dir).map_err(|source| crate::Error::Io {
            path: dir.display().to_string(),
            source,
        })?;
        crate::atomic::write_atomic(&path, encode(key, t))
    })();
    if stored.is_err() {
        STORE_FAILURES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }
    stored
}

static STORE_FAILURES: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// How many [`store_cached`] calls of this process failed (the transfers were
/// computed, but not cached: `dermis precompute` fails then).
pub fn store_failures() -> usize {
    STORE_FAILURES.load(std::sync::atomic::Ordering::Relaxed)
}

/// `compute()`'s RGB transfer of `vertices` vertices, or the copy cached under
/// `key` (stored as a transfer of three rows per vertex, R, G, B); `what`
/// names it in the log.
pub fn rgb_cached(
    what: &str,
    key: &str,
    vertices: usize,
    compute: impl FnOnce() -> RgbTransfer,
) -> RgbTransfer {
    let dir = default_cache_dir();
    if let Some(t) = load_cached(&dir, key).filter(|t| t.coeffs.len() == 3 * vertices) {
        log::info!("{what}: cached {key} from {}", dir.display());
        let coeffs = t
            .coeffs
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        return RgbTransfer { coeffs };
    }
    let t = compute();
    let flat = Transfer {
        coeffs: t.coeffs.iter().flatten().copied().collect(),
    };
    if let Err(e) = store_cached(&dir, key, &flat) {
        log::warn!("{what}: cannot cache in {}: {e}", dir.display());
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::occlusion::raytrace::{raytrace, RayOptions};
    use crate::light::occlusion::testutil::cylinder;

    #[test]
    fn cache_round_trip_and_corruption() {
        let dir =
            std::env::temp_dir().join(format!("dermis-occlusion-test-{}", std::process::id()));
        let _ = cache_key(&Mesh::default(), "", "");
        let m = cylinder(50.0, 100.0, 16);
        let o = RayOptions::default();
        let key = cache_key(&m, "raytrace", &o.cache_settings());
        assert_eq!(key, cache_key(&m, "raytrace", &o.cache_settings()));
        assert_eq!(key.len(), 16);
        assert_ne!(
            key,
            cache_key(
                &m,
                "raytrace",
                &RayOptions { samples: 512, ..o }.cache_settings()
            )
        );
        assert_ne!(key, cache_key(&m, "raster", &o.cache_settings()));
        let mut moved = m.clone();
        moved.positions[3].x += 1e-3;
        assert_ne!(key, cache_key(&moved, "raytrace", &o.cache_settings()));

        assert!(load_cached(&dir, &key).is_none()); // missing
        let t = raytrace(&m, &o, false);
        store_cached(&dir, &key, &t).unwrap();
        assert_eq!(load_cached(&dir, &key), Some(t.clone()));
        // Another key does not load this file's content.
        assert!(load_cached(&dir, "0123456789abcdef").is_none());
        assert!(load_cached(&dir, "../evil").is_none());
        assert!(store_cached(&dir, "a/b", &t).is_err());

        let path = dir.join(format!("{key}.transfer"));
        let good = std::fs::read(&path).unwrap();
        for len in [0, 5, 20, good.len() / 2, good.len() - 1] {
            std::fs::write(&path, &good[..len]).unwrap();
            assert!(load_cached(&dir, &key).is_none(), "truncated to {len}");
        }
        for pos in [0, 9, 14, 40, good.len() / 2, good.len() - 1] {
            let mut bad = good.clone();
            bad[pos] ^= 0x10;
            std::fs::write(&path, &bad).unwrap();
            assert!(load_cached(&dir, &key).is_none(), "flipped byte {pos}");
        }
        let mut long = good.clone();
        long.push(0);
        std::fs::write(&path, &long).unwrap();
        assert!(load_cached(&dir, &key).is_none());
        // The empty transfer round-trips too.
        let empty = Transfer { coeffs: Vec::new() };
        store_cached(&dir, "empty", &empty).unwrap();
        assert_eq!(load_cached(&dir, "empty"), Some(empty));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_failed_store_leaves_no_temporary() {
        let dir =
            std::env::temp_dir().join(format!("dermis-occlusion-fail-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        // The entry's name is taken by a non-empty folder: the rename fails.
        std::fs::create_dir_all(dir.join("k.transfer/x")).unwrap();
        let t = Transfer {
            coeffs: vec![[0.5; 9]; 4],
        };
        assert!(store_cached(&dir, "k", &t).is_err());
        let names: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, ["k.transfer"]);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
