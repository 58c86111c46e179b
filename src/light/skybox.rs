//! The environment seen through the camera, behind the head: a free function,
//! its pipeline from the render's cache (gpu::Pipelines).

use crate::error::Result;
use crate::frame_inputs::{FrameInputs, DEPTH_FORMAT, HDR_FORMAT};
use crate::gpu::{GraphicsDesc, Pipelines};
use crate::graph::{Access, Graph, ImageHandle, LoadOp};

/// Clears `hdr` to the environment behind the camera, or (`sky` false) to
/// transparent black; alpha 0 either way, so the mesh's passes make alpha its
/// coverage. With the mesh's `depth` (the final pass's pre-pass), the
/// environment is drawn only where no surface is: the triangle lies at the far
/// plane and the depth test keeps the pixels the mesh covers from being shaded
/// twice (they stay transparent black until the mesh's pass writes them).
pub fn pass(
    g: &mut Graph,
    pipelines: &Pipelines,
    inputs: &FrameInputs,
    hdr: &mut ImageHandle,
    sky: bool,
    depth: Option<&mut ImageHandle>,
) -> Result<()> {
    if !sky {
        let mut p = g.add_pass("background");
        let r = p.write(hdr, Access::TransferDst);
        p.record(move |cx| cx.clear_image(r, [0.0; 4]));
        return Ok(());
    }
    let mut desc = GraphicsDesc::fullscreen("background.frag", &[HDR_FORMAT]);
    desc.depth_format = depth.is_some().then_some(DEPTH_FORMAT);
    let pipeline = pipelines.graphics(&desc)?;
    let size = [hdr.desc.width as f32, hdr.desc.height as f32];
    let mut pass = g
        .simple_pass("background", &pipeline)
        .uniform(&inputs.uniforms)
        .texture(&inputs.env, &inputs.env_sampler)
        .color(hdr, LoadOp::Clear([0.0; 4]));
    if let Some(depth) = depth {
        pass = pass.depth(depth, LoadOp::Load);
    }
    pass.constants(&size).draw(3);
    Ok(())
}
