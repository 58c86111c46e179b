#version 460
// Metering, first pass (post/meter.rs): per 16 × 16 tile, the sum of log(δ + L)
// over the pixels the mesh covers (alpha > covered) and their count, L the
// luminance (Reinhard et al. 2002, eq. 1).
layout(local_size_x = 16, local_size_y = 16) in;
layout(binding = 0) uniform sampler2D hdr;
layout(std430, binding = 1) writeonly buffer Partials { vec2 partials[]; };   // (log sum, pixels)
layout(push_constant) uniform Push { vec3 luminance; float delta; float covered; } pc;
shared vec2 sums[256];

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    uint lid = gl_LocalInvocationIndex;
    vec2 s = vec2(0.0);
    if (all(lessThan(p, textureSize(hdr, 0)))) {
        vec4 c = texelFetch(hdr, p, 0);
        if (c.a > pc.covered) s = vec2(log(pc.delta + max(dot(c.rgb, pc.luminance), 0.0)), 1.0);
    }
    sums[lid] = s;
    barrier();
    for (uint n = 128u; n > 0u; n >>= 1) {
        if (lid < n) sums[lid] += sums[lid + n];
        barrier();
    }
    if (lid == 0u) partials[gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x] = sums[0];
}
