#version 460
// Metering, first pass (post/meter.rs): per 32 × 32 tile, the sum of log(δ + L)
// over the pixels the mesh covers (alpha > covered) and their count, L the
// luminance (Reinhard et al. 2002, eq. 1). Each of the 8 × 8 threads sums 16
// pixels, so the tree reduction's barriers are paid once per 1024 pixels.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D hdr;
layout(std430, binding = 1) writeonly buffer Partials { vec2 partials[]; };   // (log sum, pixels)
layout(push_constant) uniform Push { vec3 luminance; float delta; float covered; } pc;
shared vec2 sums[64];

void main() {
    ivec2 size = textureSize(hdr, 0);
    ivec2 origin = ivec2(gl_WorkGroupID.xy) * 32 + ivec2(gl_LocalInvocationID.xy);
    uint lid = gl_LocalInvocationIndex;
    vec2 s = vec2(0.0);
    for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 4; ++i) {
            ivec2 p = origin + 8 * ivec2(i, j);
            if (any(greaterThanEqual(p, size))) continue;
            vec4 c = texelFetch(hdr, p, 0);
            if (c.a > pc.covered) s += vec2(log(pc.delta + max(dot(c.rgb, pc.luminance), 0.0)), 1.0);
        }
    }
    sums[lid] = s;
    barrier();
    for (uint n = 32u; n > 0u; n >>= 1) {
        if (lid < n) sums[lid] += sums[lid + n];
        barrier();
    }
    if (lid == 0u) partials[gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x] = sums[0];
}
