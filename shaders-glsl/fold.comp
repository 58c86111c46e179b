#version 460
// The fold term of one blurred level (skin/fold/): at each listed texel x the
// level's value D becomes C·D + Σ w_y·E_y, E_y the previous level's texels: the
// 3-D kernel where the skin comes back within reach (a seam's other side, a
// squeezed UV region, a fold), the chain's share scaled back by the coverage it
// normalised away. Images are coverage-premultiplied, as in blur.comp.
layout(local_size_x = 64) in;
layout(binding = 0) uniform sampler2D src;
layout(binding = 1, rgba16f) uniform image2D level;
// (y << 16 | x, C as float bits, first source, source count)
layout(std430, binding = 2) readonly buffer Targets { uvec4 targets[]; };
// (y << 16 | x, w as float bits)
layout(std430, binding = 3) readonly buffer Sources { uvec2 sources[]; };
layout(push_constant) uniform Push { uint count; } pc;

// Below this coverage a texel has no value of its own (fidelity/diffusion_gap.rs).
const float MIN_COVERAGE = 1e-3;

ivec2 unpack(uint texel) { return ivec2(texel & 0xffffu, texel >> 16); }

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    uvec4 t = targets[i];
    ivec2 p = unpack(t.x);
    vec4 here = imageLoad(level, p);
    if (here.a <= MIN_COVERAGE) return;
    vec3 sum = uintBitsToFloat(t.y) * here.rgb / here.a;
    for (uint j = t.z; j < t.z + t.w; ++j) {
        vec4 e = texelFetch(src, unpack(sources[j].x), 0);
        if (e.a > MIN_COVERAGE) sum += uintBitsToFloat(sources[j].y) * e.rgb / e.a;
    }
    imageStore(level, p, vec4(max(sum, vec3(0.0)) * here.a, here.a));
}
