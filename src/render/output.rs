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
            // In f64: 2^exposure alone may overflow f32 where the light is faint.
            let scale = if out.view.uv_space() {
                1.0
            } else {
                f64::from(out.exposure).exp2()
            };
            let exposed: Vec<f32> = hdr
                .chunks_exact(4)
                .flat_map(|p| {
                    let e = |c: f32| (f64::from(c) * scale) as f32;
                    [e(p[0]), e(p[1]), e(p[2]), p[3]]
                })
                .collect();
            write_exr(path, w, h, &exposed)
        }
    }
}

/// What an exposed view's image fails to show, said rather than written
/// silently: the mesh covering no pixel (off-screen: a wrong `mm_per_unit`,
/// camera or size; the metered exposure is then of nothing), or the image one
/// flat black or white wherever the mesh is (a given exposure far off).
pub fn warnings(out: &RenderOutput) -> Vec<String> {
    use super::view::Shown;
    if out.view.shown() != Shown::Exposed || out.view.uv_space() {
        return Vec::new();
    }
    let covered = match (&out.metered, &out.hdr) {
        (Some(m), _) => Some(m.pixels > 0),
        (None, Some(hdr)) => Some(
            hdr.chunks_exact(4)
                .any(|p| p[3] > crate::post::meter::COVERED),
        ),
        _ => None,
    };
    if covered == Some(false) {
        return vec![format!(
            "the mesh covers no pixel of the {}×{} image (off-screen or too small: check \
             mesh.mm_per_unit, the camera and the size){}",
            out.width,
            out.height,
            if out.metered.is_some() {
                "; there was nothing to meter the exposure on"
            } else {
                ""
            }
        )];
    }
    let (mut black, mut white, mut n) = (0usize, 0usize, 0usize);
    for p in out.rgba8.chunks_exact(4).filter(|p| p[3] > 127) {
        n += 1;
        black += usize::from(p[..3] == [0, 0, 0]);
        white += usize::from(p[..3] == [255, 255, 255]);
    }
    let flat = match n {
        0 => None,
        _ if black == n => Some("black"),
        _ if white == n => Some("white"),
        _ => None,
    };
    flat.map(|flat| {
        format!(
            "the image is {flat} wherever it is covered, at exposure {:+.2} EV ({}): the \
             exposure is far from the scene's light (without --exposure / render.exposure it is \
             metered)",
            out.exposure,
            if out.metered.is_some() {
                "metered"
            } else {
                "given"
            }
        )
    })
    .into_iter()
    .collect()
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
    check_size(path, rgba8.len(), width, height)?;
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(rgba8, width, height, image::ExtendedColorType::Rgba8)
        .map_err(|e| Error::Input(format!("{}: cannot write PNG: {e}", path.display())))?;
    write_atomic(path, png)
}

/// `len` values are RGBA of `width` × `height` pixels (the encoders panic else).
fn check_size(path: &Path, len: usize, width: u32, height: u32) -> Result<()> {
    if len == 4 * width as usize * height as usize {
        return Ok(());
    }
    Err(Error::Input(format!(
        "{}: {len} values are not the RGBA of {width} × {height} pixels",
        path.display()
    )))
}

/// Linear RGBA f32, row-major, top row first, as EXR, whole or not at all.
pub fn write_exr(path: &Path, width: u32, height: u32, rgba: &[f32]) -> Result<()> {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    check_size(path, rgba.len(), width, height)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_round_trip_and_a_refused_write_keeps_the_old_file() {
        let d = std::env::temp_dir().join(format!("dermis-output-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        let (png, exr) = (d.join("a.png"), d.join("a.exr"));
        let rgba8 = [10, 20, 30, 255, 40, 50, 60, 128];
        write_rgba8_png(&png, 2, 1, &rgba8).unwrap();
        assert_eq!(image::open(&png).unwrap().to_rgba8().into_raw(), rgba8);
        write_exr(&exr, 1, 2, &[0.5, 1.0, 2.0, 1.0, 3.0, 4.0, 5.0, 0.25]).unwrap();
        let back = exr::prelude::read_first_rgba_layer_from_file(
            &exr,
            |_, _| Vec::new(),
            |px: &mut Vec<[f32; 4]>, _, (r, g, b, a): (f32, f32, f32, f32)| px.push([r, g, b, a]),
        )
        .unwrap();
        let px = &back.layer_data.channel_data.pixels;
        assert_eq!(px, &[[0.5, 1.0, 2.0, 1.0], [3.0, 4.0, 5.0, 0.25]]);
        let old = std::fs::read(&png).unwrap();
        // Too few pixels for the size: refused before anything is written.
        assert!(write_rgba8_png(&png, 4, 4, &rgba8).is_err());
        assert_eq!(std::fs::read(&png).unwrap(), old);
        let mut names: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        names.sort();
        assert_eq!(names, ["a.exr", "a.png"]);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
