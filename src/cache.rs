//! Where dermis keeps what it computes once and reuses (the occlusion
//! transfers, the media's tables), and the one hash its keys and ids use:
//! FNV-1a, 64 bits, written out here because its value must not change between
//! Rust versions or platforms (`DefaultHasher`'s may).

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

/// FNV-1a 64's offset basis (Fowler, Noll & Vo).
pub const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
/// FNV-1a 64's prime.
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

/// FNV-1a 64 of `bytes`, continuing from state `h` ([`FNV_OFFSET`] to start).
pub fn fnv1a64_from(h: u64, bytes: &[u8]) -> u64 {
    bytes
        .iter()
        .fold(h, |h, &b| (h ^ u64::from(b)).wrapping_mul(FNV_PRIME))
}

/// FNV-1a 64 of `bytes`.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    fnv1a64_from(FNV_OFFSET, bytes)
}

/// FNV-1a 64 over several byte strings in turn (as if concatenated).
pub fn fnv1a64_parts<'a>(parts: impl IntoIterator<Item = &'a [u8]>) -> u64 {
    parts.into_iter().fold(FNV_OFFSET, fnv1a64_from)
}

/// 16 lower-case hex digits.
pub fn hex(h: u64) -> String {
    format!("{h:016x}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fnv1a64_matches_its_published_vectors() {
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a64(b"foobar"), 0x8594_4171_f739_67e8);
        assert_eq!(fnv1a64_parts([&b"foo"[..], b"bar"]), fnv1a64(b"foobar"));
    }
}
