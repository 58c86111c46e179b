#version 460
// Per frame, what the irradiance pass interpolates at each vertex: its position
// (mm) and the environment's irradiance through its transfer plus the light the
// skin reflects onto it and the sky's through thin skin (occluded_irradiance,
// common/indirect.glsl), at vertex_values_texel (common/vertices.glsl).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
layout(local_size_x = 64) in;
#include "frame.glsl"
#define VERTICES 1
#include "vertices.glsl"
layout(binding = 2, rgba32f) uniform writeonly image2D values;
layout(std140, binding = 3) uniform Lighting { vec4 sh[9]; } lighting;
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
    uint v = vertex_index * VERTEX_FLOATS + POSITION_FLOAT;
    vec3 position = vec3(vertices[v], vertices[v + 1u], vertices[v + 2u]);
    ivec2 at = vertex_values_texel(vertex_index, imageSize(values).x);
    imageStore(values, at, vec4(position, 1.0));
    imageStore(values, at + ivec2(1, 0), vec4(occluded_irradiance(position), 1.0));
}
