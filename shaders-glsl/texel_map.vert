#version 460
// The texel map (skin/irradiance.rs), drawn once per render: the mesh rasterised
// by its UVs as uv.vert does, but without a vertex buffer, corner by corner
// (gl_VertexIndex runs over the index buffer), so that each fragment gets its
// triangle's three vertices (flat) and its weight on each (interpolated).
#extension GL_GOOGLE_include_directive : require
layout(std430, binding = 0) readonly buffer Indices { uint indices[]; };
#define VERTICES 1
#include "vertices.glsl"
layout(location = 0) out vec3 v_weights;
layout(location = 1) flat out uvec3 v_corners;

void main() {
    uint corner = uint(gl_VertexIndex) % 3u;
    uint first = uint(gl_VertexIndex) - corner;
    v_corners = uvec3(indices[first], indices[first + 1u], indices[first + 2u]);
    v_weights = vec3(corner == 0u, corner == 1u, corner == 2u);
    uint v = indices[gl_VertexIndex] * VERTEX_FLOATS + UV_FLOAT;
    vec2 uv = vec2(vertices[v], vertices[v + 1u]);
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
