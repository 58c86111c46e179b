#version 460
// Sums the per-row partials of sh_project.comp, then rotates (a 9×9 block-diagonal
// matrix, light/sh.rs::rotate) and scales by the environment intensity.
layout(local_size_x = 32) in;
layout(std430, binding = 0) readonly buffer Partials { float partials[]; };
layout(std430, binding = 1) readonly buffer Transform { float rotation[81]; float intensity; };
layout(std430, binding = 2) writeonly buffer Sh { vec4 sh[9]; };
layout(push_constant) uniform Push { uint rows; } pc;
shared float l[27];

void main() {
    uint k = gl_LocalInvocationID.x;
    if (k < 27u) {
        float s = 0.0;
        for (uint r = 0u; r < pc.rows; ++r) s += partials[r * 27u + k];
        l[k] = s;
    }
    barrier();
    if (k < 27u) {
        uint i = k / 3u, c = k % 3u;
        float v = 0.0;
        for (uint j = 0u; j < 9u; ++j) v += rotation[i * 9u + j] * l[j * 3u + c];
        sh[i][c] = v * intensity;
        if (c == 0u) sh[i].a = 0.0;
    }
}
