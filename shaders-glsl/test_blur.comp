#version 460
// One direction of a separable Gaussian blur, clamp-to-edge, taps at whole texels.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D src;
layout(binding = 1, rgba16f) uniform writeonly image2D dst;
layout(push_constant) uniform Push { ivec2 dir; int radius; float sigma; } pc;

void main() {
    ivec2 size = textureSize(src, 0);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, size))) return;
    vec4 sum = vec4(0.0);
    float total = 0.0;
    for (int i = -pc.radius; i <= pc.radius; ++i) {
        float w = exp(-float(i * i) / (2.0 * pc.sigma * pc.sigma));
        ivec2 q = clamp(p + i * pc.dir, ivec2(0), size - 1);
        sum += w * texelFetch(src, q, 0);
        total += w;
    }
    imageStore(dst, p, sum / total);
}
