//! The buffers a glTF file refers to: the GLB's binary chunk, data URIs (base64)
//! and external files beside the .gltf.

use std::path::Path;

/// Resolves every buffer: the GLB binary chunk, a `data:` URI, or a file relative
/// to the glTF file. Errors name the missing or short buffer.
pub(super) fn load_buffers(
    doc: &gltf::Document,
    blob: Option<&[u8]>,
    path: &Path,
) -> Result<Vec<Vec<u8>>, String> {
    let base = path.parent().unwrap_or(Path::new(""));
    let mut out = Vec::new();
    for buffer in doc.buffers() {
        let i = buffer.index();
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob
                .ok_or(format!(
                    "buffer {i} refers to the GLB binary chunk, which is missing"
                ))?
                .to_vec(),
            gltf::buffer::Source::Uri(uri) => {
                if let Some(rest) = uri.strip_prefix("data:") {
                    let (_, payload) = rest
                        .split_once(";base64,")
                        .ok_or(format!("buffer {i}: data URI is not base64"))?;
                    decode_base64(payload)
                        .ok_or(format!("buffer {i}: data URI has invalid base64"))?
                } else if uri.contains(':') {
                    return Err(format!("buffer {i}: unsupported URI scheme in '{uri}'"));
                } else {
                    let rel = percent_decode(uri).ok_or(format!(
                        "buffer {i}: URI '{uri}' is not valid percent-encoded UTF-8"
                    ))?;
                    let file = base.join(&rel);
                    std::fs::read(&file).map_err(|e| {
                        format!(
                            "cannot read external buffer '{rel}' ({}): {e}",
                            file.display()
                        )
                    })?
                }
            }
        };
        if data.len() < buffer.length() {
            return Err(format!(
                "buffer {i} has {} bytes, but the file declares {}",
                data.len(),
                buffer.length()
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// Standard or URL-safe base64 (RFC 4648 §4, §5); stops at padding.
pub(super) fn decode_base64(s: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(s.len() / 4 * 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    for c in s.bytes() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            b'=' => break,
            _ => return None,
        };
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

/// `%XX` escapes to bytes (RFC 3986 §2.1), then UTF-8.
pub(super) fn percent_decode(s: &str) -> Option<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while let Some(&b) = bytes.get(i) {
        if b == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

// ---------------------------------------------------------------------------
// Accessors
