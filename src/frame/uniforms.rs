//! The per-frame uniform block (std140, mirrors shaders-glsl/common/frame.glsl).

/// Lights the frame's shaders loop over (common/lights.glsl).
pub const MAX_LIGHTS: usize = 4;

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FrameUniforms {
    pub view_proj: [[f32; 4]; 4],
    pub inv_view_proj: [[f32; 4]; 4],
    pub camera_pos: [f32; 4],
    /// w = 0: direction towards the light; w = 1: position, mm.
    pub light_vec: [[f32; 4]; MAX_LIGHTS],
    /// rgb: irradiance facing the light (point: at 1000 mm); w: shadow texel
    /// size, mm (per mm of distance for a point light), 0 = unshadowed.
    pub light_color: [[f32; 4]; MAX_LIGHTS],
    /// World to (atlas u, v, depth), light::shadow::ShadowView::atlas_matrix.
    pub light_shadow: [[[f32; 4]; 4]; MAX_LIGHTS],
    /// x: environment rotation (radians about +Y), y: intensity, z: light count,
    /// w: occlusion on.
    pub env: [f32; 4],
    /// x: exposure (EV).
    pub params: [f32; 4],
}
