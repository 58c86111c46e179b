#version 460
// Per frame, what the irradiance pass interpolates at each vertex: its position
// (mm) and the environment's irradiance through its transfer plus the light the
// skin reflects onto it and the sky's through thin skin (occluded_irradiance,
// common/indirect.glsl), two RGBA32F texels per vertex, VERTICES_PER_ROW
// vertices a row (skin/irradiance.rs).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
layout(local_size_x = 64) in;
#include "frame.glsl"
// frame::Vertex: position, normal, uv, tangent, 12 floats.
layout(std430, binding = 1) readonly buffer Vertices { float vertices[]; };
layout(binding = 2, rgba32f) uniform writeonly image2D values;
layout(std140, binding = 3) uniform Lighting { vec4 sh[9]; } lighting;
const uint VERTEX_FLOATS = 12u;
const uint VERTICES_PER_ROW = 1024u;   // skin::irradiance::VERTICES_PER_ROW
uint vertex_index;
#define VERTEX_INDEX vertex_index
#include "sh_basis.glsl"
#include "incident.glsl"
#define RGB_TRANSFER 5
#include "transfer.glsl"
#include "sh.glsl"
#include "indirect.glsl"

void main() {
    vertex_index = gl_GlobalInvocationID.x;
    if (vertex_index >= uint(vertices.length()) / VERTEX_FLOATS) return;
    uint v = vertex_index * VERTEX_FLOATS;
    vec3 position = vec3(vertices[v], vertices[v + 1u], vertices[v + 2u]);
    ivec2 at = ivec2(2u * (vertex_index % VERTICES_PER_ROW), vertex_index / VERTICES_PER_ROW);
    imageStore(values, at, vec4(position, 1.0));
    imageStore(values, at + ivec2(1, 0), vec4(occluded_irradiance(position), 1.0));
}
