// Per-frame uniforms shared by the scene passes (std140; mirrors render::FrameUniforms).
layout(std140, binding = 0) uniform Frame {
    mat4 view_proj;
    mat4 inv_view_proj;
    vec4 camera_pos;        // xyz mm
    vec4 light_dir[4];      // xyz: direction towards the light
    vec4 light_color[4];    // rgb: irradiance on a surface facing it
    vec4 env;               // x: rotation (radians, about +Y), y: intensity, z: light count, w: occlusion on
    vec4 params;            // x: exposure (EV)
} frame;
