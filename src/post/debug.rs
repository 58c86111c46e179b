//! The screen-space debug views of the mesh (the paper's §IV debug mode):
//! linear depth, the shading normal, the albedo and the face regions, drawn over
//! a cleared image in one mesh pass (`debug_view`). Values are shown as they
//! are (post::Display::data), the albedo as a colour.

use crate::error::Result;
use crate::frame_inputs::{upload_rgba8, FrameInputs, Vertex, DEPTH_FORMAT, HDR_FORMAT};
use crate::gpu::{GraphicsDesc, Image, ImageDesc, Pipeline, Pipelines};
use crate::graph::{Graph, ImageHandle, LoadOp};
use crate::scene::texture::Texture;
use ash::vk;
use glam::Vec3;
use std::sync::Arc;

/// What the pass draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DebugView {
    /// Distance z along the view axis, 1 (white) at the mesh's nearest vertex
    /// to 0 at its farthest: `(far − z) / (far − near)`.
    Depth = 0,
    /// The shading normal after the normal map, world space, 0.5·n + 0.5.
    Normals = 1,
    /// The albedo map, linear.
    Albedo = 2,
    /// The region map's ids in the Tableau 10 colours (ids ≥ 10 black).
    Regions = 3,
}

impl DebugView {
    pub const ALL: [DebugView; 4] = [
        DebugView::Depth,
        DebugView::Normals,
        DebugView::Albedo,
        DebugView::Regions,
    ];

    /// The view's name (`render --view`).
    pub fn name(self) -> &'static str {
        match self {
            DebugView::Depth => "depth",
            DebugView::Normals => "normals",
            DebugView::Albedo => "albedo",
            DebugView::Regions => "regions",
        }
    }

    /// How the view is shown: the albedo is a fraction, the rest data.
    pub fn shown(self) -> super::Shown {
        match self {
            DebugView::Albedo => super::Shown::Fraction,
            DebugView::Depth | DebugView::Normals | DebugView::Regions => super::Shown::Data,
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DebugPush {
    /// xyz: the camera's unit viewing direction; w: near, mm along it.
    forward_near: [f32; 4],
    /// Far, mm along the viewing direction.
    far: f32,
    mode: u32,
}

/// Where the depth view's 1 and 0 lie: the mesh's nearest and farthest vertex
/// along the camera's viewing direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthRange {
    pub forward: Vec3,
    pub near_mm: f32,
    pub far_mm: f32,
}

impl DepthRange {
    /// For a camera at `eye` looking along `forward` (unit) at the mesh's
    /// `positions` (mm).
    pub fn of(eye: Vec3, forward: Vec3, positions: &[Vec3]) -> DepthRange {
        let z = positions.iter().map(|&p| forward.dot(p - eye));
        let (near_mm, far_mm) = z.fold((f32::MAX, f32::MIN), |(lo, hi), z| (lo.min(z), hi.max(z)));
        DepthRange {
            forward,
            near_mm,
            far_mm: far_mm.max(near_mm + 1e-3),
        }
    }
}

pub struct DebugPass {
    pipeline: Arc<Pipeline>,
    /// The face-region id map (red = id), sampled nearest.
    regions: Arc<Image>,
}

impl DebugPass {
    pub fn new(pipelines: &Pipelines, regions: &Texture) -> Result<Self> {
        let ctx = pipelines.ctx();
        Ok(Self {
            pipeline: pipelines.graphics(&GraphicsDesc {
                vertex: "mesh.vert",
                fragment: "debug_view.frag",
                color_formats: &[HDR_FORMAT],
                depth_format: Some(DEPTH_FORMAT),
                depth_write: true,
                vertex_layout: Some(Vertex::layout()),
                cull_mode: vk::CullModeFlags::NONE,
                specialization: &[],
                alpha_blend: false,
            })?,
            regions: upload_rgba8(ctx, "region ids", regions)?,
        })
    }

    /// Draws `view` of the mesh over `hdr` (which holds the background).
    pub fn pass(
        &self,
        g: &mut Graph,
        view: DebugView,
        inputs: &FrameInputs,
        depth_range: DepthRange,
        hdr: &mut ImageHandle,
    ) {
        let (w, h) = (hdr.desc.width, hdr.desc.height);
        let mut depth = g.create_image("depth", ImageDesc::new(w, h, DEPTH_FORMAT));
        let s = &inputs.samplers;
        let pass = g
            .simple_pass("debug_view", &self.pipeline)
            .uniform(&inputs.uniforms)
            .texture(&inputs.albedo, &s.linear)
            .texture(&inputs.normal, &s.linear)
            .texture(&self.regions, &s.nearest)
            .color(hdr, LoadOp::Load)
            .depth(&mut depth, LoadOp::Clear([1.0; 4]))
            .constants(&DebugPush {
                forward_near: depth_range.forward.extend(depth_range.near_mm).into(),
                far: depth_range.far_mm,
                mode: view as u32,
            });
        inputs.mesh.draw(pass);
    }
}
