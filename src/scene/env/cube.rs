//! Cube maps resampled to the equirect [`EnvMap`]: face selection, crosses cut
//! into faces, six faces to lat-long. No file I/O (see `decode.rs`).
//!
//! # Cube maps
//! Cube faces use the standard OpenGL / Vulkan cube-map convention (OpenGL 4.6
//! spec, table 8.19; Vulkan spec "Cube Map Face Selection"): for a direction
//! `(rx, ry, rz)` the face is chosen by the major axis and
//! ```text
//! face  sc   tc   ma        face  sc   tc   ma
//! +X   −rz  −ry   rx        −X   +rz  −ry   rx
//! +Y   +rx  +rz   ry        −Y   +rx  −rz   ry
//! +Z   +rx  −ry   rz        −Z   −rx  −ry   rz
//! s = (sc/|ma| + 1)/2,  t = (tc/|ma| + 1)/2,  t = 0 is the face image's top row.
//! ```
//! Crosses are unfolded so that every face keeps this orientation, except the −Z
//! face of the vertical cross, which is stored rotated by 180° (the usual
//! HDRShop / light-probe layout, so it joins −Y below it):
//! ```text
//! horizontal cross (4:3)          vertical cross (3:4)
//!       [+Y]                            [+Y]
//! [−X] [+Z] [+X] [−Z]             [−X] [+Z] [+X]
//!       [−Y]                            [−Y]
//!                                       [−Z]  (rotated 180°)
//! ```
//! Cube maps are resampled to an equirect map of `4s × 2s` texels (face size
//! `s`) with bilinear filtering inside each face (clamped at face edges).

use glam::Vec3;

use super::map::EnvMap;

/// The two cross layouts (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Cross {
    /// 4:3, faces in a row of four.
    Horizontal,
    /// 3:4, −Z at the bottom rotated by 180°.
    Vertical,
}

/// One square cube face in OpenGL orientation (row 0 = t = 0).
pub(super) struct Face {
    pub(super) size: u32,
    pub(super) texels: Vec<Vec3>,
}

impl Face {
    fn get(&self, x: u32, y: u32) -> Vec3 {
        let i = y as usize * self.size as usize + x as usize;
        self.texels.get(i).copied().unwrap_or(Vec3::ZERO)
    }

    /// Bilinear lookup at face coordinates `(s, t) ∈ [0, 1]²`, clamped to edges.
    fn sample(&self, s: f32, t: f32) -> Vec3 {
        if self.size == 0 {
            return Vec3::ZERO;
        }
        let n = self.size as f32;
        let fx = (s * n - 0.5).clamp(0.0, n - 1.0);
        let fy = (t * n - 0.5).clamp(0.0, n - 1.0);
        let x0 = fx.floor() as u32;
        let y0 = fy.floor() as u32;
        let x1 = (x0 + 1).min(self.size - 1);
        let y1 = (y0 + 1).min(self.size - 1);
        let tx = fx - x0 as f32;
        let ty = fy - y0 as f32;
        let top = self.get(x0, y0).lerp(self.get(x1, y0), tx);
        let bottom = self.get(x0, y1).lerp(self.get(x1, y1), tx);
        top.lerp(bottom, ty)
    }
}

/// Face index (0..6 = +X, −X, +Y, −Y, +Z, −Z) and `(s, t)` for direction `d`
/// (OpenGL 4.6 table 8.19).
pub fn cube_face_st(d: Vec3) -> (usize, f32, f32) {
    let a = d.abs();
    let (face, sc, tc, ma) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 {
            (0, -d.z, -d.y, a.x)
        } else {
            (1, d.z, -d.y, a.x)
        }
    } else if a.y >= a.z {
        if d.y > 0.0 {
            (2, d.x, d.z, a.y)
        } else {
            (3, d.x, -d.z, a.y)
        }
    } else if d.z > 0.0 {
        (4, d.x, -d.y, a.z)
    } else {
        (5, -d.x, -d.y, a.z)
    };
    if ma.is_nan() || ma <= 0.0 {
        return (4, 0.5, 0.5);
    }
    (face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0))
}

/// Cut the six faces out of a `width × height` cross image (row-major `texels`;
/// layout in the module doc).
fn cross_faces(cross: Cross, width: u32, height: u32, texels: &[Vec3]) -> [Face; 6] {
    let get = |x: u32, y: u32| -> Vec3 {
        if x >= width || y >= height {
            return Vec3::ZERO;
        }
        let i = y as usize * width as usize + x as usize;
        texels.get(i).copied().unwrap_or(Vec3::ZERO)
    };
    // (block column, block row, rotated 180°) for +X, −X, +Y, −Y, +Z, −Z.
    let (s, blocks) = match cross {
        Cross::Vertical => (
            width / 3,
            [
                (2, 1, false),
                (0, 1, false),
                (1, 0, false),
                (1, 2, false),
                (1, 1, false),
                (1, 3, true),
            ],
        ),
        Cross::Horizontal => (
            width / 4,
            [
                (2, 1, false),
                (0, 1, false),
                (1, 0, false),
                (1, 2, false),
                (1, 1, false),
                (3, 1, false),
            ],
        ),
    };
    blocks.map(|(bx, by, flip)| {
        let mut texels = Vec::with_capacity(s as usize * s as usize);
        for j in 0..s {
            for i in 0..s {
                let (fi, fj) = if flip { (s - 1 - i, s - 1 - j) } else { (i, j) };
                texels.push(get(bx * s + fi, by * s + fj));
            }
        }
        Face { size: s, texels }
    })
}

/// Resample a `width × height` cross image to an equirect map of `4s × 2s` texels.
pub(super) fn cross_to_equirect(cross: Cross, width: u32, height: u32, texels: &[Vec3]) -> EnvMap {
    cube_to_equirect(&cross_faces(cross, width, height, texels))
}

/// Resample a cube map to an equirect map of `4s × 2s` texels.
pub(super) fn cube_to_equirect(faces: &[Face; 6]) -> EnvMap {
    let s = faces[0].size.max(1);
    EnvMap::from_fn(4 * s, 2 * s, |d| {
        let (f, fs, ft) = cube_face_st(d);
        faces.get(f).map_or(Vec3::ZERO, |face| face.sample(fs, ft))
    })
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// Direction of face texel coordinates (s, t), written from the inverse of
    /// the OpenGL table (independent of `cube_face_st`).
    pub(in crate::scene::env) fn face_dir(face: usize, s: f32, t: f32) -> Vec3 {
        let (sc, tc) = (2.0 * s - 1.0, 2.0 * t - 1.0);
        let d = match face {
            0 => Vec3::new(1.0, -tc, -sc),
            1 => Vec3::new(-1.0, -tc, sc),
            2 => Vec3::new(sc, 1.0, tc),
            3 => Vec3::new(sc, -1.0, -tc),
            4 => Vec3::new(sc, -tc, 1.0),
            _ => Vec3::new(-sc, -tc, -1.0),
        };
        d.normalize()
    }

    /// A smooth, asymmetric test function of direction.
    pub(in crate::scene::env) fn probe(d: Vec3) -> Vec3 {
        Vec3::new(
            1.5 + d.x + 0.3 * d.y * d.z,
            1.2 + 0.8 * d.y - 0.2 * d.x,
            1.1 + 0.9 * d.z,
        )
    }

    #[test]
    fn cube_face_st_inverts_the_table() {
        for face in 0..6 {
            for (s, t) in [(0.5, 0.5), (0.1, 0.8), (0.9, 0.2), (0.3, 0.35)] {
                let (f, fs, ft) = cube_face_st(face_dir(face, s, t));
                assert_eq!(f, face, "({s}, {t})");
                assert!(
                    (fs - s).abs() < 1e-5 && (ft - t).abs() < 1e-5,
                    "{face}: {fs} {ft}"
                );
            }
        }
        assert_eq!(cube_face_st(Vec3::ZERO), (4, 0.5, 0.5));
    }
}
