//! Where the texels of a UV-space target sit on the surface: the CPU's
//! rasterisation of the mesh by its UVs, as `shaders-glsl/uv.vert` does it
//! (texel (x, y) of an N × N target covers uv = ((x, y) + ½)/N).

use glam::{Vec2, Vec3};

/// A covered texel and the surface point at its centre.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Texel {
    pub x: u32,
    pub y: u32,
    pub uv: Vec2,
    /// mm.
    pub position: Vec3,
    /// Interpolated, normalised vertex normal.
    pub normal: Vec3,
    /// The triangle (index into the triangles of `indices`) it lies in.
    pub triangle: u32,
}

/// The texels of an N × N target (`resolution`) whose centres fall in a
/// triangle's UVs, every `stride`-th in x and y, in row order; each once (the
/// first triangle wins where charts overlap or on shared edges).
pub fn texels(
    positions: &[Vec3],
    normals: &[Vec3],
    uvs: &[Vec2],
    indices: &[u32],
    resolution: u32,
    stride: u32,
) -> Vec<Texel> {
    rasterise(positions, normals, uvs, indices, resolution, stride, true)
}

/// As [`texels`], but a texel whose centre several triangles' UVs cover (UV
/// charts that overlap) is listed once for each: every surface point that reads it.
pub fn texels_of_every_triangle(
    positions: &[Vec3],
    normals: &[Vec3],
    uvs: &[Vec2],
    indices: &[u32],
    resolution: u32,
) -> Vec<Texel> {
    rasterise(positions, normals, uvs, indices, resolution, 1, false)
}

fn rasterise(
    positions: &[Vec3],
    normals: &[Vec3],
    uvs: &[Vec2],
    indices: &[u32],
    resolution: u32,
    stride: u32,
    once: bool,
) -> Vec<Texel> {
    let n = resolution as usize;
    let stride = stride.max(1) as usize;
    let mut taken = vec![false; n * n];
    let mut out = Vec::new();
    for (triangle, t) in indices.chunks_exact(3).enumerate() {
        let t = [t[0], t[1], t[2]].map(|i| i as usize);
        let q = t.map(|i| uvs[i] * resolution as f32);
        let area = (q[1] - q[0]).perp_dot(q[2] - q[0]);
        if area == 0.0 || !area.is_finite() {
            continue;
        }
        let lo = q[0].min(q[1]).min(q[2]).floor().max(Vec2::ZERO);
        let hi = q[0].max(q[1]).max(q[2]).ceil().min(Vec2::splat(n as f32));
        let first = |lo: f32| (lo as usize).div_ceil(stride) * stride;
        for y in (first(lo.y)..hi.y as usize).step_by(stride) {
            for x in (first(lo.x)..hi.x as usize).step_by(stride) {
                let c = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                // Barycentrics by signed areas.
                let b1 = (c - q[0]).perp_dot(q[2] - q[0]) / area;
                let b2 = (q[1] - q[0]).perp_dot(c - q[0]) / area;
                let b0 = 1.0 - b1 - b2;
                if b0 < 0.0 || b1 < 0.0 || b2 < 0.0 || (once && taken[y * n + x]) {
                    continue;
                }
                taken[y * n + x] = true;
                let b = [b0, b1, b2];
                let mix3 = |a: &[Vec3]| (0..3).map(|k| b[k] * a[t[k]]).sum::<Vec3>();
                out.push(Texel {
                    x: x as u32,
                    y: y as u32,
                    uv: c / resolution as f32,
                    position: mix3(positions),
                    normal: mix3(normals).normalize_or_zero(),
                    triangle: triangle as u32,
                });
            }
        }
    }
    out.sort_by_key(|t| (t.y, t.x));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_covers_its_texels_once_at_their_surface_points() {
        // Two triangles over the whole UV square, a 40 × 40 mm plane at z = 3.
        let positions = [
            Vec3::new(0.0, 0.0, 3.0),
            Vec3::new(40.0, 0.0, 3.0),
            Vec3::new(40.0, 40.0, 3.0),
            Vec3::new(0.0, 40.0, 3.0),
        ];
        let uvs = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
        let normals = [Vec3::Z; 4];
        let t = texels(&positions, &normals, &uvs, &[0, 1, 2, 0, 2, 3], 8, 2);
        assert_eq!(t.len(), 16, "every second texel of 8 × 8, each once");
        let last = t.last().unwrap();
        assert_eq!((last.x, last.y), (6, 6));
        assert!((last.position - Vec3::new(32.5, 32.5, 3.0)).length() < 1e-4);
        assert_eq!(last.normal, Vec3::Z);
    }
}
