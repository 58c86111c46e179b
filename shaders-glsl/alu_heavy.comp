#version 460
// A pass that is all arithmetic: per texel `iterations` rounds of sin/cos on
// registers, one RGBA16F store at the end (the bound-by verdict's shading case).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba16f) uniform writeonly image2D dst;
layout(push_constant) uniform Push { uvec2 size; uint iterations; } pc;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(p, pc.size))) return;
    vec4 x = vec4(vec2(p) / vec2(pc.size), 0.25, 0.5);
#ifdef SKIP_WORK
    // The variant with the work skipped (build.rs, `render --variants`): one
    // read and the output, nothing else.
    imageStore(dst, ivec2(p), x);
    return;
#endif
    for (uint i = 0u; i < pc.iterations; i++) {
        x = sin(x * 1.7 + 0.3) * cos(x.yzwx * 0.9 - 0.1);
    }
    imageStore(dst, ivec2(p), x);
}
