//! The six-Gaussian blur chain (GPU Gems 3 §14.4.2; the paper's eq. 4-5 and
//! Fig. 3): level k blurs level k−1 by σ_k = √(v_k − v_{k−1}) mm, separably (U then
//! V), with taps spaced by the stretch map, which is blurred alongside.
//!
//! Every UV target is coverage-premultiplied (alpha = 1 on the mesh, 0 in the
//! gutter), so the chain is a plain linear convolution of (I·a, a) and dividing by
//! alpha at lookup gives the convolution normalised over the mesh: blurs never
//! pull the gutter's black into chart borders, however wide the kernel.

use super::profile::{Kernel, Profile};
use super::UV_FORMAT;
use crate::error::Result;
use crate::gpu::{Buffer, Context, Pipeline, Sampler};
use crate::graph::upload::upload_buffer;
use crate::graph::{Access, Graph, ImageHandle};
use std::sync::Arc;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct BlurPush {
    dir: [i32; 2],
    sigma_mm: f32,
    tap_count: i32,
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
    taps: Arc<Buffer>,
    /// 0 selects the accurate kernel in the shader.
    tap_count: i32,
    sampler: Arc<Sampler>,
}

/// The chain's outputs: irradiance levels 1..=6 and the stretch levels blurred
/// alongside (level k's taps are spaced by stretch level k−1).
pub struct Levels {
    pub irradiance: Vec<ImageHandle>,
    pub stretch: Vec<ImageHandle>,
}

impl BlurChain {
    pub fn new(ctx: &Arc<Context>, kernel: &BlurKernel, sampler: Arc<Sampler>) -> Result<Self> {
        let taps: Vec<[f32; 2]> = match kernel {
            BlurKernel::Fixed(k) => k
                .offsets_sigma
                .iter()
                .zip(&k.weights)
                .map(|(&o, &w)| [o, w])
                .collect(),
            // The buffer must exist (the shader declares it); the accurate path ignores it.
            BlurKernel::Accurate => vec![[0.0, 1.0]],
        };
        let tap_count = match kernel {
            BlurKernel::Fixed(_) => taps.len() as i32,
            BlurKernel::Accurate => 0,
        };
        Ok(Self {
            pipeline: Pipeline::compute(ctx, "blur.comp")?,
            taps: upload_buffer(
                ctx,
                "blur kernel",
                bytemuck::cast_slice(&taps),
                Access::ComputeBufferRead,
            )?,
            tap_count,
            sampler,
        })
    }

    pub fn chain(
        &self,
        g: &mut Graph,
        irradiance: &ImageHandle,
        stretch: &ImageHandle,
        profile: &Profile,
    ) -> Levels {
        let mut levels = Levels {
            irradiance: Vec::new(),
            stretch: Vec::new(),
        };
        let desc = irradiance.desc;
        for (k, sigma) in profile.increments().into_iter().enumerate() {
            let (src_i, src_s) = match k {
                0 => (irradiance, stretch),
                _ => (&levels.irradiance[k - 1], &levels.stretch[k - 1]),
            };
            let mut tmp_i = g.create_image("blur_tmp", desc);
            let mut tmp_s = g.create_image("stretch_tmp", desc);
            self.pass(
                g,
                &format!("blur{}_u", k + 1),
                (src_i, src_s),
                (&mut tmp_i, &mut tmp_s),
                [1, 0],
                sigma,
            );
            let mut out_i = g.create_image(&format!("blur{}", k + 1), desc);
            let mut out_s = g.create_image(&format!("stretch{}", k + 1), desc);
            self.pass(
                g,
                &format!("blur{}_v", k + 1),
                (&tmp_i, &tmp_s),
                (&mut out_i, &mut out_s),
                [0, 1],
                sigma,
            );
            levels.irradiance.push(out_i);
            levels.stretch.push(out_s);
        }
        debug_assert!(desc.format == UV_FORMAT);
        levels
    }

    fn pass(
        &self,
        g: &mut Graph,
        name: &str,
        src: (&ImageHandle, &ImageHandle),
        dst: (&mut ImageHandle, &mut ImageHandle),
        dir: [i32; 2],
        sigma_mm: f32,
    ) {
        let (w, h) = (dst.0.desc.width, dst.0.desc.height);
        g.simple_pass(name, &self.pipeline)
            .sample(src.0, &self.sampler)
            .sample(src.1, &self.sampler)
            .store(dst.0)
            .store(dst.1)
            .buffer(&self.taps)
            .constants(&BlurPush {
                dir,
                sigma_mm,
                tap_count: self.tap_count,
            })
            .dispatch([w, h, 1]);
    }
}
