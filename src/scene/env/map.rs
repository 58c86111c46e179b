//! The environment map: an equirectangular (lat-long) image of linear RGB
//! radiance, its direction convention, texel solid angles and sanitizing.
//!
//! # Direction convention (the GPU shaders copy this exactly)
//! An [`EnvMap`] is an equirectangular (lat-long) image of linear RGB radiance,
//! row-major, row 0 at the top. World space is right-handed with **+Y up**.
//! For texture coordinates `(u, v)` in `[0, 1]²` (texel `(x, y)` has its centre
//! at `u = (x + 0.5) / W`, `v = (y + 0.5) / H`):
//! ```text
//! θ = π·v            (polar angle measured from +Y)
//! φ = 2π·(u − 0.5)
//! dir = (sin θ · sin φ,  cos θ,  −sin θ · cos φ)
//! ```
//! so `u = 0.5` looks toward −Z, `u = 0.75` toward +X, `u = 0.25` toward −X and
//! the left/right edge (`u = 0 ≡ 1`) toward +Z; `v = 0` is straight up. The
//! inverse is `u = atan2(x, −z) / 2π + 0.5`, `v = acos(y) / π`.
//!
//! A texel in row `y` subtends exactly `(2π / W)·(cos θ0 − cos θ1)` steradians,
//! `θ0 = π·y / H`, `θ1 = π·(y + 1) / H` ([`texel_solid_angle`]); the whole map sums
//! to 4π.
//!
//! # Rotation
//! [`EnvMap::rotated_y`] rotates the *content* about +Y by a right-handed angle:
//! positive degrees turn counter-clockwise when seen from above (+X toward −Z),
//! i.e. the rotation `glam::Mat3::from_rotation_y(deg.to_radians())`; radiance
//! that arrived from `d` now arrives from `R·d`. `light::sh::rotate_y` matches it.

use glam::{Mat3, Vec2, Vec3};

/// Widest accepted image (texels).
pub const MAX_WIDTH: u32 = 16384;
/// Most texels accepted in one image (a 16384 × 8192 equirect map, 1.5 GiB as f32).
pub const MAX_TEXELS: u64 = 16384 * 8192;
/// Largest finite IEEE half float. +Inf is clamped to this because the GPU keeps
/// radiance in RGBA16F: anything larger would turn back into Inf on upload, while
/// 65504 still reads as "extremely bright" and keeps SH sums finite.
pub const HALF_MAX: f32 = 65504.0;

/// Equirectangular linear-RGB radiance map (see the module doc for the convention).
/// Invariant (kept by every constructor here): `texels.len() == width * height`.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvMap {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<Vec3>,
}

/// How many channel values were replaced by [`sanitize`]. Counts are per channel
/// value (a texel with NaN in R and G counts 2). −Inf counts as `inf` and becomes 0.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SanitizeReport {
    pub nan: usize,
    pub inf: usize,
    pub negative: usize,
}

impl SanitizeReport {
    /// Total number of replaced channel values.
    pub fn total(&self) -> usize {
        self.nan + self.inf + self.negative
    }

    pub(super) fn add(&mut self, other: SanitizeReport) {
        self.nan += other.nan;
        self.inf += other.inf;
        self.negative += other.negative;
    }
}

// ---------------------------------------------------------------------------
// Direction convention
// ---------------------------------------------------------------------------

/// World direction for equirect coordinates `(u, v)` (module doc convention).
pub fn direction(u: f32, v: f32) -> Vec3 {
    let theta = std::f32::consts::PI * v;
    let phi = std::f32::consts::TAU * (u - 0.5);
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3::new(st * sp, ct, -st * cp)
}

/// Inverse of [`direction`]: `u ∈ [0, 1]`, `v ∈ [0, 1]`. `d` need not be unit
/// length; a zero or non-finite `d` gives `(0.5, 0.5)`.
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let d = d.normalize_or_zero();
    if d == Vec3::ZERO {
        return Vec2::new(0.5, 0.5);
    }
    let u = d.x.atan2(-d.z) / std::f32::consts::TAU + 0.5;
    let v = d.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
    Vec2::new(u, v)
}

/// Exact solid angle (sr) of any texel in row `y` of a `width × height` map:
/// `(2π/W)(cos θ0 − cos θ1)`. Zero for empty maps or rows outside the map.
pub fn texel_solid_angle(y: u32, width: u32, height: u32) -> f32 {
    texel_solid_angle_f64(y, width, height) as f32
}

pub(crate) fn texel_solid_angle_f64(y: u32, width: u32, height: u32) -> f64 {
    if width == 0 || height == 0 || y >= height {
        return 0.0;
    }
    let pi = std::f64::consts::PI;
    let t0 = pi * f64::from(y) / f64::from(height);
    let t1 = pi * (f64::from(y) + 1.0) / f64::from(height);
    std::f64::consts::TAU / f64::from(width) * (t0.cos() - t1.cos())
}

/// Clamp a requested size into `[1, MAX_WIDTH] × [1, …]` with at most
/// `MAX_TEXELS` texels.
fn clamp_size(width: u32, height: u32) -> (u32, u32) {
    let w = width.clamp(1, MAX_WIDTH);
    let max_h = (MAX_TEXELS / u64::from(w)).min(u64::from(u32::MAX)) as u32;
    (w, height.clamp(1, max_h))
}

pub(super) fn size_ok(width: u32, height: u32) -> bool {
    width >= 1
        && height >= 1
        && width <= MAX_WIDTH
        && u64::from(width) * u64::from(height) <= MAX_TEXELS
}

// ---------------------------------------------------------------------------
// EnvMap
// ---------------------------------------------------------------------------

impl EnvMap {
    /// Constant radiance `rgb` everywhere. Sizes are clamped to at least 1 and at
    /// most [`MAX_WIDTH`] / [`MAX_TEXELS`].
    pub fn uniform(rgb: Vec3, width: u32, height: u32) -> EnvMap {
        let (width, height) = clamp_size(width, height);
        EnvMap {
            width,
            height,
            texels: vec![rgb; width as usize * height as usize],
        }
    }

    /// Build a map by evaluating `f(direction)` at every texel centre. Sizes are
    /// clamped like [`EnvMap::uniform`].
    pub fn from_fn(width: u32, height: u32, mut f: impl FnMut(Vec3) -> Vec3) -> EnvMap {
        let (width, height) = clamp_size(width, height);
        let mut texels = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            let v = (y as f32 + 0.5) / height as f32;
            for x in 0..width {
                let u = (x as f32 + 0.5) / width as f32;
                texels.push(f(direction(u, v)));
            }
        }
        EnvMap {
            width,
            height,
            texels,
        }
    }

    /// Texel `(x, y)`; zero outside the map.
    pub fn texel(&self, x: u32, y: u32) -> Vec3 {
        if x >= self.width || y >= self.height {
            return Vec3::ZERO;
        }
        let i = y as usize * self.width as usize + x as usize;
        self.texels.get(i).copied().unwrap_or(Vec3::ZERO)
    }

    /// Direction through the centre of texel `(x, y)`.
    pub fn texel_direction(&self, x: u32, y: u32) -> Vec3 {
        let u = (x as f32 + 0.5) / self.width.max(1) as f32;
        let v = (y as f32 + 0.5) / self.height.max(1) as f32;
        direction(u, v)
    }

    /// Bilinear lookup at `(u, v)`: wraps in u, clamps in v (texel centres at
    /// `(x + 0.5) / W`).
    pub fn sample_uv(&self, uv: Vec2) -> Vec3 {
        if self.width == 0 || self.height == 0 || !uv.is_finite() {
            return Vec3::ZERO;
        }
        let w = self.width as f32;
        let h = self.height as f32;
        let fx = uv.x * w - 0.5;
        let fy = (uv.y * h - 0.5).clamp(0.0, h - 1.0);
        let x0f = fx.floor();
        let y0f = fy.floor();
        let tx = fx - x0f;
        let ty = fy - y0f;
        let wrap = |x: f32| -> u32 { (x.rem_euclid(w) as u32).min(self.width - 1) };
        let x0 = wrap(x0f);
        let x1 = wrap(x0f + 1.0);
        let y0 = (y0f as u32).min(self.height - 1);
        let y1 = (y0 + 1).min(self.height - 1);
        let top = self.texel(x0, y0).lerp(self.texel(x1, y0), tx);
        let bottom = self.texel(x0, y1).lerp(self.texel(x1, y1), tx);
        top.lerp(bottom, ty)
    }

    /// Bilinear lookup of the radiance arriving from direction `d`.
    pub fn sample_dir(&self, d: Vec3) -> Vec3 {
        self.sample_uv(direction_to_uv(d))
    }

    /// Solid-angle weighted mean radiance (irradiance-free average over 4π).
    pub fn mean(&self) -> Vec3 {
        let mut acc = [0.0f64; 3];
        for y in 0..self.height {
            let w = texel_solid_angle_f64(y, self.width, self.height);
            for x in 0..self.width {
                let t = self.texel(x, y);
                acc[0] += f64::from(t.x) * w;
                acc[1] += f64::from(t.y) * w;
                acc[2] += f64::from(t.z) * w;
            }
        }
        let s = 1.0 / (4.0 * std::f64::consts::PI);
        Vec3::new(
            (acc[0] * s) as f32,
            (acc[1] * s) as f32,
            (acc[2] * s) as f32,
        )
    }

    /// The content rotated about +Y by `degrees` (right-handed: positive is
    /// counter-clockwise seen from above, +X toward −Z). Radiance from `d` moves
    /// to `Mat3::from_rotation_y(degrees.to_radians()) · d`. A rotation about the
    /// pole is a pure shift in u, so each row is resampled with linear
    /// interpolation along u (exact for whole-texel shifts).
    pub fn rotated_y(&self, degrees: f32) -> EnvMap {
        if self.width == 0 || self.height == 0 || !degrees.is_finite() {
            return self.clone();
        }
        // R_y(α) maps φ → φ − α, so new(φ) = old(φ + α): source x = x + α/2π · W.
        let shift = f64::from(degrees).to_radians() / std::f64::consts::TAU * f64::from(self.width);
        let shift = shift.rem_euclid(f64::from(self.width));
        let whole = shift.floor();
        let frac = (shift - whole) as f32;
        let whole = whole as u32;
        let mut texels = Vec::with_capacity(self.texels.len());
        for y in 0..self.height {
            for x in 0..self.width {
                let x0 = ((u64::from(x) + u64::from(whole)) % u64::from(self.width)) as u32;
                let x1 = ((u64::from(x0) + 1) % u64::from(self.width)) as u32;
                texels.push(self.texel(x0, y).lerp(self.texel(x1, y), frac));
            }
        }
        EnvMap {
            width: self.width,
            height: self.height,
            texels,
        }
    }

    /// The content rotated by the 3×3 rotation `r` (radiance from `d` moves to
    /// `r·d`), bilinear resampling. Prefer [`EnvMap::rotated_y`] for yaw.
    pub fn rotated(&self, r: Mat3) -> EnvMap {
        let inv = r.transpose();
        EnvMap::from_fn(self.width, self.height, |d| self.sample_dir(inv * d))
    }

    /// Replace NaN / ±Inf / negative channel values in place (see [`sanitize`]).
    pub fn sanitize(&mut self) -> SanitizeReport {
        sanitize(&mut self.texels)
    }
}

/// Radiance beyond any physical source (the sun's disc is ~1e9 cd/m²), where a
/// map's sums (mips, SH, the lights' power) would overflow f32: a decoder's
/// value above it (an RGBE file of maximum exponents, ~1.7e38) counts as +Inf.
pub const MAX_RADIANCE: f32 = 1e20;

/// Replace bad channel values in place: NaN → 0, negative (incl. −Inf) → 0,
/// +Inf and values above [`MAX_RADIANCE`] → [`HALF_MAX`]. Returns per-kind
/// counts (per channel value).
pub fn sanitize(texels: &mut [Vec3]) -> SanitizeReport {
    let mut r = SanitizeReport::default();
    for t in texels.iter_mut() {
        for c in [&mut t.x, &mut t.y, &mut t.z] {
            if c.is_nan() {
                r.nan += 1;
                *c = 0.0;
            } else if c.is_infinite() || *c > MAX_RADIANCE {
                r.inf += 1;
                *c = if *c > 0.0 { HALF_MAX } else { 0.0 };
            } else if *c < 0.0 {
                r.negative += 1;
                *c = 0.0;
            }
        }
    }
    r
}
#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    #[test]
    fn direction_convention() {
        let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-6;
        assert!(close(direction(0.5, 0.5), Vec3::NEG_Z));
        assert!(close(direction(0.75, 0.5), Vec3::X));
        assert!(close(direction(0.25, 0.5), Vec3::NEG_X));
        assert!(close(direction(0.0, 0.5), Vec3::Z));
        assert!(close(direction(0.3, 0.0), Vec3::Y));
        assert!(close(direction(0.3, 1.0), Vec3::NEG_Y));
        for i in 0..50 {
            let u = (i as f32 * 0.137).fract() * 0.98 + 0.01;
            let v = (i as f32 * 0.291).fract() * 0.98 + 0.01;
            let uv = direction_to_uv(direction(u, v));
            assert!((uv - Vec2::new(u, v)).length() < 1e-4, "{u} {v} {uv}");
        }
    }

    #[test]
    fn solid_angles_sum_to_4pi() {
        let (w, h) = (64, 32);
        let total: f64 = (0..h)
            .map(|y| texel_solid_angle_f64(y, w, h) * w as f64)
            .sum();
        assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-9);
        // Against the small-texel approximation sinθ·dθ·dφ at the equator row.
        let y = h / 2;
        let approx =
            (PI / h as f32) * (2.0 * PI / w as f32) * (PI * (y as f32 + 0.5) / h as f32).sin();
        assert!((texel_solid_angle(y, w, h) - approx).abs() / approx < 1e-3);
        assert_eq!(texel_solid_angle(0, 0, 0), 0.0);
        assert_eq!(texel_solid_angle(40, 64, 32), 0.0);
    }

    #[test]
    fn rotated_y_moves_features() {
        // A bright texel at d0 must reappear at R·d0.
        let (w, h) = (72, 36);
        let mut env = EnvMap::uniform(Vec3::ZERO, w, h);
        let (x0, y0) = (10u32, 12u32);
        env.texels[(y0 * w + x0) as usize] = Vec3::ONE;
        let d0 = env.texel_direction(x0, y0);
        let deg = 50.0; // 10 texels at 5° each: a whole-texel shift
        let rot = env.rotated_y(deg);
        let (mut best, mut bx, mut by) = (0.0, 0, 0);
        for y in 0..h {
            for x in 0..w {
                if rot.texel(x, y).x > best {
                    (best, bx, by) = (rot.texel(x, y).x, x, y);
                }
            }
        }
        let expect = Mat3::from_rotation_y(deg.to_radians()) * d0;
        assert!((rot.texel_direction(bx, by) - expect).length() < 1e-4);
        assert!((best - 1.0).abs() < 1e-5);
        // Positive angle: +X goes toward −Z (counter-clockwise seen from above).
        assert!((Mat3::from_rotation_y(0.5 * PI) * Vec3::X - Vec3::NEG_Z).length() < 1e-6);
        // Fractional shifts keep energy.
        let frac = env.rotated_y(37.3);
        let s0: f32 = env.texels.iter().map(|t| t.x).sum();
        let s1: f32 = frac.texels.iter().map(|t| t.x).sum();
        assert!((s0 - s1).abs() < 1e-5);
    }

    #[test]
    fn sanitize_counts() {
        let mut env = EnvMap::uniform(Vec3::splat(0.5), 8, 4);
        env.texels[0] = Vec3::new(f32::NAN, 1.0, f32::NAN);
        env.texels[1] = Vec3::new(f32::INFINITY, -2.0, f32::NEG_INFINITY);
        env.texels[2] = Vec3::new(-0.0, -1e-9, 3.0);
        env.texels[3] = Vec3::new(1e9, f32::MAX, 0.5);
        let r = env.sanitize();
        assert_eq!(
            r,
            SanitizeReport {
                nan: 2,
                inf: 3,
                negative: 2
            }
        );
        assert_eq!(env.texels[0], Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(env.texels[3], Vec3::new(1e9, HALF_MAX, 0.5));
        assert_eq!(env.texels[1], Vec3::new(HALF_MAX, 0.0, 0.0));
        assert_eq!(env.texels[2].y, 0.0);
        assert!(env
            .texels
            .iter()
            .all(|t| t.is_finite() && t.min_element() >= 0.0));
    }
}
