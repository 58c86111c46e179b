//! Reading environment files: Radiance `.hdr` (RGBE) and OpenEXR `.exr` (incl.
//! a guard for the `exr` crate's DWA decoder), the layout from the aspect ratio
//! (2:1 equirect, 4:3 / 3:4 crosses) and six cube-face files. Untrusted bytes:
//! sizes are checked before allocation and decoder panics become errors.

use std::fmt;
use std::io::Cursor;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use glam::Vec3;

use super::cube::{cross_to_equirect, cube_to_equirect, Cross, Face};
use super::error::EnvError;
use super::map::{sanitize, EnvMap, SanitizeReport, MAX_TEXELS, MAX_WIDTH};

/// A decoded RGB image before layout interpretation.
struct RawImage {
    width: u32,
    height: u32,
    texels: Vec<Vec3>,
}

/// How a file's image is laid out, from its aspect ratio.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Layout {
    Equirect,
    Cross(Cross),
}

fn detect_layout(path: &Path, width: u64, height: u64) -> Result<Layout, EnvError> {
    if width > 0 && width == 2 * height {
        Ok(Layout::Equirect)
    } else if width > 0 && width.is_multiple_of(4) && 3 * width == 4 * height {
        Ok(Layout::Cross(Cross::Horizontal))
    } else if width > 0 && width.is_multiple_of(3) && 4 * width == 3 * height {
        Ok(Layout::Cross(Cross::Vertical))
    } else {
        Err(EnvError::Aspect {
            path: path.to_path_buf(),
            width,
            height,
        })
    }
}

/// Size limits shared by all decoders, checked before any pixel allocation.
fn check_size(path: &Path, width: u64, height: u64) -> Result<(), EnvError> {
    if width == 0 || height == 0 {
        return Err(corrupt(path, format!("empty image ({width}x{height})")));
    }
    if width > u64::from(MAX_WIDTH) || width.saturating_mul(height) > MAX_TEXELS {
        return Err(EnvError::TooLarge {
            path: path.to_path_buf(),
            width,
            height,
        });
    }
    Ok(())
}

fn corrupt(path: &Path, detail: impl fmt::Display) -> EnvError {
    // Keep messages on one line whatever the decoder says.
    let detail = detail.to_string().replace(['\n', '\r'], " ");
    EnvError::Corrupt {
        path: path.to_path_buf(),
        detail,
    }
}

/// Allocate a zeroed vector without aborting the process on failure.
fn try_zeroed<T: Clone + Default>(path: &Path, len: usize) -> Result<Vec<T>, EnvError> {
    let mut v = Vec::new();
    v.try_reserve_exact(len)
        .map_err(|_| corrupt(path, format!("cannot allocate {len} texels")))?;
    v.resize(len, T::default());
    Ok(v)
}

/// Read and decode an `.hdr` / `.exr` file into a raw RGB image. `check` sees
/// the header size before pixel memory is allocated.
fn read_raw(
    path: &Path,
    check: &dyn Fn(&Path, u64, u64) -> Result<(), EnvError>,
) -> Result<RawImage, EnvError> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => {}
        Ok(_) => {
            return Err(EnvError::Io {
                path: path.to_path_buf(),
                detail: "not a regular file".into(),
            })
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(EnvError::NotFound {
                path: path.to_path_buf(),
            })
        }
        Err(e) => {
            return Err(EnvError::Io {
                path: path.to_path_buf(),
                detail: e.to_string(),
            })
        }
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let is_hdr = match ext.as_deref() {
        Some("hdr") => true,
        Some("exr") => false,
        _ => {
            return Err(EnvError::UnknownExtension {
                path: path.to_path_buf(),
            })
        }
    };
    let bytes = std::fs::read(path).map_err(|e| EnvError::Io {
        path: path.to_path_buf(),
        detail: e.to_string(),
    })?;
    // The decoders are third-party code fed with untrusted bytes: a panic in
    // them must become an error, never take the renderer down.
    let decoded = catch_unwind(AssertUnwindSafe(|| {
        if is_hdr {
            decode_hdr(path, &bytes, check)
        } else {
            decode_exr(path, &bytes, check)
        }
    }));
    match decoded {
        Ok(r) => r,
        Err(_) => Err(corrupt(path, "decoder panicked on malformed data")),
    }
}

fn decode_hdr(
    path: &Path,
    bytes: &[u8],
    check: &dyn Fn(&Path, u64, u64) -> Result<(), EnvError>,
) -> Result<RawImage, EnvError> {
    use image::codecs::hdr::HdrDecoder;
    use image::ImageDecoder;

    let decoder = HdrDecoder::new(Cursor::new(bytes)).map_err(|e| corrupt(path, e))?;
    let (w, h) = decoder.dimensions();
    check_size(path, u64::from(w), u64::from(h))?;
    check(path, u64::from(w), u64::from(h))?;
    let n = w as usize * h as usize;
    let total = usize::try_from(decoder.total_bytes()).unwrap_or(usize::MAX);
    if Some(total) != n.checked_mul(12) {
        return Err(corrupt(path, "unexpected decoded size"));
    }
    let mut buf: Vec<u8> = try_zeroed(path, total)?;
    decoder.read_image(&mut buf).map_err(|e| corrupt(path, e))?;
    let mut texels: Vec<Vec3> = Vec::new();
    texels
        .try_reserve_exact(n)
        .map_err(|_| corrupt(path, format!("cannot allocate {n} texels")))?;
    // The decoder writes Rgb<f32> in native byte order.
    for px in buf.chunks_exact(12) {
        let f = |i: usize| -> f32 {
            let mut b = [0u8; 4];
            if let Some(s) = px.get(i..i + 4) {
                b.copy_from_slice(s);
            }
            f32::from_ne_bytes(b)
        };
        texels.push(Vec3::new(f(0), f(4), f(8)));
    }
    Ok(RawImage {
        width: w,
        height: h,
        texels,
    })
}

fn decode_exr(
    path: &Path,
    bytes: &[u8],
    check: &dyn Fn(&Path, u64, u64) -> Result<(), EnvError>,
) -> Result<RawImage, EnvError> {
    use exr::prelude::{read, ReadChannels, ReadLayers, ReadSpecificChannel};

    // Read the headers first: find the RGB layer and check its size before the
    // decoder allocates pixel storage.
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .map_err(|e| corrupt(path, e))?;
    let header = meta
        .headers
        .iter()
        .find(|h| {
            ["R", "G", "B"]
                .iter()
                .all(|c| h.channels.list.iter().any(|ch| ch.name.eq(c)))
        })
        .ok_or_else(|| EnvError::NoRgb {
            path: path.to_path_buf(),
        })?;
    let (w, h) = (header.layer_size.0 as u64, header.layer_size.1 as u64);
    check_size(path, w, h)?;
    check(path, w, h)?;
    check_dwa_chunks(path, bytes, &meta)?;
    let (w, h) = (w as u32, h as u32);
    let n = w as usize * h as usize;

    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .specific_channels()
        .required("R")
        .required("G")
        .required("B")
        .collect_pixels(
            move |size, _channels| {
                // The size was checked above; a layer of another size or a
                // failed allocation gives an empty buffer, reported below.
                let mut v: Vec<Vec3> = Vec::new();
                if size.0 == w as usize && size.1 == h as usize && v.try_reserve_exact(n).is_ok() {
                    v.resize(n, Vec3::ZERO);
                }
                (size.0, v)
            },
            |px: &mut (usize, Vec<Vec3>), pos, (r, g, b): (f32, f32, f32)| {
                let i = pos.1 * px.0 + pos.0;
                if let Some(t) = px.1.get_mut(i) {
                    *t = Vec3::new(r, g, b);
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .non_parallel()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| corrupt(path, e))?;
    let (stride, pixels) = image.layer_data.channel_data.pixels;
    if stride != w as usize || pixels.len() != n {
        return Err(corrupt(path, "decoded layer size differs from header"));
    }
    Ok(RawImage {
        width: w,
        height: h,
        texels: pixels,
    })
}

/// Guard for the `exr` crate's DWAA/DWAB decoder (1.74), which allocates
/// whatever sizes a chunk's DWA leader declares: one flipped bit in
/// `studio.exr` asked for 34 GB and aborted the process (found by the bit-flip
/// test). Before decoding, every DWA chunk's eleven u64 counters are checked
/// against the block's uncompressed size. Only single-part scan-line files are
/// walked; DWA in multi-part or tiled files is refused.
fn check_dwa_chunks(path: &Path, bytes: &[u8], meta: &exr::meta::MetaData) -> Result<(), EnvError> {
    use exr::compression::Compression;
    use exr::meta::BlockDescription;

    let is_dwa = |c: Compression| matches!(c, Compression::DWAA(_) | Compression::DWAB(_));
    if !meta.headers.iter().any(|h| is_dwa(h.compression)) {
        return Ok(());
    }
    let header = match meta.headers.as_slice() {
        [h] if !h.deep && matches!(h.blocks, BlockDescription::ScanLines) => h,
        _ => {
            return Err(corrupt(
                path,
                "DWA compression is only supported in single-part scan-line files",
            ))
        }
    };
    let rd = |at: usize, n: usize| -> Result<&[u8], EnvError> {
        at.checked_add(n)
            .and_then(|end| bytes.get(at..end))
            .ok_or_else(|| corrupt(path, "unexpected end of file"))
    };
    let cstr_end = |at: usize| -> Result<usize, EnvError> {
        let rest = bytes.get(at..).unwrap_or(&[]);
        rest.iter()
            .take(256)
            .position(|&b| b == 0)
            .map(|i| at + i)
            .ok_or_else(|| corrupt(path, "bad attribute name in header"))
    };
    // Header attributes: name\0 type\0 size:i32 value; an empty name ends it.
    let mut at = 8; // magic + version
    loop {
        let name_end = cstr_end(at)?;
        if name_end == at {
            at += 1;
            break;
        }
        let type_end = cstr_end(name_end + 1)?;
        let size_bytes = rd(type_end + 1, 4)?;
        let size = i32::from_le_bytes([size_bytes[0], size_bytes[1], size_bytes[2], size_bytes[3]]);
        let size = usize::try_from(size).map_err(|_| corrupt(path, "negative attribute size"))?;
        at = type_end + 5;
        rd(at, size)?;
        at += size;
    }
    let width = header.layer_size.0;
    let lines = header.compression.scan_lines_per_block();
    let channels = header.channels.list.len();
    // Upper bound on a block's uncompressed bytes (4-byte samples, no
    // subsampling), with slack for RLE token expansion.
    let block = width
        .saturating_mul(lines)
        .saturating_mul(channels)
        .saturating_mul(4);
    let limit = block.saturating_mul(2).saturating_add(4096) as u64;
    for k in 0..header.chunk_count {
        let o = rd(at + 8 * k, 8)?;
        let offset = u64::from_le_bytes([o[0], o[1], o[2], o[3], o[4], o[5], o[6], o[7]]);
        let offset = usize::try_from(offset).unwrap_or(usize::MAX);
        let size = rd(offset.saturating_add(4), 4)?;
        let size = u32::from_le_bytes([size[0], size[1], size[2], size[3]]) as usize;
        let data = rd(offset.saturating_add(8), size)?;
        if data.len() < 88 {
            continue; // stored raw or too short: the decoder rejects or copies it
        }
        for (i, c) in data.chunks_exact(8).take(11).enumerate() {
            let v = u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]);
            if i > 0 && v > limit {
                return Err(corrupt(
                    path,
                    format!("DWA block {k} declares {v} bytes (block holds at most {block})"),
                ));
            }
        }
    }
    Ok(())
}

/// Load an environment map by extension (`.hdr` Radiance RGBE, `.exr` OpenEXR:
/// first layer with R, G, B, any compression, half or float). The layout comes
/// from the aspect ratio: 2:1 equirect, 4:3 horizontal cross, 3:4 vertical
/// cross (crosses are resampled to a `4s × 2s` equirect map). Bad values are
/// sanitized and reported (and logged with the file name).
pub fn load(path: &Path) -> Result<(EnvMap, SanitizeReport), EnvError> {
    let check = |p: &Path, w: u64, h: u64| detect_layout(p, w, h).map(|_| ());
    let mut raw = read_raw(path, &check)?;
    let report = sanitize(&mut raw.texels);
    let layout = detect_layout(path, u64::from(raw.width), u64::from(raw.height))?;
    let env = match layout {
        Layout::Equirect => EnvMap {
            width: raw.width,
            height: raw.height,
            texels: raw.texels,
        },
        Layout::Cross(cross) => cross_to_equirect(cross, raw.width, raw.height, &raw.texels),
    };
    warn_if_sanitized(path, &report);
    Ok((env, report))
}

/// Load six square cube faces, in the order +X, −X, +Y, −Y, +Z, −Z (OpenGL /
/// Vulkan orientation, see `cube.rs`), and resample to equirect `4s × 2s`.
pub fn load_cube_faces(paths: [&Path; 6]) -> Result<(EnvMap, SanitizeReport), EnvError> {
    let square = |p: &Path, w: u64, h: u64| {
        if w != h {
            return Err(EnvError::CubeFace {
                path: p.to_path_buf(),
                detail: format!("face is {w}x{h}, not square"),
            });
        }
        if w > u64::from(MAX_WIDTH / 4) {
            return Err(EnvError::TooLarge {
                path: p.to_path_buf(),
                width: w,
                height: h,
            });
        }
        Ok(())
    };
    let mut report = SanitizeReport::default();
    let mut faces: Vec<Face> = Vec::with_capacity(6);
    for p in paths {
        let mut raw = read_raw(p, &square)?;
        let r = sanitize(&mut raw.texels);
        warn_if_sanitized(p, &r);
        report.add(r);
        if let Some(first) = faces.first() {
            if first.size != raw.width {
                return Err(EnvError::CubeFace {
                    path: p.to_path_buf(),
                    detail: format!(
                        "face is {}x{}, other faces are {}x{}",
                        raw.width, raw.height, first.size, first.size
                    ),
                });
            }
        }
        faces.push(Face {
            size: raw.width,
            texels: raw.texels,
        });
    }
    let faces: [Face; 6] = faces.try_into().map_err(|_| EnvError::CubeFace {
        path: paths[0].to_path_buf(),
        detail: "expected six faces".into(),
    })?;
    Ok((cube_to_equirect(&faces), report))
}

fn warn_if_sanitized(path: &Path, r: &SanitizeReport) {
    if r.total() > 0 {
        log::warn!(
            "{}: replaced {} NaN, {} Inf and {} negative channel values",
            path.display(),
            r.nan,
            r.inf,
            r.negative
        );
    }
}

#[cfg(test)]
mod tests {
    use super::super::cube::tests::{face_dir, probe};
    use super::super::map::HALF_MAX;
    use super::*;
    use std::path::PathBuf;

    fn assets() -> PathBuf {
        crate::assets::dir()
    }

    fn temp_dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("dermis-envmap-{}-{name}", std::process::id()));
        let _ = std::fs::create_dir_all(&d);
        d
    }

    #[test]
    fn loader_sanitizes() {
        // An EXR with bad values.
        let dir = temp_dir("sanitize");
        let p = dir.join("bad_values.exr");
        exr::prelude::write_rgb_file(&p, 8, 4, |x, y| {
            if (x, y) == (1, 1) {
                (f32::NAN, f32::INFINITY, -1.0f32)
            } else {
                (1.0f32, 1.0f32, 1.0f32)
            }
        })
        .unwrap();
        let (env, r) = load(&p).unwrap();
        assert_eq!(
            r,
            SanitizeReport {
                nan: 1,
                inf: 1,
                negative: 1
            }
        );
        assert_eq!(env.texel(1, 1), Vec3::new(0.0, HALF_MAX, 0.0));
    }

    #[test]
    fn an_rgbe_file_of_maximum_exponents_is_sanitized() {
        // 4 × 2 flat RGBE pixels (too narrow for run-length encoding), all 255.
        let p = temp_dir("max-exponent").join("max.hdr");
        let mut bytes = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n".to_vec();
        bytes.extend([255u8; 4 * 8]);
        std::fs::write(&p, bytes).unwrap();
        let (env, r) = load(&p).unwrap();
        assert_eq!(r.inf, 3 * 8, "{r:?}");
        assert!(env.texels.iter().all(|t| *t == Vec3::splat(HALF_MAX)));
    }

    #[test]
    fn load_real_maps() {
        let dir = assets();
        for name in crate::assets::ENV_MAPS {
            let t = std::time::Instant::now();
            let (env, r) = load(&dir.join("env").join(name)).unwrap();
            assert_eq!((env.width, env.height), (1024, 512), "{name}");
            assert_eq!(env.texels.len(), 1024 * 512);
            assert!(env
                .texels
                .iter()
                .all(|t| t.is_finite() && t.min_element() >= 0.0));
            let m = env.mean();
            let max = env
                .texels
                .iter()
                .fold(0.0f32, |a, t| a.max(t.max_element()));
            println!(
                "{name}: mean {:.4} {:.4} {:.4}, max {max:.1}, sanitized {r:?}, {:.0} ms",
                m.x,
                m.y,
                m.z,
                t.elapsed().as_secs_f64() * 1e3
            );
            assert!(
                m.min_element() > 1e-3 && m.max_element() < 1e3,
                "{name}: {m}"
            );
        }
    }

    fn write_cross(path: &Path, vertical: bool, s: usize) {
        let (w, h) = if vertical {
            (3 * s, 4 * s)
        } else {
            (4 * s, 3 * s)
        };
        let blocks: [(usize, usize, usize, bool); 6] = if vertical {
            [
                (0, 2, 1, false),
                (1, 0, 1, false),
                (2, 1, 0, false),
                (3, 1, 2, false),
                (4, 1, 1, false),
                (5, 1, 3, true),
            ]
        } else {
            [
                (0, 2, 1, false),
                (1, 0, 1, false),
                (2, 1, 0, false),
                (3, 1, 2, false),
                (4, 1, 1, false),
                (5, 3, 1, false),
            ]
        };
        exr::prelude::write_rgb_file(path, w, h, |x, y| {
            let (bx, by) = (x / s, y / s);
            for (f, cx, cy, flip) in blocks {
                if (cx, cy) == (bx, by) {
                    let (mut i, mut j) = (x % s, y % s);
                    if flip {
                        (i, j) = (s - 1 - i, s - 1 - j);
                    }
                    let d = face_dir(f, (i as f32 + 0.5) / s as f32, (j as f32 + 0.5) / s as f32);
                    let c = probe(d);
                    return (c.x, c.y, c.z);
                }
            }
            (0.0f32, 0.0f32, 0.0f32)
        })
        .unwrap();
    }

    #[test]
    fn cross_layouts_round_trip() {
        let dir = temp_dir("cross");
        for vertical in [false, true] {
            let s = 64;
            let p = dir.join(if vertical { "vcross.exr" } else { "hcross.exr" });
            write_cross(&p, vertical, s);
            let (env, _) = load(&p).unwrap();
            assert_eq!((env.width, env.height), (4 * s as u32, 2 * s as u32));
            let mut max_err = 0.0f32;
            for i in 0..500 {
                // Fibonacci sphere directions.
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / 500.0;
                let r = (1.0 - z * z).sqrt();
                let a = i as f32 * 2.399_963;
                let d = Vec3::new(r * a.cos(), r * a.sin(), z);
                let e = (env.sample_dir(d) - probe(d)).abs().max_element();
                max_err = max_err.max(e);
            }
            println!("cross vertical={vertical}: max error {max_err:.4}");
            assert!(max_err < 0.03, "vertical={vertical}: {max_err}");
        }
    }

    #[test]
    fn cube_faces_load() {
        let dir = temp_dir("faces");
        let s = 32usize;
        let names = ["px", "nx", "py", "ny", "pz", "nz"];
        let paths: Vec<PathBuf> = names.iter().map(|n| dir.join(format!("{n}.exr"))).collect();
        for (f, p) in paths.iter().enumerate() {
            exr::prelude::write_rgb_file(p, s, s, |x, y| {
                let c = probe(face_dir(
                    f,
                    (x as f32 + 0.5) / s as f32,
                    (y as f32 + 0.5) / s as f32,
                ));
                (c.x, c.y, c.z)
            })
            .unwrap();
        }
        let refs: [&Path; 6] = std::array::from_fn(|i| paths[i].as_path());
        let (env, _) = load_cube_faces(refs).unwrap();
        for d in [Vec3::X, Vec3::NEG_Y, Vec3::new(0.3, 0.5, -0.8).normalize()] {
            assert!((env.sample_dir(d) - probe(d)).abs().max_element() < 0.03);
        }
        // Mismatched sizes are an error naming the file.
        exr::prelude::write_rgb_file(&paths[3], 16, 16, |_, _| (1.0f32, 1.0f32, 1.0f32)).unwrap();
        let e = load_cube_faces(refs).unwrap_err().to_string();
        assert!(e.contains("ny.exr"), "{e}");
    }

    fn err_of(p: &Path) -> String {
        match load(p) {
            Ok(_) => panic!("{} loaded but should fail", p.display()),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn bad_inputs_are_errors_naming_the_file() {
        let dir = temp_dir("bad");
        let missing = dir.join("no_such_map.hdr");
        let e = err_of(&missing);
        assert!(
            e.contains("no_such_map.hdr") && e.contains("not found"),
            "{e}"
        );

        let txt = dir.join("notes.png");
        std::fs::write(&txt, b"hello").unwrap();
        let e = err_of(&txt);
        assert!(e.contains("notes.png") && e.contains("extension"), "{e}");

        let aspect = dir.join("square_map.exr");
        exr::prelude::write_rgb_file(&aspect, 16, 16, |_, _| (1.0f32, 1.0f32, 1.0f32)).unwrap();
        let e = err_of(&aspect);
        assert!(e.contains("square_map.exr") && e.contains("aspect"), "{e}");

        let garbage = dir.join("garbage.hdr");
        std::fs::write(
            &garbage,
            b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 99999\n",
        )
        .unwrap();
        let e = err_of(&garbage);
        assert!(e.contains("garbage.hdr") && e.contains("too large"), "{e}");

        let empty = dir.join("empty.exr");
        std::fs::write(&empty, b"").unwrap();
        let e = err_of(&empty);
        assert!(e.contains("empty.exr"), "{e}");

        for e in [
            err_of(&missing),
            err_of(&txt),
            err_of(&aspect),
            err_of(&garbage),
        ] {
            assert!(!e.contains('\n'));
        }
    }

    /// Source files for truncation / bit flips: the real maps when present,
    /// plus small synthetic ones (fast to decode).
    fn fuzz_sources(dir: &Path) -> Vec<PathBuf> {
        let mut v = Vec::new();
        let small_exr = dir.join("small.exr");
        exr::prelude::write_rgb_file(&small_exr, 32, 16, |x, y| (x as f32, y as f32, 0.5f32))
            .unwrap();
        v.push(small_exr);
        let small_hdr = dir.join("small.hdr");
        let px: Vec<image::Rgb<f32>> = (0..32 * 16)
            .map(|i| image::Rgb([i as f32 * 0.01, 0.5, 1.0]))
            .collect();
        let f = std::fs::File::create(&small_hdr).unwrap();
        image::codecs::hdr::HdrEncoder::new(f)
            .encode(&px, 32, 16)
            .unwrap();
        v.push(small_hdr);
        let a = assets();
        v.push(a.join("env/studio.exr"));
        v.push(a.join("env/royal_esplanade_1k.hdr"));
        v
    }

    #[test]
    fn truncated_files_are_errors() {
        let dir = temp_dir("trunc");
        for src in fuzz_sources(&dir) {
            let bytes = std::fs::read(&src).unwrap();
            let name = src.file_name().unwrap().to_string_lossy().to_string();
            for frac in [0.0, 0.01, 0.1, 0.3, 0.5, 0.9, 0.999] {
                let n = (bytes.len() as f64 * frac) as usize;
                let p = dir.join(format!("cut{}_{name}", (frac * 1000.0) as u32));
                std::fs::write(&p, &bytes[..n]).unwrap();
                let e = err_of(&p);
                assert!(
                    e.contains(&format!("cut{}_{name}", (frac * 1000.0) as u32)),
                    "{e}"
                );
            }
        }
    }

    #[test]
    fn bit_flipped_files_never_panic() {
        let dir = temp_dir("flip");
        let mut n_err = 0;
        let mut n_ok = 0;
        // xorshift: deterministic positions.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for src in fuzz_sources(&dir) {
            let bytes = std::fs::read(&src).unwrap();
            let big = bytes.len() > 100_000;
            let variants = if big { 30 } else { 150 };
            let name = src.file_name().unwrap().to_string_lossy().to_string();
            for k in 0..variants {
                let mut b = bytes.clone();
                for _ in 0..1 + next() % 4 {
                    // Mostly headers and offset tables (first 2 KiB), sometimes anywhere.
                    let span = if next() % 4 == 0 {
                        b.len()
                    } else {
                        b.len().min(2048)
                    };
                    let i = (next() as usize) % span;
                    b[i] ^= 1 << (next() % 8);
                }
                let p = dir.join(format!("flip{k}_{name}"));
                std::fs::write(&p, &b).unwrap();
                let r = catch_unwind(|| load(&p).map(|(env, _)| env.texels.len()));
                match r {
                    Err(_) => panic!("panic on {}", p.display()),
                    Ok(Ok(_)) => n_ok += 1,
                    Ok(Err(e)) => {
                        let msg = e.to_string();
                        assert!(
                            msg.contains(&format!("flip{k}_{name}")) && !msg.contains('\n'),
                            "{msg}"
                        );
                        n_err += 1;
                    }
                }
                let _ = std::fs::remove_file(&p);
            }
        }
        println!("bit flips: {n_ok} loaded, {n_err} errors, 0 panics");
        assert!(n_ok + n_err >= 300);
    }

    #[test]
    fn dwa_leader_guard() {
        // Regression: one flipped bit in the first DWA chunk leader of
        // studio.exr made the exr crate allocate 34 GB and abort the process.
        let a = assets();
        let mut b = std::fs::read(a.join("env/studio.exr")).unwrap();
        b[0x385] ^= 0x04;
        let p = temp_dir("dwa").join("dwa_flip.exr");
        std::fs::write(&p, &b).unwrap();
        let e = err_of(&p);
        assert!(e.contains("dwa_flip.exr") && e.contains("DWA"), "{e}");
    }
}
