//! Glow (bloom) on the HDR image, d'Eon & Luebke's (GPU Gems 3 ch. 14): the
//! film/eye falloff (1 − r/d)⁴ of Pharr & Humphreys' bloom (Physically Based
//! Rendering, 2004) approximated as a sum of two Gaussians, 0.0174·G(0.008, r) +
//! 0.192·G(0.0576, r) with G(v, r) = exp(−r²/2v)/(2πv) (constants from the
//! project's design card). The fit is to the falloff with
//! d = 1: it integrates to 0.2094 = 2π/30, the integral of (1 − r)⁴ over the
//! disc, and meets it at r = 0.2 and 0.5 within 0.01. dermis takes d = the image
//! height: r and √v are fractions of the height, so the glow keeps its look
//! at any resolution (pbrt likewise sizes its bloom as a fraction of the image).
//!
//! Output = HDR + intensity · (kernel ∗ HDR); alpha (coverage) is kept. Each
//! Gaussian is blurred separably on a box-filtered mip level where its σ still
//! spans [`MIN_SIGMA_TEXELS`] texels; the box and the bilinear upsampling add
//! ¼ texel² of that level, which the blur leaves out ([`level_for`]).
//! Passes: `glow_downK` (K = 1…), `glowI_u`, `glowI_v` (I = 1, 2), `glow`.

use crate::error::Result;
use crate::frame_inputs::HDR_FORMAT;
use crate::gpu::{GraphicsDesc, ImageDesc, Pipeline, Pipelines, Sampler};
use crate::graph::{Graph, ImageHandle, LoadOp};
use std::sync::Arc;

/// (weight, variance in image heights²) of each Gaussian.
pub const GAUSSIANS: [(f32, f32); 2] = [(0.0174, 0.008), (0.192, 0.0576)];
/// Smallest σ, in texels of its level, a Gaussian is blurred at: its ¼ texel²
/// of box and tent is then under 1.6 % of its variance.
pub const MIN_SIGMA_TEXELS: f32 = 4.0;

/// G(v, r) = exp(−r²/2v)/(2πv): the 2-D Gaussian of variance v per axis.
pub fn gaussian(v: f32, r: f32) -> f32 {
    (-r * r / (2.0 * v)).exp() / (2.0 * std::f32::consts::PI * v)
}

/// The glow kernel at `r` image heights (per image height², integrating to
/// 0.2094 over the plane).
pub fn kernel(r: f32) -> f32 {
    GAUSSIANS.iter().map(|&(w, v)| w * gaussian(v, r)).sum()
}

/// The mip level k (2^k pixels per texel) a Gaussian of variance `v_pixels`
/// (pixels²) is blurred at, and the σ in that level's texels that gives the
/// variance once the level's box (4^k − 1)/12 px² and its bilinear upsampling
/// 4^k/6 + 1/12 px² (the mean over the 2^k pixel phases) are added: ¼ texel²
/// together. Level 0 is the image itself, with neither.
pub fn level_for(v_pixels: f32) -> (u32, f32) {
    let mut k = 0;
    while v_pixels.sqrt() / 2f32.powi(k as i32 + 1) >= MIN_SIGMA_TEXELS {
        k += 1;
    }
    let texel2 = 4f32.powi(k as i32);
    let extra = if k == 0 { 0.0 } else { 0.25 };
    (k, (v_pixels / texel2 - extra).sqrt())
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct BlurPush {
    dir: [i32; 2],
    sigma: f32,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct CompositePush {
    /// Weight × intensity of each Gaussian.
    weights: [f32; 2],
    /// Pixels per texel of each Gaussian's level (2^k).
    scale: [f32; 2],
}

pub struct Glow {
    down: Arc<Pipeline>,
    blur: Arc<Pipeline>,
    composite: Arc<Pipeline>,
    nearest: Arc<Sampler>,
    linear: Arc<Sampler>,
}

impl Glow {
    pub fn new(pipelines: &Pipelines, nearest: Arc<Sampler>, linear: Arc<Sampler>) -> Result<Self> {
        Ok(Self {
            down: pipelines.compute("glow_down.comp", &[])?,
            blur: pipelines.compute("glow_blur.comp", &[])?,
            composite: pipelines.graphics(&GraphicsDesc::fullscreen("glow.frag", &[HDR_FORMAT]))?,
            nearest,
            linear,
        })
    }

    /// `hdr` with its glow at `intensity` added: a new image.
    pub fn pass(&self, g: &mut Graph, hdr: &ImageHandle, intensity: f32) -> ImageHandle {
        let (w, h) = (hdr.desc.width, hdr.desc.height);
        let plan = GAUSSIANS.map(|(_, v)| level_for(v * (h * h) as f32));
        let deepest = plan.iter().map(|&(k, _)| k).max().unwrap_or(0);
        let mut mips: Vec<ImageHandle> = Vec::new();
        for k in 1..=deepest {
            let src = mips.last().unwrap_or(hdr);
            let desc = ImageDesc::new(
                src.desc.width.div_ceil(2),
                src.desc.height.div_ceil(2),
                HDR_FORMAT,
            );
            let mut dst = g.create_image(&format!("glow mip{k}"), desc);
            g.simple_pass(&format!("glow_down{k}"), &self.down)
                .tag(super::TAG)
                .sample(src, &self.nearest)
                .store(&mut dst)
                .dispatch([desc.width, desc.height, 1]);
            mips.push(dst);
        }
        let blurred: Vec<ImageHandle> = plan
            .iter()
            .enumerate()
            .map(|(i, &(k, sigma))| {
                let src = if k == 0 { hdr } else { &mips[k as usize - 1] };
                let desc = ImageDesc::new(src.desc.width, src.desc.height, HDR_FORMAT);
                let name = format!("glow{}", i + 1);
                let mut tmp = g.create_image(&format!("{name} tmp"), desc);
                let mut out = g.create_image(&name, desc);
                self.blur_pass(g, &format!("{name}_u"), src, &mut tmp, [1, 0], sigma);
                self.blur_pass(g, &format!("{name}_v"), &tmp, &mut out, [0, 1], sigma);
                out
            })
            .collect();
        let mut out = g.create_image("glowed", ImageDesc::new(w, h, HDR_FORMAT));
        g.simple_pass("glow", &self.composite)
            .tag(super::TAG)
            .sample(hdr, &self.nearest)
            .sample(&blurred[0], &self.linear)
            .sample(&blurred[1], &self.linear)
            .color(&mut out, LoadOp::DontCare)
            .constants(&CompositePush {
                weights: GAUSSIANS.map(|(weight, _)| weight * intensity),
                scale: plan.map(|(k, _)| 2f32.powi(k as i32)),
            })
            .draw(3);
        out
    }

    fn blur_pass(
        &self,
        g: &mut Graph,
        name: &str,
        src: &ImageHandle,
        dst: &mut ImageHandle,
        dir: [i32; 2],
        sigma: f32,
    ) {
        let (w, h) = (dst.desc.width, dst.desc.height);
        g.simple_pass(name, &self.blur)
            .tag(super::TAG)
            .sample(src, &self.nearest)
            .store(dst)
            .constants(&BlurPush { dir, sigma })
            .dispatch([w, h, 1]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_two_gaussians_fit_the_falloff() {
        // ∫ (1 − r)⁴ 2πr dr over [0, 1] = 2π/30; the weights sum to it.
        let total: f32 = GAUSSIANS.iter().map(|&(w, _)| w).sum();
        assert!(
            (total - 2.0 * std::f32::consts::PI / 30.0).abs() < 1e-3,
            "{total}"
        );
        for r in [0.2f32, 0.3, 0.5, 0.7] {
            let falloff = (1.0 - r).powi(4);
            assert!(
                (kernel(r) - falloff).abs() < 0.015,
                "{r}: {} vs {falloff}",
                kernel(r)
            );
        }
    }

    #[test]
    fn levels_keep_the_variance_and_the_width_in_texels() {
        for v in [4.0f32, 100.0, 1200.0, 60_000.0] {
            let (k, sigma) = level_for(v);
            let extra = if k == 0 { 0.0 } else { 0.25 };
            let total = (sigma * sigma + extra) * 4f32.powi(k as i32);
            assert!((total - v).abs() < 1e-3 * v, "{v}: {k} {sigma}");
            assert!(
                k == 0 || sigma >= MIN_SIGMA_TEXELS - 0.1,
                "{v}: {k} {sigma}"
            );
            assert!(
                v.sqrt() / 2f32.powi(k as i32 + 1) < MIN_SIGMA_TEXELS,
                "{v}: {k}"
            );
        }
        // The test image of tests/it/post.rs: 160 pixels high.
        assert_eq!(level_for(0.008 * 160.0 * 160.0).0, 1);
        assert_eq!(level_for(0.0576 * 160.0 * 160.0).0, 3);
    }
}
