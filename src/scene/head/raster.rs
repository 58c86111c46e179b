//! Triangle rasterisation in pixel (texel) coordinates, shared by the atlas's overlap
//! check and the texture bake.

use glam::{Vec2, Vec3};

/// Calls `f(x, y, barycentrics)` for every pixel centre (x + ½, y + ½) inside the
/// triangle (coordinates in pixels), with edge functions ≥ `eps` · edge length
/// (eps > 0 leaves shared edges to neither side; eps < 0 to both).
pub(super) fn raster_triangle(
    t: &[Vec2; 3],
    w: usize,
    h: usize,
    eps: f32,
    mut f: impl FnMut(usize, usize, Vec3),
) {
    let area = (t[1] - t[0]).perp_dot(t[2] - t[0]);
    if area.abs() < 1e-12 {
        return;
    }
    let s = area.signum();
    let lo = t[0].min(t[1]).min(t[2]);
    let hi = t[0].max(t[1]).max(t[2]);
    let x0 = (lo.x - 0.5).ceil().max(0.0) as usize;
    let y0 = (lo.y - 0.5).ceil().max(0.0) as usize;
    let x1 = ((hi.x - 0.5).floor().max(-1.0) + 1.0).min(w as f32) as usize;
    let y1 = ((hi.y - 0.5).floor().max(-1.0) + 1.0).min(h as f32) as usize;
    let len = [
        (t[2] - t[1]).length(),
        (t[0] - t[2]).length(),
        (t[1] - t[0]).length(),
    ];
    for y in y0..y1 {
        for x in x0..x1 {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let e = [
                (t[2] - t[1]).perp_dot(p - t[1]) * s,
                (t[0] - t[2]).perp_dot(p - t[2]) * s,
                (t[1] - t[0]).perp_dot(p - t[0]) * s,
            ];
            if e.iter().zip(&len).all(|(e, l)| *e >= eps * l) {
                f(x, y, Vec3::new(e[0], e[1], e[2]) / area.abs());
            }
        }
    }
}
