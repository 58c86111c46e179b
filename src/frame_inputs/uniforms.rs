//! The per-frame uniform block (std140, mirrors shaders-glsl/common/frame.glsl).

/// Lights the frame's shaders loop over (common/lights.glsl): the scene's
/// explicit lights, then the sources extracted from the environment.
pub const MAX_LIGHTS: usize = 8;

/// What stays fixed for a whole render and selects code in the shading passes:
/// their specialization constants (shaders-glsl/common/frame.glsl). Fixed loop
/// bounds and dead branches removed at pipeline creation matter on CPU drivers,
/// which run both sides of every branch (docs/records/2026-11-24-frame-speed.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShaderVariant {
    /// Explicit lights, ≤ MAX_LIGHTS.
    pub lights: u32,
    /// The per-vertex transfer carries visibility (else R&H at the shading normal).
    pub occlusion: bool,
    /// The scene gave a roughness map (else the regions' m is used).
    pub roughness_map: bool,
    /// The specular lobe is a medium's boundary, a rough dielectric whose ior
    /// is `params.x` (else the paper's KS lobe, Schlick's F0 there).
    pub dielectric_lobe: bool,
    /// Bit i: light i has a shadow map.
    pub shadowed: u32,
    /// Bit i: light i has an angular size, so its shadow has a penumbra
    /// (percentage-closer soft shadows, common/lights.glsl).
    pub soft: u32,
}

impl ShaderVariant {
    /// `constant_id` 0..=5 of frame.glsl.
    pub fn specialization(&self) -> [u32; 6] {
        [
            self.lights,
            u32::from(self.occlusion),
            u32::from(self.roughness_map),
            self.shadowed,
            self.soft,
            u32::from(self.dielectric_lobe),
        ]
    }
}

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
    /// x: tan of the source's angular radius (0: a point); y: the shadow map's
    /// depth range, mm (directional lights); z: what the source adds to the
    /// specular lobe's m² (light::shadow::lobe_widening); w: a point light's
    /// shadow near plane, mm (its depth is perspective), else 0.
    pub light_params: [[f32; 4]; MAX_LIGHTS],
    /// World to (atlas u, v, depth) in the light's focus tile (the window of
    /// its map that holds what the camera sees, light::shadow::Focus).
    pub light_focus: [[[f32; 4]; 4]; MAX_LIGHTS],
    /// x: the focus tile's texel, mm (0: no focus map); y: the depth of the
    /// nearest surface it holds (light::shadow::Focus::nearest); z, w: the
    /// tile's lowest atlas corner (u, v).
    pub light_focus_tile: [[f32; 4]; MAX_LIGHTS],
    /// x: environment rotation (radians about +Y), y: intensity, z: light count,
    /// w: occlusion on.
    pub env: [f32; 4],
    /// x: the specular lobe's parameter (skin::specular::Lobe::parameter:
    /// Schlick's F0 0.028 for the paper's lobe, a medium boundary's ior); y: 1/(2 s̄), s̄ the specular map's mean over the mesh
    /// (skin::specular::map_rho_s); z, w: the shadow atlas's tile columns and rows.
    pub params: [f32; 4],
}
