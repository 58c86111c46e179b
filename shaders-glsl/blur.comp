#version 460
// One direction of one Gaussian of the skin chain (GPU Gems 3 §14.4.2-3): the
// destination texel's taps sit at offset_σ · σ_mm · stretch along the blur axis,
// stretch (texels/mm) read from the stretch level before this one (the V pass:
// along the surface perpendicular of ∂P/∂u where the UVs are sheared), and are read
// with bilinear filtering in normalised coordinates, so the source may be finer
// than the destination (the adaptive chain downsamples as it blurs; the Gaussian
// is the low-pass). The same shader blurs the stretch chain (src = stretch).
// Images are coverage-premultiplied (alpha = coverage), so the chain is linear
// and the final divide by alpha gives a convolution normalised over the mesh:
// gutter texels never pull black into chart borders.
layout(local_size_x = 8, local_size_y = 8) in;
// > 0: the fixed kernel's tap count (d'Eon's 7 taps at 1σ); 0: the accurate kernel.
layout(constant_id = 0) const int TAP_COUNT = 7;
layout(binding = 0) uniform sampler2D src;
layout(binding = 1) uniform sampler2D stretch;
layout(binding = 2, rgba16f) uniform writeonly image2D dst;
const int MAX_FIXED_TAPS = 32;   // skin/blur.rs::MAX_FIXED_TAPS
layout(std140, binding = 3) uniform Kernel { vec4 taps[MAX_FIXED_TAPS]; };   // (offset in σ, weight)
layout(push_constant) uniform Push { ivec2 dir; float sigma_mm; } pc;

// The accurate kernel: Gaussian weights at a spacing of at most min(0.5σ,
// 0.5 texel) out to ±4σ, with σ² reduced by the 1/6 texel² that linear
// interpolation adds (the variance of the tent it convolves with).
const float MAX_SPACING_SIGMA = 0.5;
const float MAX_SPACING_TEXELS = 0.5;
const float EXTENT_SIGMA = 4.0;
const int MAX_TAPS = 257;

void main() {
    ivec2 size = imageSize(dst);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, size))) return;
    vec2 uv = (vec2(p) + 0.5) / vec2(size);
#ifdef SKIP_WORK
    // The variant with the work skipped (build.rs, `render --variants`): one
    // read and the output, nothing else.
    imageStore(dst, p, textureLod(src, uv, 0.0));
    return;
#endif
    vec2 src_size = vec2(textureSize(src, 0));
    // Stretch in source texels per mm; far out in the gutter there is no
    // stretch to normalise: one destination texel per mm.
    vec4 st = textureLod(stretch, uv, 0.0);
    vec2 s = st.a > 1e-4 ? st.rg / st.a * src_size / vec2(textureSize(stretch, 0))
                         : src_size / vec2(size);
    bool along_u = pc.dir.x != 0;
    float sigma_texels = pc.sigma_mm * (along_u ? s.x : s.y);
    // One source texel along the blur axis, in normalised coordinates.
    vec2 texel = vec2(pc.dir) / src_size;
    // Shear (stretch.frag): the V pass steps along the surface direction
    // perpendicular to ∂P/∂u, (st.b, st.g) texels per mm, so the two passes are
    // orthogonal on the surface. st.b = 0 (no shear, or shear correction off):
    // the plain V axis, as before.
    if (!along_u && st.a > 1e-4 && st.b != 0.0) {
        vec2 step = vec2(st.b / st.a * src_size.x / float(textureSize(stretch, 0).x), s.y);
        float len = length(step);
        sigma_texels = pc.sigma_mm * len;
        texel = step / (len * src_size);
    }
    // σ = 0 (skin.blur_width = 0 on the stretch chain): a copy.
    if (sigma_texels <= 0.0) {
        imageStore(dst, p, textureLod(src, uv, 0.0));
        return;
    }
    vec4 sum = vec4(0.0);
    if (TAP_COUNT > 0) {
        for (int i = 0; i < TAP_COUNT; ++i) {
            sum += taps[i].y * textureLod(src, uv + taps[i].x * sigma_texels * texel, 0.0);
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
            sum += w * textureLod(src, uv + x * texel, 0.0);
            total += w;
        }
        sum /= total;
    }
    imageStore(dst, p, sum);
}
