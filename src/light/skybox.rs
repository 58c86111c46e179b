//! The environment seen through the camera, behind the head.

use crate::error::Result;
use crate::frame::{FrameInputs, HDR_FORMAT};
use crate::gpu::{Context, GraphicsDesc, Pipeline};
use crate::graph::{Access, Graph, ImageHandle, LoadOp};
use std::sync::Arc;

pub struct SkyboxPass {
    pipeline: Arc<Pipeline>,
}

impl SkyboxPass {
    pub fn new(ctx: &Arc<Context>) -> Result<Self> {
        let pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc::fullscreen("background.frag", &[HDR_FORMAT]),
        )?;
        Ok(Self { pipeline })
    }

    /// Clears `hdr` to the environment behind the camera, or (`sky` false) to
    /// transparent black; alpha 0 either way, so the mesh's passes make alpha
    /// its coverage.
    pub fn pass(&self, g: &mut Graph, inputs: &FrameInputs, hdr: &mut ImageHandle, sky: bool) {
        if !sky {
            let mut p = g.add_pass("background");
            let r = p.write(hdr, Access::TransferDst);
            p.record(move |cx| cx.clear_image(r, [0.0; 4]));
            return;
        }
        let size = [hdr.desc.width as f32, hdr.desc.height as f32];
        g.simple_pass("background", &self.pipeline)
            .uniform(&inputs.uniforms)
            .texture(&inputs.env, &inputs.env_sampler)
            .color(hdr, LoadOp::Clear([0.0; 4]))
            .constants(&size)
            .draw(3);
    }
}
