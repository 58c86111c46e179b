//! Bilinear lookups as the GPU's samplers make them at mip level 0: texel
//! centres at `(i + ½)/size`, clamp to edge in u and v (`gpu::Sampler::clamped`,
//! `frame_inputs/samplers.rs`). sRGB maps are decoded to linear per texel before
//! filtering, as an `_SRGB` format is sampled.

use glam::{Vec2, Vec3, Vec4};

use crate::scene::env::EnvMap;
use crate::scene::texture::{srgb_to_linear, Encoding, Texture};

/// RGBA of an 8-bit texture at `uv` (linear values; alpha is never sRGB).
pub fn rgba8(t: &Texture, uv: Vec2) -> Vec4 {
    bilinear(t.width, t.height, uv, |x, y| {
        let i = 4 * (y as usize * t.width as usize + x as usize);
        let c = Vec4::from_array(std::array::from_fn(|k| f32::from(t.rgba8[i + k]) / 255.0));
        match t.encoding {
            Encoding::Srgb => Vec4::new(
                srgb_to_linear(c.x),
                srgb_to_linear(c.y),
                srgb_to_linear(c.z),
                c.w,
            ),
            Encoding::Linear => c,
        }
    })
}

/// Radiance of an environment map at `uv` (the skybox's lookup).
pub fn env(map: &EnvMap, uv: Vec2) -> Vec3 {
    bilinear(map.width, map.height, uv, |x, y| {
        map.texel(x, y).extend(0.0)
    })
    .truncate()
}

/// The four texels around `uv` (clamped to the edge), linearly weighted.
pub fn bilinear(width: u32, height: u32, uv: Vec2, fetch: impl Fn(u32, u32) -> Vec4) -> Vec4 {
    let p = uv * Vec2::new(width as f32, height as f32) - 0.5;
    let p = if p.is_finite() { p } else { Vec2::ZERO };
    let base = p.floor();
    let f = p - base;
    let clamp = |v: f32, size: u32| v.clamp(0.0, size.saturating_sub(1) as f32) as u32;
    let (x0, x1) = (clamp(base.x, width), clamp(base.x + 1.0, width));
    let (y0, y1) = (clamp(base.y, height), clamp(base.y + 1.0, height));
    let top = fetch(x0, y0).lerp(fetch(x1, y0), f.x);
    let bottom = fetch(x0, y1).lerp(fetch(x1, y1), f.x);
    top.lerp(bottom, f.y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_weights_and_edges() {
        // 2 × 1 sRGB texture: black and white.
        let t = Texture {
            width: 2,
            height: 1,
            encoding: Encoding::Srgb,
            rgba8: vec![0, 0, 0, 255, 255, 255, 255, 255],
        };
        // Texel centres, the midpoint (linear, not sRGB, average) and clamping.
        assert_eq!(
            rgba8(&t, Vec2::new(0.25, 0.5)),
            Vec4::new(0.0, 0.0, 0.0, 1.0)
        );
        assert_eq!(rgba8(&t, Vec2::new(0.75, 0.5)), Vec4::ONE);
        assert!((rgba8(&t, Vec2::new(0.5, 0.5)).x - 0.5).abs() < 1e-6);
        assert_eq!(rgba8(&t, Vec2::new(-3.0, 9.0)).x, 0.0);
        assert_eq!(rgba8(&t, Vec2::new(1.0, 0.5)).x, 1.0);
        // sRGB 188 is linear 0.50 (texture::DEFAULT_ALBEDO_SRGB).
        assert!((srgb_to_linear(188.0 / 255.0) - 0.5).abs() < 3e-3);
        let mut map = EnvMap::uniform(Vec3::ZERO, 4, 2);
        map.texels[3] = Vec3::ONE; // top-right texel: no wrap to the left edge
        assert_eq!(env(&map, Vec2::new(0.0, 0.25)), Vec3::ZERO);
        assert_eq!(env(&map, Vec2::new(1.0, 0.25)), Vec3::ONE);
    }
}
