//! Writing rendered images: PNG (8-bit, as tone-mapped) or EXR (linear float),
//! by extension.

use super::sheet::Sheet;
use super::RenderOutput;
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
        Format::Png => write_png(path, w, h, &out.rgba8),
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
    write_png(path, sheet.width, sheet.height, &sheet.rgba8)
}

fn write_png(path: &Path, width: u32, height: u32, rgba8: &[u8]) -> Result<()> {
    image::save_buffer(path, rgba8, width, height, image::ExtendedColorType::Rgba8)
        .map_err(|e| Error::Input(format!("{}: cannot write PNG: {e}", path.display())))
}

/// Linear RGBA f32, row-major, top row first.
pub fn write_exr(path: &Path, width: u32, height: u32, rgba: &[f32]) -> Result<()> {
    let w = width as usize;
    exr::prelude::write_rgba_file(path, w, height as usize, |x, y| {
        let i = (y * w + x) * 4;
        (rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3])
    })
    .map_err(|e| Error::Input(format!("{}: cannot write EXR: {e}", path.display())))
}
