//! The stretch maps (GPU Gems 3 §14.4.3; the paper's Fig. 3 top row): texels per
//! mm along u and v for every texel, and the chain of them blurred with the
//! profile's Gaussians (blurred level k−1 spaces the taps of level k). They depend
//! on the mesh alone, which is rigid for a render: they are computed in its first
//! frame, at most [`MAX_RESOLUTION`]² (stretch varies smoothly; the blur reads it
//! bilinearly at any resolution), and kept.

use super::blur::BlurChain;
use super::profile::Profile;
use super::{uv_pipeline, UV_FORMAT};
use crate::error::Result;
use crate::frame::MeshBuffers;
use crate::gpu::{Image, ImageDesc, Pipeline, Pipelines};
use crate::graph::{Access, Graph, ImageHandle, Imported, LoadOp};
use ash::vk;
use std::sync::Arc;

/// Largest side of the stretch maps.
pub const MAX_RESOLUTION: u32 = 1024;

pub struct StretchMaps {
    pipeline: Arc<Pipeline>,
    /// Levels 0 (unblurred) ..= 5: what blur levels 1..=6 are spaced by.
    levels: Vec<Arc<Image>>,
    /// `Some(texels_per_mm)` at the irradiance resolution: no stretch correction.
    constant: Option<f32>,
    increments: Vec<f32>,
    /// Irradiance resolution ÷ stretch resolution (a constant stretch is given
    /// at the irradiance resolution).
    scale: f32,
}

impl StretchMaps {
    /// Stretch maps for an irradiance chain at `resolution`² with `profile`.
    pub fn new(
        pipelines: &Pipelines,
        resolution: u32,
        profile: &Profile,
        constant: Option<f32>,
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
            pipeline: uv_pipeline(pipelines, "uv.vert", "stretch.frag", &[])?,
            levels,
            constant,
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
            let constant = self.constant.map_or(0.0, |c| c / self.scale);
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
