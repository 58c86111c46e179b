//! 8-bit RGBA textures loaded from PNG or JPEG files.
//!
//! Every image becomes tightly packed RGBA8 (row-major, top row first): grey is
//! replicated to RGB, a missing alpha becomes 255, 16-bit channels are rounded to
//! 8 bits. The [`Encoding`] records how the GPU must interpret the bytes.

use std::io::Cursor;
use std::path::Path;

use image::{ImageDecoder, ImageFormat, ImageReader, Limits};

use super::file::SceneError;

/// Largest accepted width or height (also the render-size limit of the scene file).
pub const MAX_TEXTURE_SIZE: u32 = 16384;

/// Stand-ins for maps a scene leaves out (docs/reference/scene-format.md, `[textures]`).
/// Albedo: sRGB 188 = linear 0.50 (IEC 61966-2-1), a neutral mid grey.
pub const DEFAULT_ALBEDO_SRGB: [u8; 4] = [188, 188, 188, 255];
/// Tangent-space (0, 0, 1): `n = 2·rgb/255 − 1`.
pub const FLAT_NORMAL: [u8; 4] = [128, 128, 255, 255];
/// A uniform specular map: each region's ρs raised to the middle of d'Eon's
/// range, ×(1 + ½·0.16/0.18) (skin::specular::map_rho_s).
pub const DEFAULT_SPECULAR: [u8; 4] = [255, 255, 255, 255];
/// Region 0 everywhere.
pub const DEFAULT_REGION: [u8; 4] = [0, 0, 0, 255];

/// How the stored bytes map to values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// sRGB transfer function (colour maps such as albedo); sample through an `_SRGB` format.
    Srgb,
    /// Linear values in 0..=1 (normal, specular, roughness and region maps).
    Linear,
}

/// A decoded image, `width * height * 4` bytes of RGBA8.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Texture {
    pub width: u32,
    pub height: u32,
    pub encoding: Encoding,
    pub rgba8: Vec<u8>,
}

impl Texture {
    /// A 1 x 1 texture of one colour (the stand-in for a map the scene leaves out).
    pub fn solid(rgba: [u8; 4], encoding: Encoding) -> Texture {
        Texture {
            width: 1,
            height: 1,
            encoding,
            rgba8: rgba.to_vec(),
        }
    }

    /// Reverses the row order: a map authored with its UV origin at the bottom
    /// left (OpenGL) becomes one sampled with glTF's top-left origin, since the
    /// texel for (u, v) moves from row (1 − v)·h to row v·h.
    pub fn flip_vertical(&mut self) {
        flip_rows(&mut self.rgba8, self.width as usize * 4);
    }
}

/// Reverses the order of the rows of `row_len` elements in `pixels`.
pub fn flip_rows<T>(pixels: &mut [T], row_len: usize) {
    let h = pixels.len() / row_len.max(1);
    for y in 0..h / 2 {
        let (top, bottom) = pixels.split_at_mut((h - 1 - y) * row_len);
        top[y * row_len..(y + 1) * row_len].swap_with_slice(&mut bottom[..row_len]);
    }
}

/// Rec. 709 luminance weights (ITU-R BT.709-6, item 3.2): the primaries of the
/// linear sRGB the renderer works in (IEC 61966-2-1).
pub const LUMINANCE: glam::Vec3 = glam::Vec3::new(0.2126, 0.7152, 0.0722);

/// IEC 61966-2-1 sRGB decoding of a value in [0, 1].
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// IEC 61966-2-1 sRGB encoding of a linear value, clamped to [0, 1].
pub fn linear_to_srgb(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

/// [`linear_to_srgb`] as an 8-bit value, rounded.
pub fn linear_to_srgb8(c: f32) -> u8 {
    (linear_to_srgb(c) * 255.0).round() as u8
}

/// Loads a PNG or JPEG file (the format is detected from the content) as RGBA8.
pub fn load_texture(path: &Path, encoding: Encoding) -> Result<Texture, SceneError> {
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    decode_texture(&bytes, encoding).map_err(|message| SceneError::texture(path, message))
}

/// Decodes an in-memory PNG or JPEG; the error is a one-line description.
fn decode_texture(bytes: &[u8], encoding: Encoding) -> Result<Texture, String> {
    let reader = ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| format!("cannot read image: {e}"))?;
    let format = reader.format();
    match format {
        Some(ImageFormat::Png) => check_png_complete(bytes)?,
        Some(ImageFormat::Jpeg) => {
            check_jpeg_complete(bytes)?;
            super::jpeg_scan::check_scans(bytes)?;
            return decode_jpeg_strict(bytes, encoding);
        }
        _ => return Err("not a PNG or JPEG image".into()),
    }
    let mut decoder = reader
        .into_decoder()
        .map_err(|e| format!("cannot decode image: {e}"))?;
    let (width, height) = decoder.dimensions();
    if width == 0 || height == 0 {
        return Err(format!("image is {width} x {height}; it must not be empty"));
    }
    if width > MAX_TEXTURE_SIZE || height > MAX_TEXTURE_SIZE {
        return Err(format!(
            "image is {width} x {height}; the limit is {MAX_TEXTURE_SIZE} per side"
        ));
    }
    // The size check above bounds the allocation: at most 16384² RGBA16 = 2 GiB.
    let mut limits = Limits::default();
    limits.max_image_width = Some(MAX_TEXTURE_SIZE);
    limits.max_image_height = Some(MAX_TEXTURE_SIZE);
    limits.max_alloc = Some(u64::from(MAX_TEXTURE_SIZE).pow(2) * 8);
    decoder
        .set_limits(limits)
        .map_err(|e| format!("cannot decode image: {e}"))?;
    let image = image::DynamicImage::from_decoder(decoder)
        .map_err(|e| format!("cannot decode image: {e}"))?;
    // Any channel count and depth to RGBA8 (16-bit rounds to nearest).
    let rgba = image.to_rgba8();
    let (width, height) = rgba.dimensions();
    Ok(Texture {
        width,
        height,
        encoding,
        rgba8: rgba.into_raw(),
    })
}

/// Decodes a JPEG as RGBA8 with zune-jpeg in strict mode: a bad Huffman code,
/// a scan ending early or a marker where none belongs is an error (the `image`
/// crate's lenient mode fills such an image with grey or garbage silently, as
/// a browser would; libjpeg calls them corrupt).
fn decode_jpeg_strict(bytes: &[u8], encoding: Encoding) -> Result<Texture, String> {
    use zune_core::bytestream::ZCursor;
    use zune_core::colorspace::ColorSpace;
    use zune_core::options::DecoderOptions;
    let options = DecoderOptions::default()
        .set_strict_mode(true)
        .set_max_width(usize::MAX)
        .set_max_height(usize::MAX)
        .jpeg_set_out_colorspace(ColorSpace::RGBA);
    let corrupt = |e: zune_jpeg::errors::DecodeErrors| {
        format!("corrupt JPEG: {e}")
            .replace('\n', " ")
            .trim_end()
            .to_string()
    };
    let mut decoder = zune_jpeg::JpegDecoder::new_with_options(ZCursor::new(bytes), options);
    decoder.decode_headers().map_err(corrupt)?;
    let (width, height) = decoder
        .dimensions()
        .ok_or("corrupt JPEG: no frame header")?;
    let (width, height) = (width as u32, height as u32);
    if width == 0 || height == 0 {
        return Err(format!("image is {width} x {height}; it must not be empty"));
    }
    if width > MAX_TEXTURE_SIZE || height > MAX_TEXTURE_SIZE {
        return Err(format!(
            "image is {width} x {height}; the limit is {MAX_TEXTURE_SIZE} per side"
        ));
    }
    let pixels = decoder.decode().map_err(corrupt)?;
    if pixels.len() != 4 * width as usize * height as usize {
        return Err(format!(
            "corrupt JPEG: {} bytes decoded for {width} x {height} RGBA",
            pixels.len()
        ));
    }
    Ok(Texture {
        width,
        height,
        encoding,
        rgba8: pixels,
    })
}

/// Rejects a PNG whose chunk list stops before IEND (the decoder may accept a file
/// cut after its last image-data chunk). Chunk layout: PNG spec §5.3.
fn check_png_complete(bytes: &[u8]) -> Result<(), String> {
    let mut pos: usize = 8; // after the 8-byte signature
    loop {
        let header = bytes
            .get(pos..pos.saturating_add(8))
            .ok_or("truncated PNG: the file ends before its IEND chunk")?;
        let length = u32::from_be_bytes([header[0], header[1], header[2], header[3]]) as usize;
        let kind = &header[4..8];
        // length, type, data, CRC
        let next = pos
            .checked_add(12)
            .and_then(|p| p.checked_add(length))
            .ok_or("corrupt PNG: chunk length overflows")?;
        if next > bytes.len() {
            return Err("truncated PNG: the file ends inside a chunk".into());
        }
        if kind == b"IEND" {
            return Ok(());
        }
        pos = next;
    }
}

/// Rejects a JPEG without an end-of-image marker after its scans (the decoder
/// fills a cut-off image with grey instead of failing). Marker syntax: ITU T.81 §B.1.
fn check_jpeg_complete(bytes: &[u8]) -> Result<(), String> {
    const TRUNCATED: &str = "truncated JPEG: no end-of-image marker";
    let mut pos: usize = 2; // after SOI (FF D8)
    loop {
        // A marker is FF (possibly repeated as fill) followed by a code.
        if bytes.get(pos) != Some(&0xFF) {
            return Err(if pos >= bytes.len() {
                TRUNCATED.into()
            } else {
                format!("corrupt JPEG: expected a marker at byte {pos}")
            });
        }
        while bytes.get(pos) == Some(&0xFF) {
            pos += 1;
        }
        let code = *bytes.get(pos).ok_or(TRUNCATED)?;
        pos += 1;
        match code {
            0xD9 => return Ok(()),          // EOI
            0x01 | 0xD0..=0xD8 => continue, // stand-alone markers
            _ => {}
        }
        let len_bytes = bytes.get(pos..pos + 2).ok_or(TRUNCATED)?;
        let length = usize::from(u16::from_be_bytes([len_bytes[0], len_bytes[1]]));
        if length < 2 {
            return Err(format!(
                "corrupt JPEG: segment length {length} at byte {pos}"
            ));
        }
        pos += length;
        if pos > bytes.len() {
            return Err(TRUNCATED.into());
        }
        if code == 0xDA {
            // Entropy-coded data follows SOS: skip to the next marker that is not a
            // stuffed byte (FF 00), a restart marker (FF D0..D7) or fill (FF FF).
            loop {
                let byte = *bytes.get(pos).ok_or(TRUNCATED)?;
                if byte == 0xFF {
                    match *bytes.get(pos + 1).ok_or(TRUNCATED)? {
                        0x00 | 0xD0..=0xD7 => pos += 2,
                        0xFF => pos += 1,
                        _ => break,
                    }
                } else {
                    pos += 1;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn assets() -> PathBuf {
        crate::assets::scan()
    }

    /// A fresh directory under the system temp dir, unique per test.
    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!(
            "dermis-texture-{name}-{}-{:?}",
            std::process::id(),
            std::time::SystemTime::now()
        ));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    fn png_bytes(img: image::DynamicImage) -> Vec<u8> {
        let mut out = Cursor::new(Vec::new());
        img.write_to(&mut out, ImageFormat::Png).unwrap();
        out.into_inner()
    }

    #[test]
    fn solid_is_one_pixel() {
        let t = Texture::solid([1, 2, 3, 4], Encoding::Linear);
        assert_eq!((t.width, t.height), (1, 1));
        assert_eq!(t.rgba8, vec![1, 2, 3, 4]);
        assert_eq!(t.encoding, Encoding::Linear);
    }

    #[test]
    fn flip_vertical_reverses_rows() {
        // 2 x 3, one distinct byte per texel channel.
        let rows: Vec<Vec<u8>> = (0..3u8)
            .map(|y| (0..8).map(|i| y * 8 + i).collect())
            .collect();
        let mut t = Texture {
            width: 2,
            height: 3,
            encoding: Encoding::Linear,
            rgba8: rows.concat(),
        };
        t.flip_vertical();
        assert_eq!(t.rgba8, [&rows[2][..], &rows[1], &rows[0]].concat());
        t.flip_vertical();
        assert_eq!(t.rgba8, rows.concat());
        // Even height: every row moves.
        let mut t = Texture {
            width: 1,
            height: 2,
            encoding: Encoding::Srgb,
            rgba8: vec![1, 2, 3, 4, 5, 6, 7, 8],
        };
        t.flip_vertical();
        assert_eq!(t.rgba8, vec![5, 6, 7, 8, 1, 2, 3, 4]);
    }

    #[test]
    fn lee_perry_smith_maps_load() {
        let dir = assets();
        for (name, enc) in [
            ("Map-COL.jpg", Encoding::Srgb),
            ("Map-SPEC.jpg", Encoding::Linear),
            ("Infinite-Level_02_Tangent_SmoothUV.jpg", Encoding::Linear),
        ] {
            let t = load_texture(&dir.join(name), enc).unwrap();
            assert_eq!((t.width, t.height), (1024, 1024), "{name}");
            assert_eq!(t.rgba8.len(), 1024 * 1024 * 4, "{name}");
            assert_eq!(t.encoding, enc);
            // Alpha is opaque and the image is not blank.
            assert!(t.rgba8.chunks_exact(4).all(|p| p[3] == 255), "{name}");
            let first = &t.rgba8[0..3];
            assert!(t.rgba8.chunks_exact(4).any(|p| &p[0..3] != first), "{name}");
        }
        // A tangent-space normal map points mostly along +Z: blue channel high.
        let n = load_texture(
            &dir.join("Infinite-Level_02_Tangent_SmoothUV.jpg"),
            Encoding::Linear,
        )
        .unwrap();
        let mean_b: f64 = n
            .rgba8
            .chunks_exact(4)
            .map(|p| f64::from(p[2]))
            .sum::<f64>()
            / (1024.0 * 1024.0);
        assert!(mean_b > 200.0, "mean blue {mean_b}");
    }

    #[test]
    fn grey_and_16_bit_png_become_rgba8() {
        let dir = temp_dir("png16");
        // 16-bit grey, 2 x 1: 0 and 65535 -> 0 and 255, replicated to RGB.
        let grey =
            image::ImageBuffer::<image::Luma<u16>, _>::from_raw(2, 1, vec![0u16, 65535]).unwrap();
        let path = dir.join("grey16.png");
        std::fs::write(&path, png_bytes(image::DynamicImage::ImageLuma16(grey))).unwrap();
        let t = load_texture(&path, Encoding::Linear).unwrap();
        assert_eq!((t.width, t.height), (2, 1));
        assert_eq!(t.rgba8, vec![0, 0, 0, 255, 255, 255, 255, 255]);
        // 8-bit grey + alpha.
        let la = image::ImageBuffer::<image::LumaA<u8>, _>::from_raw(1, 1, vec![10u8, 20]).unwrap();
        let path = dir.join("la.png");
        std::fs::write(&path, png_bytes(image::DynamicImage::ImageLumaA8(la))).unwrap();
        let t = load_texture(&path, Encoding::Srgb).unwrap();
        assert_eq!(t.rgba8, vec![10, 10, 10, 20]);
        // 16-bit RGB: 0x8080 rounds to 0x80.
        let rgb =
            image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(1, 1, vec![0x8080u16, 0, 65535])
                .unwrap();
        let path = dir.join("rgb16.png");
        std::fs::write(&path, png_bytes(image::DynamicImage::ImageRgb16(rgb))).unwrap();
        let t = load_texture(&path, Encoding::Linear).unwrap();
        assert_eq!(t.rgba8, vec![0x80, 0, 255, 255]);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn oversized_image_is_rejected_before_decoding() {
        let dir = temp_dir("huge");
        // A valid 1 x 1 PNG whose IHDR claims 20000 x 1 (CRC recomputed).
        let mut bytes = png_bytes(image::DynamicImage::new_rgba8(1, 1));
        bytes[16..20].copy_from_slice(&20000u32.to_be_bytes());
        let crc = crc32(&bytes[12..29]);
        bytes[29..33].copy_from_slice(&crc.to_be_bytes());
        let path = dir.join("huge.png");
        std::fs::write(&path, &bytes).unwrap();
        let err = load_texture(&path, Encoding::Srgb).unwrap_err().to_string();
        assert!(err.contains("huge.png") && err.contains("16384"), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// CRC-32 as PNG uses it (ISO 3309), bitwise.
    fn crc32(data: &[u8]) -> u32 {
        let mut crc = 0xFFFF_FFFFu32;
        for &b in data {
            crc ^= u32::from(b);
            for _ in 0..8 {
                crc = if crc & 1 != 0 {
                    (crc >> 1) ^ 0xEDB8_8320
                } else {
                    crc >> 1
                };
            }
        }
        !crc
    }

    #[test]
    fn bad_images_give_errors_naming_the_file() {
        let dir = temp_dir("bad");
        let missing = dir.join("missing.png");
        let err = load_texture(&missing, Encoding::Srgb)
            .unwrap_err()
            .to_string();
        assert!(err.contains("missing.png"), "{err}");

        let png = png_bytes(image::DynamicImage::new_rgb8(64, 64));
        let mut cases: Vec<(&str, Vec<u8>)> = vec![
            ("empty.png", Vec::new()),
            ("text.png", b"hello, not an image".to_vec()),
            ("sig-only.png", png[..8].to_vec()),
            ("cut-header.png", png[..20].to_vec()),
            ("cut-middle.png", png[..png.len() / 2].to_vec()),
            ("no-iend.png", png[..png.len() - 12].to_vec()),
            ("cut-last.png", png[..png.len() - 1].to_vec()),
        ];
        // Corrupt PNG: a flipped byte inside IHDR breaks its CRC.
        let mut bad_crc = png.clone();
        bad_crc[20] ^= 0x40;
        cases.push(("bad-crc.png", bad_crc));
        let jpg = std::fs::read(assets().join("Map-COL.jpg")).unwrap();
        cases.push(("cut-header.jpg", jpg[..100].to_vec()));
        cases.push(("cut-middle.jpg", jpg[..jpg.len() / 2].to_vec()));
        cases.push(("cut-end.jpg", jpg[..jpg.len() - 2].to_vec()));
        let mut garbage = jpg[..2].to_vec();
        garbage.extend_from_slice(&[0x12; 500]);
        cases.push(("garbage.jpg", garbage));
        for (name, bytes) in cases {
            let path = dir.join(name);
            std::fs::write(&path, &bytes).unwrap();
            let result = load_texture(&path, Encoding::Srgb);
            let err = result.err().unwrap_or_else(|| panic!("{name} loaded"));
            let msg = err.to_string();
            assert!(msg.contains(name), "{msg}");
            assert!(!msg.contains('\n'), "{msg}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// A run of one bits (stuffed FF 00 pairs) in the scan is no Huffman code of
    /// any table: always refused, by the decoder or the scan walk.
    #[test]
    fn runs_of_ones_in_a_jpeg_scan_are_refused() {
        let jpg = std::fs::read(assets().join("Map-COL.jpg")).unwrap();
        let data = scan_data(&jpg).start;
        let mut next = xorshift(0x9E37_79B9_7F4A_7C15);
        for _ in 0..20 {
            let mut bytes = jpg.clone();
            let at = data + 64 + (next() as usize) % 8192;
            for pair in bytes[at..at + 16].chunks_exact_mut(2) {
                pair.copy_from_slice(&[0xFF, 0x00]);
            }
            let msg = decode_texture(&bytes, Encoding::Srgb)
                .err()
                .unwrap_or_else(|| panic!("ones at byte {at} decoded"));
            assert!(msg.starts_with("corrupt JPEG"), "{msg}");
            assert!(!msg.contains('\n'), "{msg}");
        }
    }

    /// xorshift64 (Marsaglia 2003): deterministic mutants without a crate.
    fn xorshift(seed: u64) -> impl FnMut() -> u64 {
        let mut x = seed;
        move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        }
    }

    /// The entropy-coded bytes of a one-scan JPEG: after the SOS header, before
    /// the final FF D9.
    fn scan_data(jpg: &[u8]) -> std::ops::Range<usize> {
        let sos = jpg.windows(2).position(|w| w == [0xFF, 0xDA]).unwrap();
        let start = sos + 2 + usize::from(u16::from_be_bytes([jpg[sos + 2], jpg[sos + 3]]));
        assert_eq!(&jpg[jpg.len() - 2..], [0xFF, 0xD9]);
        start..jpg.len() - 2
    }

    /// The textures mutated, and how many mutants of each.
    const MUTATED: [&str; 3] = [
        "Map-COL.jpg",
        "Map-SPEC.jpg",
        "Infinite-Level_02_Tangent_SmoothUV.jpg",
    ];
    const MUTANTS_PER_FILE: usize = 40;

    /// Deterministic mutants of a texture's scan data, named by what was done:
    /// one byte replaced, one bit flipped, 16 bytes replaced, the scan cut
    /// short (end marker kept), one byte deleted, one byte inserted.
    fn mutants(jpg: &[u8], seed: u64) -> Vec<(String, Vec<u8>)> {
        let data = scan_data(jpg);
        let mut next = xorshift(seed);
        let mut out = Vec::new();
        for i in 0..MUTANTS_PER_FILE {
            let at = data.start + (next() as usize) % (data.len() - 16);
            let r = next();
            let mut b = jpg.to_vec();
            let name = match i % 6 {
                0 => {
                    b[at] ^= (r % 255 + 1) as u8; // never the same byte
                    format!("byte {at} replaced")
                }
                1 => {
                    b[at] ^= 1 << (r % 8);
                    format!("bit {} of byte {at} flipped", r % 8)
                }
                2 => {
                    for (k, x) in b[at..at + 16].iter_mut().enumerate() {
                        *x = (r >> (k % 8 * 8)) as u8;
                    }
                    format!("bytes {at}..{} replaced", at + 16)
                }
                3 => {
                    b.truncate(at);
                    b.extend_from_slice(&[0xFF, 0xD9]);
                    format!("scan cut at byte {at}")
                }
                4 => {
                    b.remove(at);
                    format!("byte {at} deleted")
                }
                _ => {
                    b.insert(at, r as u8);
                    format!("byte inserted at {at}")
                }
            };
            out.push((name, b));
        }
        out
    }

    /// libjpeg's verdict on each mutant of each file (djpeg of libjpeg-turbo
    /// 2.1.5, Debian 12; `libjpeg_and_dermis_agree_on_corrupt_jpegs` measures
    /// it): `W`, it warned "Corrupt JPEG data" (exit 2); `.`, it decoded the
    /// mutant without a word. docs/records/2026-11-29-corrupt-jpeg.md.
    const LIBJPEG: [&str; 3] = [
        "...WW....W.....W.W..WW.....WW.WWWW.W...W",
        ".WWW.W.W.WWW...WWW...WW.W.WW..W.WW.WW.WW",
        "..WW....WW...WWW.....W.W...W..W.WW...WWW",
    ];

    /// Every mutant libjpeg reports as corrupt is refused, the message naming
    /// the file and the damage (libjpeg's "Corrupt JPEG data" warnings are
    /// refusals here: a texture decoded from them is wrong without a sign).
    #[test]
    fn corrupt_jpeg_scans_are_refused() {
        let dir = temp_dir("mutants");
        let (mut refused, mut accepted) = (0, 0);
        for (f, file) in MUTATED.into_iter().enumerate() {
            let jpg = std::fs::read(assets().join(file)).unwrap();
            for (i, (what, bytes)) in mutants(&jpg, 0x9E37_79B9_7F4A_7C15 + f as u64)
                .into_iter()
                .enumerate()
            {
                let path = dir.join(format!("mutant-{i}-{file}"));
                std::fs::write(&path, &bytes).unwrap();
                let result = load_texture(&path, Encoding::Srgb);
                if LIBJPEG[f].as_bytes()[i] == b'.' {
                    accepted += 1;
                    continue;
                }
                let msg = result
                    .err()
                    .unwrap_or_else(|| panic!("{file} mutant {i} ({what}) loaded"))
                    .to_string();
                assert!(msg.contains(&format!("mutant-{i}-{file}")), "{msg}");
                assert!(
                    msg.contains("corrupt JPEG") || msg.contains("truncated JPEG"),
                    "{msg}"
                );
                assert!(!msg.contains('\n'), "{msg}");
                refused += 1;
            }
        }
        println!("mutants: {refused} refused as libjpeg does, {accepted} libjpeg accepts");
        assert_eq!(refused + accepted, MUTATED.len() * MUTANTS_PER_FILE);
        // The scan's textures still load.
        for name in MUTATED {
            load_texture(&assets().join(name), Encoding::Srgb).unwrap();
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    /// The measurement behind `LIBJPEG` (needs `djpeg`, libjpeg-turbo-progs;
    /// `cargo test --release --lib libjpeg_and_dermis -- --ignored --nocapture`):
    /// djpeg's verdict on every mutant (exit 0 clean, 2 warned, 1 failed) beside
    /// dermis's, and whether the decoded pixels differ from the original's.
    #[test]
    #[ignore = "needs djpeg (libjpeg-turbo-progs)"]
    fn libjpeg_and_dermis_agree_on_corrupt_jpegs() {
        use std::io::Write;
        let (mut n, mut libjpeg_flags, mut dermis_flags, mut changed) = (0, 0, 0, 0);
        let mut zune_flags = 0;
        let mut verdicts = Vec::new();
        for (f, file) in MUTATED.into_iter().enumerate() {
            let jpg = std::fs::read(assets().join(file)).unwrap();
            let original = decode_texture(&jpg, Encoding::Srgb).unwrap();
            // What the scan walk costs beside the decode (release build).
            let clock = std::time::Instant::now();
            super::super::jpeg_scan::check_scans(&jpg).unwrap();
            let walk = clock.elapsed();
            decode_jpeg_strict(&jpg, Encoding::Srgb).unwrap();
            println!(
                "{file}: scan walk {:.1} ms, decode {:.1} ms",
                walk.as_secs_f64() * 1e3,
                (clock.elapsed() - walk).as_secs_f64() * 1e3
            );
            let mut verdict = String::new();
            for (i, (what, bytes)) in mutants(&jpg, 0x9E37_79B9_7F4A_7C15 + f as u64)
                .into_iter()
                .enumerate()
            {
                let mut child = std::process::Command::new("djpeg")
                    .args(["-outfile", "/dev/null"])
                    .stdin(std::process::Stdio::piped())
                    .stderr(std::process::Stdio::piped())
                    .spawn()
                    .expect("djpeg runs (apt-get install libjpeg-turbo-progs)");
                child.stdin.take().unwrap().write_all(&bytes).unwrap();
                let out = child.wait_with_output().unwrap();
                let libjpeg = String::from_utf8_lossy(&out.stderr)
                    .trim()
                    .replace('\n', "; ");
                let flagged = !out.status.success();
                let dermis = decode_texture(&bytes, Encoding::Srgb);
                let differs = match &dermis {
                    Ok(t) => t.rgba8 != original.rgba8,
                    // Refused: decode leniently to see whether it would differ.
                    Err(_) => image::load_from_memory(&bytes)
                        .map(|im| im.to_rgba8().into_raw() != original.rgba8)
                        .unwrap_or(true),
                };
                println!(
                    "{file} #{i} ({what}): libjpeg {:?} {libjpeg:?}; dermis {}; pixels {}",
                    out.status.code(),
                    match &dermis {
                        Ok(_) => "loads".to_string(),
                        Err(m) => format!("refuses: {m}"),
                    },
                    if differs { "differ" } else { "same" }
                );
                n += 1;
                libjpeg_flags += usize::from(flagged);
                dermis_flags += usize::from(dermis.is_err());
                changed += usize::from(differs);
                verdict.push(if flagged { 'W' } else { '.' });
                // Before the scan walk: the end marker and zune-jpeg's strict mode.
                let zune = check_jpeg_complete(&bytes)
                    .and_then(|()| decode_jpeg_strict(&bytes, Encoding::Srgb));
                zune_flags += usize::from(zune.is_err());
                assert!(
                    !flagged || dermis.is_err(),
                    "{file} mutant {i} ({what}): libjpeg says {libjpeg:?}, dermis loads it"
                );
            }
            verdicts.push(verdict);
        }
        println!(
            "{n} mutants: {changed} decode to other pixels, libjpeg flags {libjpeg_flags}, \
             dermis refuses {dermis_flags} (zune-jpeg strict alone: {zune_flags}); \
             libjpeg: {verdicts:?}"
        );
        assert_eq!(verdicts, LIBJPEG, "update LIBJPEG");
    }

    /// Restart markers (none in the repository's JPEGs): a scan re-encoded by
    /// `cjpeg -restart 4B` (every 4 MCUs) loads; one RST renumbered or removed is refused, as
    /// libjpeg warns about both (needs cjpeg and djpeg, libjpeg-turbo-progs).
    #[test]
    #[ignore = "needs cjpeg and djpeg (libjpeg-turbo-progs)"]
    fn restart_markers_are_checked() {
        use std::io::Write;
        use std::process::{Command, Stdio};
        let pipe = |program: &str, args: &[&str], input: &[u8]| {
            let mut child = Command::new(program)
                .args(args)
                .stdin(Stdio::piped())
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap_or_else(|e| panic!("{program}: {e}"));
            let mut stdin = child.stdin.take().unwrap();
            let input = input.to_vec();
            let writer = std::thread::spawn(move || stdin.write_all(&input));
            let out = child.wait_with_output().unwrap();
            writer.join().unwrap().unwrap();
            out
        };
        let t = load_texture(&assets().join("Map-COL.jpg"), Encoding::Srgb).unwrap();
        let mut ppm = format!("P6\n{} {}\n255\n", t.width, t.height).into_bytes();
        for p in t.rgba8.chunks_exact(4) {
            ppm.extend_from_slice(&p[..3]);
        }
        let jpg = pipe("cjpeg", &["-restart", "4B"], &ppm).stdout;
        decode_texture(&jpg, Encoding::Srgb).unwrap();
        let rst: Vec<usize> = (0..jpg.len() - 1)
            .filter(|&i| jpg[i] == 0xFF && (0xD0..=0xD7).contains(&jpg[i + 1]))
            .collect();
        assert!(rst.len() > 100, "{} restart markers", rst.len());
        let mut renumbered = jpg.clone();
        renumbered[rst[40] + 1] = 0xD0 + (renumbered[rst[40] + 1] - 0xD0 + 3) % 8;
        let mut removed = jpg.clone();
        removed.drain(rst[40]..rst[40] + 2);
        for (what, bytes) in [("renumbered", renumbered), ("removed", removed)] {
            let libjpeg = pipe("djpeg", &["-outfile", "/dev/null"], &bytes);
            assert_eq!(libjpeg.status.code(), Some(2), "libjpeg, RST {what}");
            let msg = decode_texture(&bytes, Encoding::Srgb)
                .err()
                .unwrap_or_else(|| panic!("RST {what}: loaded"));
            println!(
                "RST {what}: libjpeg {:?}; dermis {msg}",
                String::from_utf8_lossy(&libjpeg.stderr).trim()
            );
            assert!(msg.starts_with("corrupt JPEG"), "{msg}");
        }
    }

    #[test]
    fn fuzzed_jpeg_never_panics() {
        let assets = assets();
        let jpg = std::fs::read(assets.join("Map-COL.jpg")).unwrap();
        let png = png_bytes(image::DynamicImage::new_rgb8(32, 32));
        let mut rng = 0x2545_F491_4F6C_DD1Du64;
        let mut next = move || {
            // xorshift64* (Vigna 2016)
            rng ^= rng >> 12;
            rng ^= rng << 25;
            rng ^= rng >> 27;
            rng.wrapping_mul(0x2545_F491_4F6C_DD1D)
        };
        let (mut ok, mut err) = (0, 0);
        for i in 0..240 {
            let src = if i % 4 == 3 { &png } else { &jpg };
            let mut bytes = src.clone();
            if i % 2 == 0 {
                bytes.truncate((next() as usize) % src.len());
            } else {
                for _ in 0..1 + next() % 8 {
                    let at = (next() as usize) % bytes.len();
                    bytes[at] ^= 1 << (next() % 8);
                }
            }
            let outcome = std::panic::catch_unwind(|| {
                decode_texture(&bytes, Encoding::Srgb)
                    .map_err(|m| SceneError::texture(Path::new("fuzz.jpg"), m).to_string())
            });
            match outcome {
                Ok(Ok(t)) => {
                    assert_eq!(t.rgba8.len(), (t.width * t.height * 4) as usize);
                    ok += 1
                }
                Ok(Err(msg)) => {
                    assert!(!msg.contains('\n'), "{msg}");
                    err += 1
                }
                Err(_) => panic!("decoder panicked on case {i}"),
            }
        }
        println!("fuzzed images: {ok} decoded, {err} rejected");
        assert!(err >= 120, "every truncation must be rejected");
    }
}
