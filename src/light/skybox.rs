//! The environment seen through the camera, behind the head: a free function,
//! its pipeline from the render's cache (gpu::Pipelines).

use crate::error::Result;
use crate::frame::{FrameInputs, HDR_FORMAT};
use crate::gpu::{GraphicsDesc, Pipelines};
use crate::graph::{Access, Graph, ImageHandle, LoadOp};

/// Clears `hdr` to the environment behind the camera, or (`sky` false) to
/// transparent black; alpha 0 either way, so the mesh's passes make alpha its
/// coverage.
pub fn pass(
    g: &mut Graph,
    pipelines: &Pipelines,
    inputs: &FrameInputs,
    hdr: &mut ImageHandle,
    sky: bool,
) -> Result<()> {
    if !sky {
        let mut p = g.add_pass("background");
        let r = p.write(hdr, Access::TransferDst);
        p.record(move |cx| cx.clear_image(r, [0.0; 4]));
        return Ok(());
    }
    let pipeline =
        pipelines.graphics(&GraphicsDesc::fullscreen("background.frag", &[HDR_FORMAT]))?;
    let size = [hdr.desc.width as f32, hdr.desc.height as f32];
    g.simple_pass("background", &pipeline)
        .uniform(&inputs.uniforms)
        .texture(&inputs.env, &inputs.env_sampler)
        .color(hdr, LoadOp::Clear([0.0; 4]))
        .constants(&size)
        .draw(3);
    Ok(())
}
