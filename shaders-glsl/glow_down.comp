#version 460
// Glow (post/glow.rs): one box-filtered mip level, each texel the mean of 2 × 2
// of the level above, zero outside it (the glow is the convolution of the image
// with black around it).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D src;
layout(binding = 1, rgba16f) uniform writeonly image2D dst;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(dst)))) return;
    ivec2 size = textureSize(src, 0);
    vec4 sum = vec4(0.0);
    for (int i = 0; i < 4; ++i) {
        ivec2 q = 2 * p + ivec2(i & 1, i >> 1);
        if (all(lessThan(q, size))) sum += texelFetch(src, q, 0);
    }
    imageStore(dst, p, 0.25 * sum);
}
