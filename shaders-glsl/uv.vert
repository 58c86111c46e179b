#version 460
// Rasterises the mesh by its UVs: texel (x, y) of an N×N target covers
// uv = ((x, y) + 0.5) / N, the same mapping texture sampling uses (v down).
layout(location = 0) in vec3 position;   // mm
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in vec4 tangent;
layout(location = 0) out vec3 v_position;
layout(location = 1) out vec3 v_normal;
layout(location = 2) out vec2 v_uv;
layout(location = 3) out vec4 v_tangent;

void main() {
    v_position = position;
    v_normal = normal;
    v_uv = uv;
    v_tangent = tangent;
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
