//! Text in images: labels of the debug sheet and the numbers of the test
//! texture, in DejaVu Sans (assets/fonts, Bitstream Vera licence) rasterised by
//! ab_glyph and blended over RGBA8 pixels.

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};

/// DejaVu Sans, embedded: the PNG outputs need a font file on every machine.
pub const FONT: &[u8] = include_bytes!("../assets/fonts/DejaVuSans.ttf");

fn font() -> FontRef<'static> {
    FontRef::try_from_slice(FONT).expect("the embedded DejaVu Sans parses")
}

/// Width in pixels of `text` set at `px` pixels (the font's em height).
pub fn width(text: &str, px: f32) -> f32 {
    let font = font();
    let scaled = font.as_scaled(PxScale::from(px));
    let mut previous = None;
    let mut x = 0.0;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = previous {
            x += scaled.kern(p, id);
        }
        x += scaled.h_advance(id);
        previous = Some(id);
    }
    x
}

/// Draws `text` into `rgba` (`width` pixels per row, RGBA8) with its top-left
/// corner at (x, y) and the line `px` pixels high, in `color`, blended by
/// coverage; what falls outside the image is dropped.
pub fn draw(
    rgba: &mut [u8],
    image_width: u32,
    (x, y): (f32, f32),
    px: f32,
    color: [u8; 3],
    text: &str,
) {
    let font = font();
    let scaled = font.as_scaled(PxScale::from(px));
    let (w, h) = (
        image_width as i64,
        (rgba.len() / 4) as i64 / image_width.max(1) as i64,
    );
    let mut pen = x;
    let mut previous = None;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = previous {
            pen += scaled.kern(p, id);
        }
        let glyph = id.with_scale_and_position(px, ab_glyph::point(pen, y + scaled.ascent()));
        pen += scaled.h_advance(id);
        previous = Some(id);
        let Some(outline) = font.outline_glyph(glyph) else {
            continue;
        };
        let b = outline.px_bounds();
        outline.draw(|gx, gy, coverage| {
            let (px, py) = (b.min.x as i64 + gx as i64, b.min.y as i64 + gy as i64);
            if px < 0 || py < 0 || px >= w || py >= h {
                return;
            }
            let i = (py * w + px) as usize * 4;
            let a = coverage.clamp(0.0, 1.0);
            for (dst, &src) in rgba[i..i + 3].iter_mut().zip(&color) {
                *dst = (*dst as f32 * (1.0 - a) + src as f32 * a).round() as u8;
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_drawn_where_it_is_asked_for() {
        let (w, h) = (64u32, 32u32);
        let mut rgba = vec![0u8; (w * h * 4) as usize];
        draw(&mut rgba, w, (2.0, 4.0), 20.0, [255, 255, 255], "42");
        let lit: Vec<(u32, u32)> = (0..w * h)
            .filter(|&i| rgba[i as usize * 4] > 128)
            .map(|i| (i % w, i / w))
            .collect();
        assert!(lit.len() > 20, "{}", lit.len());
        // Inside the advance of the two digits and the line's height.
        let advance = width("42", 20.0);
        assert!(advance > 15.0 && advance < 30.0, "{advance}");
        assert!(lit
            .iter()
            .all(|&(x, y)| (2..=3 + advance as u32).contains(&x) && (4..=24).contains(&y)));
    }
}
