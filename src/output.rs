//! Writing images: PNG (8-bit sRGB) by extension.

use crate::error::{Error, Result};
use std::path::Path;

/// Writes sRGB-encoded RGBA8 pixels; the format follows the file's extension.
pub fn write_rgba8(path: &Path, width: u32, height: u32, rgba8: &[u8]) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => {
            image::save_buffer(path, rgba8, width, height, image::ExtendedColorType::Rgba8)
                .map_err(|e| Error::Input(format!("{}: cannot write PNG: {e}", path.display())))
        }
        _ => Err(Error::Input(format!(
            "{}: unsupported output format (use .png)",
            path.display()
        ))),
    }
}
