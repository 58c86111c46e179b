//! The six-Gaussian blur chain (GPU Gems 3 §14.4.2; the paper's eq. 4-5 and
//! Fig. 3): level k blurs level k−1 by σ_k = √(v_k − v_{k−1}) mm, separably (U then
//! V), with taps spaced by the stretch map's level k−1 (skin::stretch). Levels
//! may be coarser than their predecessor (skin::chain): the U pass then writes
//! the new width, the V pass the new height. A level whose σ spans about a
//! texel or less (chain::Stencil) is blurred in one pass, `blurK`, by a 3×3 or
//! 5×5 stencil of its covariance (blur_narrow.comp), whichever kernel is chosen;
//! so is a narrow level that halves its predecessor's side (5×5 only).
//!
//! Every UV target is coverage-premultiplied (alpha = 1 on the mesh, 0 in the
//! gutter), so the chain is a plain linear convolution of (I·a, a) and dividing by
//! alpha at lookup gives the convolution normalised over the mesh: blurs never
//! pull the gutter's black into chart borders, however wide the kernel.

use super::chain::{Level, Stencil};
use super::fold::FoldPass;
use super::profile::Kernel;
use super::UV_FORMAT;
use crate::error::{Error, Result};
use crate::gpu::{Buffer, ImageDesc, Pipeline, Pipelines, Sampler};
use crate::graph::upload::upload_buffer;
use crate::graph::{Access, Graph, ImageHandle};
use std::sync::Arc;

/// Taps the fixed-kernel uniform block holds (blur.comp).
pub const MAX_FIXED_TAPS: usize = 32;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct BlurPush {
    dir: [i32; 2],
    sigma_mm: f32,
}

/// Which taps each blur pass uses.
#[derive(Clone, Debug, PartialEq)]
pub enum BlurKernel {
    /// A fixed kernel at offsets in σ (d'Eon's 7 taps at 1σ: the default, fast).
    Fixed(Kernel),
    /// Gaussian weights at ≤ min(0.5σ, 0.5 texel) spacing to ±4σ, computed per
    /// texel, σ² compensated for bilinear filtering (matches an exact Gaussian).
    Accurate,
}

pub struct BlurChain {
    pipeline: Arc<Pipeline>,
    /// Both directions of a narrow Gaussian (blur_narrow.comp), indexed by
    /// `Stencil as usize`, which is also the shader's FIVE constant.
    narrow: [Arc<Pipeline>; 2],
    /// The 5×5 stencil from a source of twice the side (HALF).
    narrow_halving: Arc<Pipeline>,
    taps: Arc<Buffer>,
    sampler: Arc<Sampler>,
    /// The stretch maps hold the shear (skin.shear_correction): the V pass
    /// may step across columns, so the U pass keeps the source's width.
    shear: bool,
}

impl BlurChain {
    /// `shear`: the stretch maps hold the UV shear (skin::stretch, `shear`).
    pub fn new(
        pipelines: &Pipelines,
        kernel: &BlurKernel,
        sampler: Arc<Sampler>,
        shear: bool,
    ) -> Result<Self> {
        let ctx = pipelines.ctx();
        // std140: one vec4 (offset in σ, weight, 0, 0) per tap.
        let mut taps = [[0.0f32; 4]; MAX_FIXED_TAPS];
        let tap_count = match kernel {
            BlurKernel::Fixed(k) => {
                if k.weights.len() > MAX_FIXED_TAPS {
                    return Err(Error::Input(format!(
                        "blur kernel of {} taps: at most {MAX_FIXED_TAPS}",
                        k.weights.len()
                    )));
                }
                for (t, (&o, &w)) in taps.iter_mut().zip(k.offsets_sigma.iter().zip(&k.weights)) {
                    *t = [o, w, 0.0, 0.0];
                }
                k.weights.len() as u32
            }
            BlurKernel::Accurate => 0,
        };
        Ok(Self {
            pipeline: pipelines.compute("blur.comp", &[tap_count])?,
            narrow: [
                pipelines.compute("blur_narrow.comp", &[Stencil::Three as u32, 0])?,
                pipelines.compute("blur_narrow.comp", &[Stencil::Five as u32, 0])?,
            ],
            narrow_halving: pipelines.compute("blur_narrow.comp", &[Stencil::Five as u32, 1])?,
            taps: upload_buffer(
                ctx,
                "blur kernel",
                bytemuck::cast_slice(&taps),
                Access::UniformRead,
            )?,
            sampler,
            shear,
        })
    }

    /// The blurred levels `levels` plans, in order (a level without a σ adds
    /// none: see [`BlurChain::select`]); level k's taps are spaced by
    /// `stretch[k − 1]`; with `fold`, each level's fold term follows its blur.
    pub fn chain(
        &self,
        g: &mut Graph,
        irradiance: &ImageHandle,
        stretch: &[ImageHandle],
        levels: &[Level],
        fold: Option<&FoldPass>,
    ) -> Vec<ImageHandle> {
        let mut out: Vec<ImageHandle> = Vec::new();
        for (k, level) in levels.iter().enumerate() {
            let name = Self::level_name(k + 1);
            let Some(sigma) = level.sigma_mm else {
                // The level is its predecessor's image.
                g.alias(&name, out.last().unwrap_or(irradiance));
                continue;
            };
            let desc = ImageDesc::new(level.resolution, level.resolution, UV_FORMAT);
            let mut dst = g.create_image(&name, desc);
            let src = out.last().unwrap_or(irradiance);
            if let Some(stencil) = level.one_pass {
                self.narrow(g, &name, (src, &stretch[k]), sigma, stencil, &mut dst);
            } else {
                self.gaussian(g, &name, src, &stretch[k], sigma, &mut dst);
            }
            if let Some(fold) = fold {
                fold.pass(g, k, src, &mut dst);
            }
            out.push(dst);
        }
        out
    }

    /// The name of blur level `k` (1..=6; a view's name).
    pub fn level_name(k: usize) -> String {
        format!("blur{k}")
    }

    /// The image of each of the six levels: the level's own blur, or for a
    /// level without a σ its predecessor's (the first's: the irradiance).
    pub fn select<'a>(
        irradiance: &'a ImageHandle,
        blurred: &'a [ImageHandle],
        levels: &[Level],
    ) -> Vec<&'a ImageHandle> {
        let mut next = blurred.iter();
        let mut out: Vec<&ImageHandle> = Vec::new();
        for level in levels {
            let previous = out.last().copied().unwrap_or(irradiance);
            out.push(match level.sigma_mm {
                Some(_) => next.next().unwrap_or(previous),
                None => previous,
            });
        }
        out
    }

    /// One Gaussian of σ mm, separably, from `src` into `dst` (whose side may be
    /// smaller): `{name}_u` writes dst's width × src's height, `{name}_v` dst.
    /// With shear the V pass's taps leave their column, and linear
    /// interpolation across a narrowed intermediate's columns would widen the
    /// blur along u by 1/6 of its texel² (13 % of a level's variance at 4×
    /// narrower, tests/it/skin_diffusion.rs): `{name}_u` then keeps src's width
    /// and `{name}_v` alone shrinks it.
    pub fn gaussian(
        &self,
        g: &mut Graph,
        name: &str,
        src: &ImageHandle,
        stretch: &ImageHandle,
        sigma_mm: f32,
        dst: &mut ImageHandle,
    ) {
        let width = if self.shear {
            src.desc.width
        } else {
            dst.desc.width
        };
        let tmp_desc = ImageDesc::new(width, src.desc.height, UV_FORMAT);
        let mut tmp = g.create_image(&format!("{name}_tmp"), tmp_desc);
        let along = |dir| BlurPush { dir, sigma_mm };
        let u = format!("{name}_u");
        self.pass(g, &u, (src, stretch), &mut tmp, along([1, 0]));
        self.pass(g, &format!("{name}_v"), (&tmp, stretch), dst, along([0, 1]));
    }

    /// One narrow Gaussian of σ mm over `stencil`, both directions in one pass
    /// `name`, from `src` into `dst` of the same size or, with the 5×5
    /// stencil, half of it (blur_narrow.comp).
    pub fn narrow(
        &self,
        g: &mut Graph,
        name: &str,
        (src, stretch): (&ImageHandle, &ImageHandle),
        sigma_mm: f32,
        stencil: Stencil,
        dst: &mut ImageHandle,
    ) {
        let (w, h) = (dst.desc.width, dst.desc.height);
        let pipeline = if src.desc.width == w {
            &self.narrow[stencil as usize]
        } else {
            assert!(stencil == Stencil::Five && src.desc.width == 2 * w);
            &self.narrow_halving
        };
        g.simple_pass(name, pipeline)
            .tag(super::TAG)
            .sample(src, &self.sampler)
            .sample(stretch, &self.sampler)
            .store(dst)
            .constants(&sigma_mm)
            .dispatch([w, h, 1]);
    }

    fn pass(
        &self,
        g: &mut Graph,
        name: &str,
        (src, stretch): (&ImageHandle, &ImageHandle),
        dst: &mut ImageHandle,
        push: BlurPush,
    ) {
        let (w, h) = (dst.desc.width, dst.desc.height);
        g.simple_pass(name, &self.pipeline)
            .tag(super::TAG)
            .sample(src, &self.sampler)
            .sample(stretch, &self.sampler)
            .store(dst)
            .uniform(&self.taps)
            .constants(&push)
            .dispatch([w, h, 1]);
    }
}
