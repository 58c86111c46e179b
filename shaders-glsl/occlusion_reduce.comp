#version 460
// T_i = Σ V(ω)·max(N·ω, 0)·y_i(ω)·dω over a vertex's six face tiles (the paper's
// eq. 12-13), with the exact solid angle of a cube-map texel,
// dω = A(x0,y0) − A(x0,y1) − A(x1,y0) + A(x1,y1), A(x, y) = atan(xy / √(x²+y²+1)).
#extension GL_GOOGLE_include_directive : require
#include "cube_faces.glsl"
#include "sh_basis.glsl"
layout(local_size_x = 64) in;
layout(binding = 0) uniform sampler2D atlas;   // R8: 1 visible, 0 mesh
layout(std430, binding = 1) readonly buffer Normals { vec4 normals[]; };
layout(std430, binding = 2) buffer Transfer { float transfer[]; };
layout(push_constant) uniform Push { uint first_vertex; uint count; uint face_size; uint tiles_per_row; } pc;
shared float sums[64 * 9];

float area(float x, float y) { return atan(x * y, sqrt(x * x + y * y + 1.0)); }

void main() {
    uint v = gl_WorkGroupID.x;
    uint lid = gl_LocalInvocationID.x;
    if (v >= pc.count) return;
    vec3 n = normals[pc.first_vertex + v].xyz;
    uint n_face = pc.face_size * pc.face_size;
    float acc[9];
    for (int k = 0; k < 9; ++k) acc[k] = 0.0;
    float h = 2.0 / float(pc.face_size);
    for (uint t = lid; t < 6u * n_face; t += 64u) {
        uint face = t / n_face;
        uint i = t % pc.face_size, j = (t % n_face) / pc.face_size;
        uint tile = v * 6u + face;
        ivec2 texel = ivec2((tile % pc.tiles_per_row) * pc.face_size + i, (tile / pc.tiles_per_row) * pc.face_size + j);
        float x0 = float(i) * h - 1.0, y0 = float(j) * h - 1.0;
        vec3 d = normalize(FACE_F[face] + (x0 + 0.5 * h) * FACE_R[face] + (y0 + 0.5 * h) * FACE_D[face]);
        float w = texelFetch(atlas, texel, 0).r * max(dot(n, d), 0.0)
                * (area(x0, y0) - area(x0, y0 + h) - area(x0 + h, y0) + area(x0 + h, y0 + h));
        float b[9];
        sh_basis(d, b);
        for (int k = 0; k < 9; ++k) acc[k] += w * b[k];
    }
    for (int k = 0; k < 9; ++k) sums[lid * 9u + uint(k)] = acc[k];
    barrier();
    for (uint s = 32u; s > 0u; s >>= 1) {
        if (lid < s) {
            for (uint k = 0u; k < 9u; ++k) sums[lid * 9u + k] += sums[(lid + s) * 9u + k];
        }
        barrier();
    }
    if (lid == 0u) {
        for (uint k = 0u; k < 9u; ++k) transfer[(pc.first_vertex + v) * 9u + k] = sums[k];
    }
}
