#version 460
// One Gaussian of the skin chain that spans about a texel or less (skin/chain.rs,
// Stencil), both directions in one pass, source and destination of one size.
// Its covariance in source texels is Σ = σ²·U·Uᵀ, U = [[r, b], [0, g]]
// the stretch map's factor (stretch.frag: the U pass steps (r, 0) and the V pass
// (b, g) texels per mm, so this is the two passes' covariance). The stencil's
// weights have exactly that covariance and are read with bilinear taps: a tap at
// offset o = n + f from a texel centre puts 1 − f on texel n and f on n + 1, so
// its second moment is n² + f·(2n + 1) (o, not o², under a texel) along each axis
// and ox·oy across. The variance is exact, not σ² plus bilinear filtering's share
// as with the separable taps. Images are coverage-premultiplied, as in blur.comp.
//
// 3×3 (FIVE false), four taps in two pairs ±d1, ±d2 of weights w1/2, w2/2. Pairs
// (ox, ±oy) with ox = Σuu, oy = Σvv give the variances, per axis the tent m/2,
// 1 − m, m/2, and their weights (1 ± c)/2 a cross moment c·ox·oy. A larger cross
// moment (narrow and sheared: |Σuv| up to min(Σuu, Σvv), what any 3×3 stencil of
// positive weights holds) puts one pair on the diagonal at (Σuv/Σvv, Σuv/Σuu)
// with weight Σuu·Σvv/Σuv and the rest on the centre.
//
// 5×5 (FIVE true), nine taps: per axis weights c0, a1, a2 at 0, ±1, ±2 texels,
// a2/a1 = e^(−3/(2m)) as the Gaussian's ratio between 2 and 1 texels, read as the
// centre and a pair at ±(1 + a2/(a1 + a2)); in 2-D the tensor product of the two
// axes, with weight moved from the axes' taps to the corners where the cross
// moment needs more than the product holds.
//
// HALF (with FIVE only): the source has twice the destination's side (a level
// that halves its resolution). A destination texel's centre is a
// source texel corner, so a tap at o destination texels reads source texels at
// 2o ± ½ and has second moment ((n − ½)² + 2n·f)/4 with 2o + ½ = n + f: the
// centre tap is the 2×2 box, of variance BOX. The stencil is the 5×5 of Σ − BOX
// on each axis, its side taps moved to where they hold their moment plus BOX,
// so the total is Σ again (a per-axis variance below BOX stays BOX).
layout(local_size_x = 8, local_size_y = 8) in;
layout(constant_id = 0) const bool FIVE = false;
layout(constant_id = 1) const bool HALF = false;
layout(binding = 0) uniform sampler2D src;
layout(binding = 1) uniform sampler2D stretch;
layout(binding = 2, rgba16f) uniform writeonly image2D dst;
layout(push_constant) uniform Push { float sigma_mm; } pc;

// The offset of a bilinear tap whose second moment about the texel centre is m:
// at o = n + f, n² + f·(2n + 1) = m; under one texel o = m. (Above a texel,
// where the stretch is far above the mean, the variance stays exact and the
// taps leave the 3×3 stencil's centre row and column.)
float tap_offset(float m) {
    float n = floor(sqrt(m));
    return n + (m - n * n) / (2.0 * n + 1.0);
}

// The second moment of a same-size tap at o: tap_offset's inverse.
float tap_moment(float o) {
    float n = floor(o);
    return n * n + (o - n) * (2.0 * n + 1.0);
}

// The box of a HALF pass's centre tap, destination texels² per axis
// (skin::chain::HALF_BOX_TEXELS2).
const float BOX = HALF ? 1.0 / 16.0 : 0.0;

// The offset o (destination texels) of a HALF pass's tap whose second moment
// is m ≥ BOX: ((n − ½)² + 2n·f)/4 = m at 2o + ½ = n + f, n ≥ 1.
float half_tap_offset(float m) {
    float s = 4.0 * max(m, BOX);
    float n = max(floor(sqrt(s) + 0.5), 1.0);
    return 0.5 * (n + (s - (n - 0.5) * (n - 0.5)) / (2.0 * n) - 0.5);
}

// The 5×5 stencil along one axis, variance m: (h, D), the weight of each side's
// tap at ±D (1 − 2h on the centre): h·(1 + 3t) = m/2 at D = 1 + t. Where that
// would put more than a third on each side (m above ≈ 1.05 texel², the stretch
// far above the mesh's mean), three equal taps, the sides at the bilinear
// offset whose moment holds the variance (continuous at the switch), so the
// centre never empties into a ring.
vec2 five_taps(float m) {
    float r = exp(-1.5 / max(m, 1e-6));
    float t = r / (1.0 + r);
    float h = m / (2.0 + 6.0 * t);
    return h <= 1.0 / 3.0 ? vec2(h, 1.0 + t) : vec2(1.0 / 3.0, tap_offset(1.5 * m));
}

vec4 at(vec2 uv, vec2 offset) {
    return textureLod(src, uv + offset, 0.0);
}

void main() {
    ivec2 size = imageSize(dst);
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, size))) return;
    vec2 texel = 1.0 / vec2(size);
    vec2 uv = (vec2(p) + 0.5) * texel;
#ifdef SKIP_WORK
    // The variant with the work skipped (build.rs, `render --variants`): one
    // read and the output, nothing else.
    imageStore(dst, p, textureLod(src, uv, 0.0));
    return;
#endif
    // (r, g, b) in texels of this size per mm; in the gutter, one texel per mm.
    vec4 st = textureLod(stretch, uv, 0.0);
    vec2 scale = vec2(size) / vec2(textureSize(stretch, 0));
    vec3 s = st.a > 1e-4 ? st.rgb / st.a * scale.xyx : vec3(1.0, 1.0, 0.0);
    float v = pc.sigma_mm * pc.sigma_mm;
    float x = v * (s.x * s.x + s.z * s.z), y = v * s.y * s.y, xy = v * s.z * s.y;
    vec4 sum;
    if (FIVE) {
        vec2 tx = five_taps(max(x - BOX, 0.0)), ty = five_taps(max(y - BOX, 0.0));
        if (HALF) {
            tx.y = half_tap_offset(tap_moment(tx.y) + BOX);
            ty.y = half_tap_offset(tap_moment(ty.y) + BOX);
        }
        vec2 dx = vec2(tx.y * texel.x, 0.0), dy = vec2(0.0, ty.y * texel.y);
        // k on the corners: the tensor product's 4·hx·hy, or up to 2·min(hx, hy)
        // (all the side weight) where the cross moment k·γ·Dx·Dy needs more.
        float dd = tx.y * ty.y;
        float k = max(4.0 * tx.x * ty.x, min(abs(xy) / dd, 2.0 * min(tx.x, ty.x)));
        float gamma = clamp(xy / max(k * dd, 1e-12), -1.0, 1.0);
        sum = (1.0 - 2.0 * (tx.x + ty.x) + k) * at(uv, vec2(0.0))
            + (tx.x - 0.5 * k) * (at(uv, dx) + at(uv, -dx))
            + (ty.x - 0.5 * k) * (at(uv, dy) + at(uv, -dy))
            + 0.25 * k * ((1.0 + gamma) * (at(uv, dx + dy) + at(uv, -dx - dy))
                        + (1.0 - gamma) * (at(uv, dx - dy) + at(uv, dy - dx)));
    } else {
        vec2 o = vec2(tap_offset(x), tap_offset(y));
        float a = min(abs(xy), min(min(x, y), 1.0));
        bool paired = a <= o.x * o.y;
        vec2 d1 = paired ? o : vec2(a / y, a / x);
        vec2 d2 = paired ? o : vec2(0.0);
        float w1 = paired ? 0.5 + 0.5 * a / max(o.x * o.y, 1e-12) : x * y / a;
        // d1 on the diagonal of Σuv's sign, d2 across it.
        float sgn = xy < 0.0 ? -1.0 : 1.0;
        d1 *= vec2(1.0, sgn) * texel;
        d2 *= vec2(1.0, -sgn) * texel;
        sum = 0.5 * (w1 * (at(uv, d1) + at(uv, -d1)) + (1.0 - w1) * (at(uv, d2) + at(uv, -d2)));
    }
    imageStore(dst, p, sum);
}
