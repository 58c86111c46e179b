// Per-frame uniforms shared by the scene passes (std140; mirrors render::FrameUniforms).
layout(std140, binding = 0) uniform Frame {
    mat4 view_proj;
    mat4 inv_view_proj;
    vec4 camera_pos;        // xyz mm
    vec4 light_vec[8];      // w 0: xyz direction towards the light; w 1: xyz position, mm
    vec4 light_color[8];    // rgb: irradiance facing the light (point: at 1000 mm); w: shadow texel, mm (0: unshadowed)
    mat4 light_shadow[8];   // world → (atlas u, v, depth) after the divide by w
    vec4 light_params[8];   // x: tan(angular radius), y: shadow depth range mm, z: m² widening, w: point light's shadow near plane mm
    mat4 light_focus[8];    // world → atlas (u, v, depth) in the light's focus tile: where the camera looks
    vec4 light_focus_tile[8];   // x: the focus tile's texel, mm (0: none); y: its nearest surface's depth; zw: its lowest atlas corner
    vec4 env;               // x: rotation (radians, about +Y), y: intensity, z: light count, w: occlusion on (z, w: also below)
    vec4 params;            // x: the specular lobe's Schlick F0, or with DIELECTRIC_LOBE its ior (ks_specular.glsl), y: 1/(2·specular map mean) (ks_specular.glsl), zw: atlas tiles
} frame;
// Fixed for a render (frame::ShaderVariant): the driver drops dead branches, which
// a CPU driver would otherwise run with masked lanes. Loops over the lights are
// marked [[unroll]] (GL_EXT_control_flow_attributes): without it lavapipe (Mesa
// 22.3) left a body that large rolled (nir_opt_loop_unroll's cost limit, it
// seems), and the lit close-up's skin pass took 1.7× as long
// (docs/records/2026-11-26-light-loops-unrolled.md).
layout(constant_id = 0) const int LIGHT_COUNT = 0;
layout(constant_id = 1) const bool OCCLUSION = true;
layout(constant_id = 2) const bool ROUGHNESS_MAP = false;
layout(constant_id = 3) const int SHADOWED_LIGHTS = 0;   // bit i: light i has a shadow map
layout(constant_id = 4) const int SOFT_LIGHTS = 0;       // bit i: light i has an angular size
layout(constant_id = 5) const bool DIELECTRIC_LOBE = false; // the specular is a medium's boundary (ks_specular.glsl)
