//! The sweep's one hash: FNV-1a, 64 bits, written out here because its value
//! must not change between Rust versions or platforms (`DefaultHasher`'s may).
//! Point ids to shards, the sweep hash, the reference checksum.

/// FNV-1a, 64 bits (offset basis 0xcbf29ce484222325, prime 0x100000001b3): a
/// hash whose value is fixed by its definition, unlike `DefaultHasher`'s.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    fnv1a64_parts([bytes])
}

/// FNV-1a 64 over several byte strings in turn (as if concatenated).
pub fn fnv1a64_parts<'a>(parts: impl IntoIterator<Item = &'a [u8]>) -> u64 {
    parts.into_iter().fold(0xcbf2_9ce4_8422_2325, |h, bytes| {
        bytes.iter().fold(h, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
        })
    })
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
