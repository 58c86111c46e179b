#version 460
// The read ruler (docs/guide/measure.md): one RGBA16F texel read per invocation and
// nothing written (coverage is never negative), so the reads cannot be dropped.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D src;
layout(binding = 1, rgba16f) uniform writeonly image2D sink;   // 1×1

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, textureSize(src, 0)))) return;
    vec4 v = texelFetch(src, p, 0);
    if (v.a < -1.0) imageStore(sink, ivec2(0), v);
}
