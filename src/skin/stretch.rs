//! The stretch maps (GPU Gems 3 §14.4.3; the paper's Fig. 3 top row): texels per
//! mm along u and v for every texel, and the chain of them blurred with the
//! profile's Gaussians (blurred level k−1 spaces the taps of level k). With
//! shear correction they hold the whole metric of the UV parametrisation, not
//! only its scale ([`StretchTensor`]: the U pass's stretch along ∂P/∂u, the V
//! pass's step along the surface direction perpendicular to it). They depend
//! on the mesh alone, which is rigid for a render: they are computed in its first
//! frame, at most [`MAX_RESOLUTION`]² (stretch varies smoothly; the blur reads it
//! bilinearly at any resolution), and kept.

use super::blur::BlurChain;
use super::profile::Profile;
use super::{uv_pipeline, UV_FORMAT};
use crate::error::Result;
use crate::frame_inputs::MeshBuffers;
use crate::gpu::{Image, ImageDesc, Pipeline, Pipelines};
use crate::graph::{Access, Graph, ImageHandle, Imported, LoadOp};
use ash::vk;
use glam::{Vec2, Vec3};
use std::sync::Arc;

/// Largest side of the stretch maps.
pub const MAX_RESOLUTION: u32 = 1024;

pub struct StretchMaps {
    pipeline: Arc<Pipeline>,
    /// Levels 0 (unblurred) ..= 5: what blur levels 1..=6 are spaced by.
    levels: Vec<Arc<Image>>,
    /// `Some(texels_per_mm)` at the irradiance resolution: no stretch correction.
    constant: Option<f32>,
    /// Store the UV shear (stretch.frag); off: the diagonal only.
    shear: bool,
    increments: Vec<f32>,
    /// Irradiance resolution ÷ stretch resolution (a constant stretch is given
    /// at the irradiance resolution).
    scale: f32,
}

impl StretchMaps {
    /// Stretch maps for an irradiance chain at `resolution`² with `profile`;
    /// `shear`: store the UV shear too (skin.shear_correction).
    pub fn new(
        pipelines: &Pipelines,
        resolution: u32,
        profile: &Profile,
        constant: Option<f32>,
        shear: bool,
    ) -> Result<Self> {
        let ctx = pipelines.ctx();
        let side = resolution.min(MAX_RESOLUTION);
        let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
            | vk::ImageUsageFlags::STORAGE
            | vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::TRANSFER_SRC;
        let mut increments = profile.increments();
        increments.truncate(increments.len().saturating_sub(1));
        let levels = (0..=increments.len())
            .map(|k| {
                let desc = ImageDesc::new(side, side, UV_FORMAT);
                Image::new(ctx, &format!("stretch{k}"), desc, usage).map(Arc::new)
            })
            .collect::<Result<_>>()?;
        Ok(Self {
            pipeline: uv_pipeline(pipelines, ("uv.vert", "stretch.frag"), &[UV_FORMAT], &[])?,
            levels,
            constant,
            shear,
            increments,
            scale: resolution as f32 / side as f32,
        })
    }

    /// The stretch levels 0..=5 as graph images, kept: the mesh is rigid for
    /// a render, so the first frame that needs them computes them (passes
    /// `stretch` and `stretch{k}_u/_v`).
    pub fn pass(&self, g: &mut Graph, mesh: &MeshBuffers, blur: &BlurChain) -> Vec<ImageHandle> {
        let mut first = false;
        let mut out: Vec<ImageHandle> = self
            .levels
            .iter()
            .enumerate()
            .map(|(k, image)| {
                let (level, stale) = g.import_kept_image(
                    &level_name(k),
                    Imported::Image(image.clone()),
                    Access::ShaderSampled,
                    0,
                );
                first |= stale;
                level
            })
            .collect();
        if first {
            let constant = StretchPush {
                constant_stretch: self.constant.map_or(0.0, |c| c / self.scale),
                shear: self.shear as u32,
            };
            let pass = g
                .simple_pass("stretch", &self.pipeline)
                .tag(super::TAG)
                .color(&mut out[0], LoadOp::Clear([0.0; 4]))
                .constants(&constant);
            mesh.draw(pass);
            for (k, &sigma) in self.increments.iter().enumerate() {
                let (done, rest) = out.split_at_mut(k + 1);
                let name = level_name(k + 1);
                blur.gaussian(g, &name, &done[k], &done[k], sigma, &mut rest[0]);
            }
        }
        out
    }
}

/// The name of stretch level `k` (a view's name): `stretch` (unblurred),
/// `stretch1`…`stretch5`.
pub fn level_name(k: usize) -> String {
    match k {
        0 => "stretch".into(),
        k => format!("stretch{k}"),
    }
}

/// stretch.frag's push constants.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct StretchPush {
    /// > 0: texels per mm everywhere (stretch correction off).
    constant_stretch: f32,
    /// 1: store the shear.
    shear: u32,
}

/// The first fundamental form of a parametrisation: with a = ∂P/∂u and b = ∂P/∂v
/// (mm per texel), `[E, F, G] = [a·a, a·b, b·b]` (mm² per texel²).
pub fn metric(a: Vec3, b: Vec3) -> [f32; 3] {
    [a.dot(a), a.dot(b), b.dot(b)]
}

/// What a stretch map texel holds (stretch.frag, CPU copy), in texels per mm:
/// the upper factor U = [[u, shear], [0, v]] of the inverse metric, M⁻¹ = U·Uᵀ.
/// The U pass steps `u` texels along the u axis per mm of surface along a =
/// ∂P/∂u; the V pass steps (`shear`, `v`) texels per mm of surface along b⊥,
/// the part of b = ∂P/∂v perpendicular to a. The two passes are then
/// orthogonal on the surface and each is σ mm wide there: their product is the
/// isotropic Gaussian on the surface. Without shear (a·b = 0) this is
/// (1/|a|, 1/|b|, 0), the old stretch map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StretchTensor {
    pub u: f32,
    pub v: f32,
    pub shear: f32,
}

impl StretchTensor {
    /// The tensor of the parametrisation with ∂P/∂u = `a`, ∂P/∂v = `b` (mm per
    /// texel); `shear = false`: the diagonal only, (1/|a|, 1/|b|, 0)
    /// (skin.shear_correction = false).
    pub fn of(a: Vec3, b: Vec3, shear: bool) -> Self {
        let u = 1.0 / a.length().max(1e-6);
        if !shear {
            return Self {
                u,
                v: 1.0 / b.length().max(1e-6),
                shear: 0.0,
            };
        }
        let [e, f, _] = metric(a, b);
        let k = if e > 1e-12 { f / e } else { 0.0 };
        let v = 1.0 / (b - k * a).length().max(1e-6);
        Self {
            u,
            v,
            shear: -k * v,
        }
    }

    /// The two passes' steps, in texels (u, v) per mm of surface: the U pass's
    /// along the u axis, the V pass's along the surface perpendicular of ∂P/∂u
    /// (blur.comp).
    pub fn steps(&self) -> [Vec2; 2] {
        [Vec2::new(self.u, 0.0), Vec2::new(self.shear, self.v)]
    }

    /// U·Uᵀ: the inverse metric M⁻¹ as [m11, m12, m22] (texels² per mm²).
    pub fn inverse_metric(&self) -> [f32; 3] {
        [
            self.u * self.u + self.shear * self.shear,
            self.shear * self.v,
            self.v * self.v,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Mat2;

    /// ∂P/∂u and ∂P/∂v of the affine map of a triangle from UV (texels) to
    /// positions (mm): the Jacobian solved from two edges.
    fn jacobian(p: [Vec3; 3], uv: [Vec2; 3]) -> (Vec3, Vec3) {
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
        // [e1 e2] = [a b]·[d1 d2] → [a b] = [e1 e2]·[d1 d2]⁻¹.
        let inv = Mat2::from_cols(d1, d2).inverse();
        let a = e1 * inv.x_axis.x + e2 * inv.x_axis.y;
        let b = e1 * inv.y_axis.x + e2 * inv.y_axis.y;
        (a, b)
    }

    /// A triangle whose UV axes meet at 53° on the surface (cos 0.6), u along x
    /// at 0.05 mm per texel, v at 0.08 mm per texel, and tilted out of the plane.
    fn sheared_triangle() -> (Vec3, Vec3) {
        let (cos, sin) = (0.6f32, 0.8f32);
        let tilt = |p: Vec3| Vec3::new(p.x, p.y * 0.6, p.y * 0.8);
        let at = |u: f32, v: f32| tilt(Vec3::new(0.05 * u + 0.08 * cos * v, 0.08 * sin * v, 0.0));
        let uv = [
            Vec2::new(10.0, 20.0),
            Vec2::new(40.0, 25.0),
            Vec2::new(15.0, 60.0),
        ];
        jacobian(uv.map(|t| at(t.x, t.y)), uv)
    }

    #[test]
    fn the_metric_of_a_sheared_triangle() {
        let (a, b) = sheared_triangle();
        let [e, f, g] = metric(a, b);
        println!("E {e:.6} F {f:.6} G {g:.6} mm²/texel²");
        assert!((e - 0.0025).abs() < 1e-7, "{e}");
        assert!((g - 0.0064).abs() < 1e-7, "{g}");
        assert!((f - 0.05 * 0.08 * 0.6).abs() < 1e-7, "{f}");
        // cos of the angle between the surface directions of u and v.
        assert!((f / (e * g).sqrt() - 0.6).abs() < 1e-5);
    }

    /// The two passes, each a 1-D Gaussian of σ mm along its step, make the
    /// UV-space covariance σ²·(s₁s₁ᵀ + s₂s₂ᵀ) (texels²); mapped to the surface by
    /// [a b] it must be σ²·I in the tangent plane.
    #[test]
    fn the_passes_make_an_isotropic_gaussian_on_the_surface() {
        let (a, b) = sheared_triangle();
        let surface_covariance = |t: StretchTensor| {
            let [s1, s2] = t.steps();
            let map = |s: Vec2| a * s.x + b * s.y;
            let (p1, p2) = (map(s1), map(s2));
            // Eigenvalues of p1p1ᵀ + p2p2ᵀ in its plane: the Gram matrix's.
            let (xx, xy, yy) = (p1.dot(p1), p1.dot(p2), p2.dot(p2));
            let mean = 0.5 * (xx + yy);
            let d = (0.25 * (xx - yy).powi(2) + xy * xy).sqrt();
            (mean + d, mean - d, xy)
        };
        let on = StretchTensor::of(a, b, true);
        let (major, minor, cross) = surface_covariance(on);
        println!(
            "on: eigen-variances {major:.6} {minor:.6} (σ = 1 mm), steps {:?}",
            on.steps()
        );
        assert!((major - 1.0).abs() < 1e-5 && (minor - 1.0).abs() < 1e-5);
        assert!(
            cross.abs() < 1e-5,
            "the passes are orthogonal on the surface: {cross}"
        );
        // M⁻¹ = U·Uᵀ.
        let [e, f, g] = metric(a, b);
        let det = e * g - f * f;
        let want = [g / det, -f / det, e / det];
        for (got, want) in on.inverse_metric().iter().zip(want) {
            assert!(
                (got - want).abs() < 1e-4 * want.abs().max(1.0),
                "{got} vs {want}"
            );
        }
        // The diagonal alone: 1 ± cos along the bisectors.
        let (major, minor, _) = surface_covariance(StretchTensor::of(a, b, false));
        println!("off: eigen-variances {major:.4} {minor:.4}");
        assert!((major - 1.6).abs() < 1e-4 && (minor - 0.4).abs() < 1e-4);
    }

    /// The scan (assets/default.toml): how sheared its UVs are, and the range
    /// of the stored tensor at the stretch maps' smallest and largest sides
    /// (256: a 256² irradiance; 1024: every irradiance from 1024² to 8192²).
    /// RGBA16F holds 3 significant digits (relative step ≤ 2⁻¹¹ after rounding)
    /// between 6.1·10⁻⁵ and 65504.
    #[test]
    fn the_scans_tensor_keeps_three_digits_in_half_floats() {
        let file = crate::scene::file::scene_by_name(None).unwrap();
        let mesh = crate::scene::load_mesh(&file).unwrap();
        let percentile = |v: &mut Vec<(f32, f64)>, q: f64| {
            v.sort_by(|a, b| a.0.total_cmp(&b.0));
            let total: f64 = v.iter().map(|x| x.1).sum();
            let mut acc = 0.0;
            for &(x, w) in v.iter() {
                acc += w;
                if acc >= q * total {
                    return x;
                }
            }
            v.last().unwrap().0
        };
        for side in [256.0f32, 1024.0] {
            // Per triangle, weighted by its UV area (the texels the blur sees).
            let (mut cos, mut u, mut v, mut shear) = (vec![], vec![], vec![], vec![]);
            for t in mesh.indices.chunks_exact(3) {
                let i = [t[0], t[1], t[2]].map(|i| i as usize);
                let uv = i.map(|i| mesh.uvs[i] * side);
                let area = 0.5 * (uv[1] - uv[0]).perp_dot(uv[2] - uv[0]).abs() as f64;
                if area < 1e-6 {
                    continue;
                }
                let (a, b) = jacobian(i.map(|i| mesh.positions[i]), uv);
                let [e, f, g] = metric(a, b);
                let st = StretchTensor::of(a, b, true);
                cos.push((f.abs() / (e * g).sqrt(), area));
                u.push((st.u, area));
                v.push((st.v, area));
                shear.push((st.shear.abs(), area));
            }
            let range = |x: &mut Vec<(f32, f64)>| [0.001, 0.5, 0.999].map(|q| percentile(x, q));
            let (ru, rv, rs) = (range(&mut u), range(&mut v), range(&mut shear));
            println!(
                "scan at {side}²: |cos(u, v)| median {:.2}, 90th percentile {:.2}; texels/mm \
                 (0.1 %, 50 %, 99.9 %): u {ru:.3?}, v⊥ {rv:.3?}, |shear| {rs:.3?}",
                percentile(&mut cos, 0.5),
                percentile(&mut cos, 0.9),
            );
            for x in [ru, rv] {
                assert!(x[0] > 1e-3 && x[2] < 1e4, "{x:?}");
            }
        }
    }

    #[test]
    fn without_shear_the_tensor_is_the_old_stretch() {
        let a = Vec3::new(0.03, 0.0, 0.04);
        let b = Vec3::new(0.0, 0.2, 0.0);
        for shear in [true, false] {
            let t = StretchTensor::of(a, b, shear);
            assert_eq!(t.u, 1.0 / a.length());
            assert_eq!(t.v, 1.0 / b.length());
            assert_eq!(t.shear, 0.0);
        }
    }
}
