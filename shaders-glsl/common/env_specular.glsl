// The KS-prefiltered environment (light/prefilter.rs): ENV_SPEC_LEVELS equirect
// images of ENV_SPEC_W × ENV_SPEC_H stacked in v, level k for Beckmann roughness
// m = ENV_SPEC_M0 + k·ENV_SPEC_DM. With ENV_SPECULAR defined (its binding, after
// frame.glsl and envmap.glsl), declares the lookup.
#define ENV_SPEC_W 128
#define ENV_SPEC_H 64
#define ENV_SPEC_LEVELS 8
#define ENV_SPEC_M0 0.1
#define ENV_SPEC_DM 0.1

#ifdef ENV_SPECULAR
layout(binding = ENV_SPECULAR) uniform sampler2D env_specular;

// Lobe-averaged environment radiance around the world direction r for roughness
// m, rotated and scaled like the background; m is clamped to the tabulated range
// and interpolated linearly between levels.
vec3 prefiltered_radiance(vec3 r, float m) {
    vec2 uv = equirect_uv(env_dir(r, frame.env.x));
    float k = clamp((m - ENV_SPEC_M0) / ENV_SPEC_DM, 0.0, float(ENV_SPEC_LEVELS - 1));
    float k0 = floor(k);
    float k1 = min(k0 + 1.0, float(ENV_SPEC_LEVELS - 1));
    // Stay half a texel inside each level so bilinear taps do not cross levels.
    float v = clamp(uv.y, 0.5 / ENV_SPEC_H, 1.0 - 0.5 / ENV_SPEC_H);
    vec3 a = textureLod(env_specular, vec2(uv.x, (k0 + v) / ENV_SPEC_LEVELS), 0.0).rgb;
    vec3 b = textureLod(env_specular, vec2(uv.x, (k1 + v) / ENV_SPEC_LEVELS), 0.0).rgb;
    return mix(a, b, k - k0) * frame.env.y;
}
#endif
