//! Writing rendered images: PNG (8-bit, as tone-mapped) or EXR (linear float),
//! by extension; each encoded in memory and written atomically (crate::atomic).

use super::sheet::Sheet;
use super::RenderOutput;
use crate::atomic::write_atomic;
use crate::error::{Error, Result};
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Png,
    Exr,
}

impl Format {
    pub fn of(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => Ok(Format::Png),
            Some("exr") => Ok(Format::Exr),
            _ => Err(Error::Input(format!(
                "{}: unsupported output format (use .png or .exr)",
                path.display()
            ))),
        }
    }
}

/// The 8-bit image as PNG, or the linear one as EXR: a screen view's radiance
/// × 2^exposure (alpha: coverage), a UV-space view's values as stored.
pub fn write(path: &Path, out: &RenderOutput) -> Result<()> {
    let (w, h) = (out.width, out.height);
    match Format::of(path)? {
        Format::Png => write_rgba8_png(path, w, h, &out.rgba8),
        Format::Exr => {
            let hdr = out.hdr.as_ref().ok_or_else(|| {
                Error::Input(format!("{}: no HDR image was rendered", path.display()))
            })?;
            let scale = if out.view.uv_space() {
                1.0
            } else {
                out.exposure.exp2()
            };
            let exposed: Vec<f32> = hdr
                .chunks_exact(4)
                .flat_map(|p| [p[0] * scale, p[1] * scale, p[2] * scale, p[3]])
                .collect();
            write_exr(path, w, h, &exposed)
        }
    }
}

/// A debug sheet or comparison (render::sheet), as PNG.
pub fn write_sheet(path: &Path, sheet: &Sheet) -> Result<()> {
    if Format::of(path)? != Format::Png {
        return Err(Error::Input(format!(
            "{}: a sheet is written as .png",
            path.display()
        )));
    }
    write_rgba8_png(path, sheet.width, sheet.height, &sheet.rgba8)
}

/// Writes 8-bit RGBA (row-major, top row first) as a PNG, whole or not at all
/// (crate::atomic): every PNG dermis writes, the viewer's screenshots included.
pub fn write_rgba8_png(path: &Path, width: u32, height: u32, rgba8: &[u8]) -> Result<()> {
    use image::ImageEncoder;
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(rgba8, width, height, image::ExtendedColorType::Rgba8)
        .map_err(|e| Error::Input(format!("{}: cannot write PNG: {e}", path.display())))?;
    write_atomic(path, png)
}

/// Linear RGBA f32, row-major, top row first, as EXR, whole or not at all.
pub fn write_exr(path: &Path, width: u32, height: u32, rgba: &[f32]) -> Result<()> {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    let w = width as usize;
    let channels = SpecificChannels::rgba(|Vec2(x, y)| {
        let i = (y * w + x) * 4;
        (rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3])
    });
    let mut exr = std::io::Cursor::new(Vec::new());
    Image::from_channels((w, height as usize), channels)
        .write()
        .to_buffered(&mut exr)
        .map_err(|e| Error::Input(format!("{}: cannot write EXR: {e}", path.display())))?;
    write_atomic(path, exr.into_inner())
}
