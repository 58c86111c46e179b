//! The test texture (the paper's §IV menu, "toggle test texture"): a UV checker
//! of numbered cells that replaces the albedo, so UV stretch, seams and the UV
//! origin show on the face. Cell 0 is at UV (0, 0) and numbers run along u,
//! then v; the image is authored like a map of the scene (numbers upright with
//! row 0 at the top) and turned by the scene's `uv_origin` as every map is.

use super::file::UvOrigin;
use super::texture::{Encoding, Texture};

/// Side of the texture; the scan's maps are 1024² too.
pub const SIZE: u32 = 1024;
/// Cells along u and along v.
pub const CELLS: u32 = 8;
/// sRGB cell colours: light and dark grey (mean linear albedo ≈ 0.43, skin-like
/// in brightness so exposure and scattering look as on the scan).
const LIGHT: [u8; 3] = [225, 225, 225];
const DARK: [u8; 3] = [110, 110, 110];
/// Numbers: dark red on light cells, white on dark ones.
const INK: [[u8; 3]; 2] = [[150, 20, 20], [255, 255, 255]];

/// The checker as the GPU samples it (rows from v = 0) for maps authored with
/// `origin`.
pub fn albedo(origin: UvOrigin) -> Texture {
    let cell = SIZE / CELLS;
    // The cell row of the authored image's row `row`, counted from v = 0.
    let v_index = |row: u32| match origin {
        UvOrigin::TopLeft => row,
        UvOrigin::BottomLeft => CELLS - 1 - row,
    };
    let mut rgba8 = vec![255u8; (SIZE * SIZE * 4) as usize];
    for y in 0..SIZE {
        for x in 0..SIZE {
            let dark = (x / cell + v_index(y / cell)) % 2 == 1;
            let i = ((y * SIZE + x) * 4) as usize;
            rgba8[i..i + 3].copy_from_slice(if dark { &DARK } else { &LIGHT });
        }
    }
    let px = cell as f32 * 0.4;
    for row in 0..CELLS {
        for column in 0..CELLS {
            let label = (v_index(row) * CELLS + column).to_string();
            let x = (column * cell) as f32 + 0.5 * (cell as f32 - crate::text::width(&label, px));
            let y = (row * cell) as f32 + 0.5 * (cell as f32 - px);
            let ink = INK[((v_index(row) + column) % 2) as usize];
            crate::text::draw(&mut rgba8, SIZE, (x, y), px, ink, &label);
        }
    }
    let mut texture = Texture {
        width: SIZE,
        height: SIZE,
        encoding: Encoding::Srgb,
        rgba8,
    };
    if origin == UvOrigin::BottomLeft {
        texture.flip_vertical();
    }
    texture
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mean red of the texels of cell (u index, v index) as the GPU samples it.
    fn ink_in_cell(t: &Texture, column: u32, v_index: u32) -> usize {
        let cell = SIZE / CELLS;
        let mut n = 0;
        for y in v_index * cell..(v_index + 1) * cell {
            for x in column * cell..(column + 1) * cell {
                let p = &t.rgba8[((y * SIZE + x) * 4) as usize..][..3];
                n += usize::from(p[0] != p[1]);
            }
        }
        n
    }

    #[test]
    fn cell_zero_is_at_uv_origin_whatever_the_convention() {
        for origin in [UvOrigin::TopLeft, UvOrigin::BottomLeft] {
            let t = albedo(origin);
            assert_eq!((t.width, t.height), (SIZE, SIZE));
            // Light cells carry red ink: "0" at (0, 0) is one glyph, "16" at
            // (0, 2) two, so the second holds more ink than the first.
            let zero = ink_in_cell(&t, 0, 0);
            let sixteen = ink_in_cell(&t, 0, 2);
            assert!(zero > 100 && sixteen > zero, "{origin:?}: {zero} {sixteen}");
            // Dark cells carry white ink only.
            assert_eq!(ink_in_cell(&t, 1, 0), 0, "{origin:?}");
        }
    }
}
