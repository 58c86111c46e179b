#version 460
// Glow (post/glow.rs): one direction of a Gaussian of σ texels on one mip level,
// point weights exp(−x²/2σ²) to ±4σ normalised over the whole kernel, zero
// outside the image.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D src;
layout(binding = 1, rgba16f) uniform writeonly image2D dst;
layout(push_constant) uniform Push { ivec2 dir; float sigma; } pc;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(dst);
    if (any(greaterThanEqual(p, size))) return;
    int n = int(ceil(4.0 * pc.sigma));
    vec4 sum = vec4(0.0);
    float total = 0.0;
    for (int k = -n; k <= n; ++k) {
        float w = exp(-0.5 * float(k * k) / (pc.sigma * pc.sigma));
        ivec2 q = p + k * pc.dir;
        if (all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, size))) sum += w * texelFetch(src, q, 0);
        total += w;
    }
    imageStore(dst, p, sum / total);
}
