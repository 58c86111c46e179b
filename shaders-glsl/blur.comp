#version 460
// One direction of one Gaussian of the skin chain (GPU Gems 3 §14.4.2-3), applied
// to the irradiance and the stretch map with the same taps. Taps sit at
// offset_σ · σ_mm · stretch texels (stretch in texels/mm, from the previous
// stretch level) and are read with bilinear filtering. Both images are
// coverage-premultiplied (alpha = coverage), so the chain is linear and the
// final divide by alpha gives a convolution normalised over the mesh: gutter
// texels never pull black into chart borders.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D src_irradiance;
layout(binding = 1) uniform sampler2D src_stretch;
layout(binding = 2, rgba16f) uniform writeonly image2D dst_irradiance;
layout(binding = 3, rgba16f) uniform writeonly image2D dst_stretch;
layout(std430, binding = 4) readonly buffer Kernel { vec2 taps[]; };   // (offset in σ, weight)
// tap_count > 0: the fixed kernel in `taps` (d'Eon's 7 taps at 1σ).
// tap_count = 0: the accurate kernel: Gaussian weights at a spacing of at most
// min(0.5σ, 0.5 texel) out to ±4σ, with σ² reduced by the 1/6 texel² that
// bilinear taps add (the variance of the tent a linear filter convolves with).
layout(push_constant) uniform Push { ivec2 dir; float sigma_mm; int tap_count; } pc;

const float MAX_SPACING_SIGMA = 0.5;
const float MAX_SPACING_TEXELS = 0.5;
const float EXTENT_SIGMA = 4.0;
const int MAX_TAPS = 257;

// Linear interpolation along the blur axis: every tap lies on the line through
// this texel's centre, so bilinear filtering reduces to a lerp of two texels.
ivec2 clamp_texel(ivec2 t, ivec2 size) { return clamp(t, ivec2(0), size - 1); }

void fetch(float offset, ivec2 p, ivec2 size, out vec4 irr, out vec4 str) {
    float f = floor(offset);
    float t = offset - f;
    ivec2 a = clamp_texel(p + int(f) * pc.dir, size);
    ivec2 b = clamp_texel(p + (int(f) + 1) * pc.dir, size);
    irr = mix(texelFetch(src_irradiance, a, 0), texelFetch(src_irradiance, b, 0), t);
    str = mix(texelFetch(src_stretch, a, 0), texelFetch(src_stretch, b, 0), t);
}

void main() {
    ivec2 size = imageSize(dst_irradiance);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, size))) return;
    vec4 st = texelFetch(src_stretch, p, 0);
    // Far out in the gutter there is no stretch to normalise: use 1 texel/mm.
    vec2 s = st.a > 1e-4 ? st.rg / st.a : vec2(1.0);
    float sigma_texels = pc.sigma_mm * (pc.dir.x != 0 ? s.x : s.y);
    vec4 irr = vec4(0.0);
    vec4 str = vec4(0.0);
    vec4 ti, ts;
    if (pc.tap_count > 0) {
        for (int i = 0; i < pc.tap_count; ++i) {
            fetch(taps[i].x * sigma_texels, p, size, ti, ts);
            irr += taps[i].y * ti;
            str += taps[i].y * ts;
        }
    } else {
        float var = max(sigma_texels * sigma_texels - 1.0 / 6.0, 0.01 * sigma_texels * sigma_texels);
        float sigma = sqrt(var);
        float spacing = min(MAX_SPACING_SIGMA * sigma, MAX_SPACING_TEXELS);
        int n = min(int(ceil(EXTENT_SIGMA * sigma / spacing)), (MAX_TAPS - 1) / 2);
        spacing = EXTENT_SIGMA * sigma / float(n);
        float total = 0.0;
        for (int k = -n; k <= n; ++k) {
            float x = float(k) * spacing;
            float w = exp(-0.5 * x * x / var);
            fetch(x, p, size, ti, ts);
            irr += w * ti;
            str += w * ts;
            total += w;
        }
        irr /= total;
        str /= total;
    }
    imageStore(dst_irradiance, p, irr);
    imageStore(dst_stretch, p, str);
}
