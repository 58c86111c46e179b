//! Labelled images of several views on one canvas: the debug sheet (the paper's
//! Fig. 3 and debug mode) and the occlusion comparison (Figs. 6–8), composed on
//! the CPU from each view's 8-bit readback, labels in DejaVu Sans (crate::text).

use super::RenderOutput;

/// Views per row of the debug sheet.
pub const COLUMNS: usize = 6;
/// Largest tile of the debug sheet; each view is scaled to fit it.
pub const TILE: (u32, u32) = (256, 256);
/// Height of the label strip under each tile, and its text.
const LABEL: u32 = 24;
const LABEL_PX: f32 = 16.0;
const BACKGROUND: [u8; 3] = [32, 32, 32];
const INK: [u8; 3] = [235, 235, 235];

/// An RGBA8 image, row-major, top row first.
pub struct Sheet {
    pub width: u32,
    pub height: u32,
    pub rgba8: Vec<u8>,
}

/// `tiles` in rows of `columns`, each scaled to fit `tile` (keeping its
/// aspect; box-filtered down, nearest up), centred, its label below.
pub fn compose(tiles: &[(String, RenderOutput)], columns: usize, tile: (u32, u32)) -> Sheet {
    let rows = tiles.len().div_ceil(columns) as u32;
    let (cell_w, cell_h) = (tile.0, tile.1 + LABEL);
    let width = cell_w * columns.min(tiles.len()) as u32;
    let height = cell_h * rows;
    let mut rgba8: Vec<u8> = BACKGROUND
        .into_iter()
        .chain([255])
        .cycle()
        .take((width * height * 4) as usize)
        .collect();
    for (i, (label, out)) in tiles.iter().enumerate() {
        let (x0, y0) = ((i % columns) as u32 * cell_w, (i / columns) as u32 * cell_h);
        let scale = (tile.0 as f32 / out.width as f32).min(tile.1 as f32 / out.height as f32);
        let (w, h) = (
            ((out.width as f32 * scale).round() as u32).max(1),
            ((out.height as f32 * scale).round() as u32).max(1),
        );
        let (ox, oy) = (x0 + (tile.0 - w) / 2, y0 + (tile.1 - h) / 2);
        for y in 0..h {
            for x in 0..w {
                let p = resample(out, (x, y), scale);
                let i = (((oy + y) * width + ox + x) * 4) as usize;
                rgba8[i..i + 4].copy_from_slice(&p);
            }
        }
        // Smaller type where the label would not fit the tile.
        let fits = (cell_w as f32 - 4.0) / crate::text::width(label, LABEL_PX);
        let px = LABEL_PX * fits.min(1.0);
        let text_x = x0 as f32 + 0.5 * (cell_w as f32 - crate::text::width(label, px));
        let text_y = (y0 + tile.1) as f32 + 0.5 * (LABEL as f32 - px);
        crate::text::draw(&mut rgba8, width, (text_x, text_y), px, INK, label);
    }
    Sheet {
        width,
        height,
        rgba8,
    }
}

/// The pixel (x, y) of `out` scaled by `scale`: the mean of the source pixels
/// it covers (at least one).
fn resample(out: &RenderOutput, (x, y): (u32, u32), scale: f32) -> [u8; 4] {
    let span = |d: u32, limit: u32| {
        let a = ((d as f32 / scale) as u32).min(limit - 1);
        let b = (((d + 1) as f32 / scale) as u32).clamp(a + 1, limit);
        a..b
    };
    let (xs, ys) = (span(x, out.width), span(y, out.height));
    let mut sum = [0u32; 4];
    let mut n = 0;
    for sy in ys {
        for sx in xs.clone() {
            let i = ((sy * out.width + sx) * 4) as usize;
            for (s, &v) in sum.iter_mut().zip(&out.rgba8[i..i + 4]) {
                *s += v as u32;
            }
            n += 1;
        }
    }
    sum.map(|s| ((s + n / 2) / n) as u8)
}
