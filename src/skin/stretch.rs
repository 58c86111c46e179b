//! The stretch map (GPU Gems 3 §14.4.3; the paper's Fig. 3 top row): texels per
//! mm along u and v for every texel, recomputed every frame so deforming meshes
//! work.

use super::{uv_pipeline, UV_FORMAT};
use crate::error::Result;
use crate::frame::MeshBuffers;
use crate::gpu::{Context, ImageDesc, Pipeline};
use crate::graph::{Graph, ImageHandle, LoadOp};
use std::sync::Arc;

pub struct StretchPass {
    pipeline: Arc<Pipeline>,
}

impl StretchPass {
    pub fn new(ctx: &Arc<Context>) -> Result<Self> {
        Ok(Self {
            pipeline: uv_pipeline(ctx, "uv.vert", "stretch.frag", &[])?,
        })
    }

    /// `constant`: `Some(texels_per_mm)` disables stretch correction.
    pub fn pass(
        &self,
        g: &mut Graph,
        mesh: &MeshBuffers,
        resolution: u32,
        constant: Option<f32>,
    ) -> ImageHandle {
        let mut out = g.create_image("stretch", ImageDesc::new(resolution, resolution, UV_FORMAT));
        let pass = g
            .simple_pass("stretch", &self.pipeline)
            .color(&mut out, LoadOp::Clear([0.0; 4]))
            .constants(&constant.unwrap_or(0.0));
        mesh.draw(pass);
        out
    }
}
