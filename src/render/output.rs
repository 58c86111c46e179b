//! Writing rendered images: PNG (8-bit sRGB) or EXR (linear float), by extension.

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

pub fn write(path: &Path, out: &RenderOutput) -> Result<()> {
    let (w, h) = (out.width, out.height);
    match Format::of(path)? {
        Format::Png => image::save_buffer(path, &out.rgba8, w, h, image::ExtendedColorType::Rgba8)
            .map_err(|e| Error::Input(format!("{}: cannot write PNG: {e}", path.display()))),
        Format::Exr => {
            let hdr = out.hdr.as_ref().ok_or_else(|| {
                Error::Input(format!("{}: no HDR image was rendered", path.display()))
            })?;
            write_exr(path, w, h, hdr)
        }
    }
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
