#version 460
// The copy ruler (docs/guide/measure.md): one RGBA16F texel read and one written per
// invocation, at the blur chain's resolution and format, workgroups as blur.comp's.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D src;
layout(binding = 1, rgba16f) uniform writeonly image2D dst;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(dst)))) return;
    imageStore(dst, p, texelFetch(src, p, 0));
}
