// The explicit lights of frame.glsl: directional, or point with 1/d² falloff, each
// optionally shadowed by its tile of the shadow atlas (light/shadow.rs), read with
// 3×3 bilinear PCF. Expects SHADOW_ATLAS: the atlas's binding.
layout(binding = SHADOW_ATLAS) uniform sampler2DShadow shadow_atlas;

const float POINT_REFERENCE_MM = 1000.0;   // scene::POINT_LIGHT_REFERENCE_MM
// Acne offsets, in shadow-map texels: along the normal (normal-offset shadows,
// Holbert 2011) and towards the light (a constant depth bias in world units).
// The PCF taps reach 2 texels from the lookup; a surface tilted θ from the light
// then stays behind the lookup point when the normal offset is ≥ 2·sin θ texels.
const float NORMAL_OFFSET_TEXELS = 2.5;
const float LIGHT_OFFSET_TEXELS = 1.0;

// Fraction of light i that reaches x (surface normal ng) from direction l.
float shadow_visibility(int i, vec3 x, vec3 ng, vec3 l, float dist) {
    float texel = frame.light_color[i].w * (frame.light_vec[i].w > 0.5 ? dist : 1.0);
    vec3 side = dot(ng, l) < 0.0 ? -ng : ng;
    vec3 p = x + texel * (NORMAL_OFFSET_TEXELS * side + LIGHT_OFFSET_TEXELS * l);
    vec4 s = frame.light_shadow[i] * vec4(p, 1.0);
    s.xyz /= s.w;
    if (s.z <= 0.0 || s.z >= 1.0) return 1.0;   // outside the light's frustum
    vec2 step = 1.0 / vec2(textureSize(shadow_atlas, 0));
    float lit = 0.0;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            lit += texture(shadow_atlas, vec3(s.xy + vec2(dx, dy) * step, s.z));
        }
    }
    return lit / 9.0;
}

// Irradiance light i delivers at x to a surface facing it (shadowed; mirrors
// scene::Light::at); l: the unit direction towards the light.
vec3 light_irradiance(int i, vec3 x, vec3 ng, out vec3 l) {
    vec4 lv = frame.light_vec[i];
    vec3 e = frame.light_color[i].rgb;
    float dist = 1.0;
    if (lv.w > 0.5) {
        vec3 d = lv.xyz - x;
        float d2 = max(dot(d, d), 1e-6);
        dist = sqrt(d2);
        l = d / dist;
        e *= POINT_REFERENCE_MM * POINT_REFERENCE_MM / d2;
    } else {
        l = lv.xyz;
    }
    if ((SHADOWED_LIGHTS & (1 << i)) != 0) e *= shadow_visibility(i, x, ng, l, dist);
    return e;
}
