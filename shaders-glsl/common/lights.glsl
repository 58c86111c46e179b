// The explicit lights of frame.glsl: directional, or point with 1/d² falloff, each
// optionally shadowed by its tile of the shadow atlas (light/shadow.rs). Point-like
// lights are read with 3×3 bilinear PCF. Lights with an angular size (the sources
// extracted from the environment) have percentage-closer soft shadows, so the
// penumbra follows the source's size; they are computed once per frame in texture
// space by light_visibility.frag (light/visibility.rs), which defines
// SHADOW_DEPTH (the atlas again, nearest, no comparison), and read back by the
// shading passes, which define SOFT_VISIBILITY: the first of three bindings of
// the visibility textures, three lights each, coverage-premultiplied.
// translucent.frag defines SHADOW_DEPTH too, for the thickness light passes
// through and the surface it enters by (shadow_thickness, entry_normal:
// transmission).
// Expects SHADOW_ATLAS: the atlas with a depth-comparison sampler, and
// GL_EXT_control_flow_attributes for its [[unroll]] loops (frame.glsl says why).
// A fragment shader that looks up a hard light's shadow sets shading_dpdx/dpdy
// first.
layout(binding = SHADOW_ATLAS) uniform sampler2DShadow shadow_atlas;
#include "incident.glsl"

// The shaded sample's window position (a compute pass over a UV map defines
// it as its texel's centre).
#ifndef SHADING_POINT
#define SHADING_POINT gl_FragCoord.xy
#endif

// The shaded point's position derivatives across its pixel (or, over a UV
// raster, its texel): dFdx/dFdy of the position, taken by the fragment shader
// in uniform control flow before any lookup. A point or directional source
// casts a step; its filter covers this footprint and no more (hard_shadow).
vec3 shading_dpdx = vec3(0.0), shading_dpdy = vec3(0.0);

// Acne offsets, in shadow-map texels: along the normal (normal-offset shadows,
// Holbert 2011) and towards the light (a constant depth bias in world units).
// The PCF taps reach 2 texels from the lookup; a surface tilted θ from the light
// then stays behind the lookup point when the normal offset is ≥ 2·sin θ texels.
const float NORMAL_OFFSET_TEXELS = 2.5;
const float LIGHT_OFFSET_TEXELS = 1.0;
// Soft shadows (Fernando 2005, PCSS): taps of the blocker search and of the
// filter, on a Vogel (golden-angle) disk turned per pixel; the filter's radius is
// clamped to what those taps can cover without gaps turning into bands.
const int BLOCKER_TAPS = 8;
const int PCF_TAPS = 12;
const float MAX_SOFT_TEXELS = 48.0;

// A per-pixel rotation by interleaved gradient noise (Jimenez 2014).
mat2 soft_shadow_turn() {
    float a = 6.2831853 * fract(52.9829189 * fract(dot(SHADING_POINT, vec2(0.06711056, 0.00583715))));
    float c = cos(a), s = sin(a);
    return mat2(c, s, -s, c);
}

// Tap k of n on a unit Vogel disk (radius √((k + ½)/n), golden angle): constant
// once the loops are unrolled, so a tap costs one rotation.
vec2 vogel_tap(int k, int n) {
    float a = float(k) * 2.39996323;
    return sqrt((float(k) + 0.5) / float(n)) * vec2(cos(a), sin(a));
}

// Slot of soft light i among the soft lights (a constant once unrolled).
int soft_slot(int i) {
    return bitCount(SOFT_LIGHTS & ((1 << i) - 1));
}

// One of light i's shadow maps: world to atlas (u, v, depth), its texel (mm)
// and the depth of the nearest surface it holds (no blocker lies nearer).
struct ShadowMap {
    mat4 to_atlas;
    float texel;
    float nearest;
};

// Texels around a lookup that the acne offsets can move it (2.5 along the
// normal, 1 along the light) and the 3×3 PCF reach.
const float LOOKUP_REACH_TEXELS = 6.0;

// Light i's map for x: its focus tile (light/shadow.rs: the window of the whole
// map that holds what the camera sees, at the same resolution) where the lookup,
// its filter and, for a source of angular radius atan(tan_r), the blocker search
// lie inside it and that search needs at most MAX_SOFT_TEXELS of it; else the
// tile of the whole mesh.
ShadowMap shadow_map(int i, vec3 x, float tan_r) {
    vec4 tile = frame.light_focus_tile[i];
    if (tile.x > 0.0) {
        vec4 s = frame.light_focus[i] * vec4(x, 1.0);
        vec3 p = s.xyz / s.w;
        float search = (p.z - tile.y) * frame.light_params[i].y * tan_r / tile.x;
        vec2 reach = (LOOKUP_REACH_TEXELS + search) / vec2(textureSize(shadow_atlas, 0));
        vec2 lo = tile.zw + reach, hi = tile.zw + 1.0 / frame.params.zw - reach;
        if (search <= MAX_SOFT_TEXELS && all(greaterThan(p.xy, lo)) && all(lessThan(p.xy, hi))) {
            return ShadowMap(frame.light_focus[i], tile.x, tile.y);
        }
    }
    return ShadowMap(frame.light_shadow[i], frame.light_color[i].w, 0.0);
}

// The atlas point (u, v, depth) of map m for x (surface normal ng, direction l
// to the light, dist to a point light: m's texel is per mm of it), with the
// acne offsets.
vec4 shadow_point(ShadowMap m, bool point, vec3 x, vec3 ng, vec3 l, float dist) {
    float texel = m.texel * (point ? dist : 1.0);
    vec3 side = dot(ng, l) < 0.0 ? -ng : ng;
    vec3 p = x + texel * (NORMAL_OFFSET_TEXELS * side + LIGHT_OFFSET_TEXELS * l);
    vec4 s = m.to_atlas * vec4(p, 1.0);
    return vec4(s.xyz / s.w, 1.0);
}

#ifdef SHADOW_DEPTH
layout(binding = SHADOW_DEPTH) uniform sampler2D shadow_depth;

// Receiver-plane depth slope (Isidoro 2006): d depth / d(atlas u, v) on the plane
// through the shaded point with normal ng, seen by light i's (orthographic) map,
// so that wide kernels compare each tap with the surface under it rather than
// with the point's own depth. Clamped where the plane is seen nearly edge-on.
vec2 receiver_slope(int i, ShadowMap m, vec3 ng, vec2 step) {
    vec3 t1 = normalize(cross(ng, abs(ng.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0)));
    vec3 t2 = cross(ng, t1);
    vec3 a = (m.to_atlas * vec4(t1, 0.0)).xyz;
    vec3 b = (m.to_atlas * vec4(t2, 0.0)).xyz;
    mat2 j = mat2(a.xy, b.xy);
    if (abs(determinant(j)) < 1e-12) return vec2(0.0);
    vec2 slope = vec2(a.z, b.z) * inverse(j);
    // At most an 80° tilt: tan 80° = 5.7 mm of depth per mm, per texel (texel
    // mm across) in units of the depth range (mm); per texel, since an atlas of
    // 2 × 1 tiles has texels twice as narrow in u as in v.
    vec2 per_texel = slope * step;
    float limit = 5.7 * m.texel / frame.light_params[i].y;
    float len = length(per_texel);
    return len > limit ? slope * (limit / len) : slope;
}

// Fraction of a source of angular radius atan(tan_r) that reaches the atlas
// point s (u, v, depth) on a surface of normal ng: blockers found within the
// reach of the source's cone give the penumbra's radius, (receiver − blocker
// distance)·tan r, averaged over the blockers (Fernando 2005).
float soft_visibility(int i, ShadowMap m, vec3 s, vec3 ng, vec2 step) {
    float tan_r = frame.light_params[i].x;
    float range = frame.light_params[i].y;
    float texel = m.texel;
    // Taps stay inside this light's tile of the atlas.
    vec2 tiles = frame.params.zw;
    vec2 lo = floor(s.xy * tiles) / tiles + 0.5 * step;
    vec2 hi = lo + 1.0 / tiles - step;
    vec2 slope = receiver_slope(i, m, ng, step);
    float eps = texel / range;   // one texel of depth
    mat2 turn = soft_shadow_turn();
    float search = clamp((s.z - m.nearest) * range * tan_r / texel, 1.0, MAX_SOFT_TEXELS);
    float distance = 0.0, count = 0.0;
    [[unroll]] for (int k = 0; k < BLOCKER_TAPS; ++k) {
        vec2 d = turn * vogel_tap(k, BLOCKER_TAPS) * search * step;
        vec2 p = clamp(s.xy + d, lo, hi);
        float receiver = s.z + dot(slope, p - s.xy);
        float z = textureLod(shadow_depth, p, 0.0).r;
        if (z < receiver - eps) {
            distance += receiver - z;
            count += 1.0;
        }
    }
    // No blocker: lit; every tap a blocker: the umbra (the filter, whose radius
    // is at most the search's, would find the same).
    if (count == 0.0) return 1.0;
    if (count == float(BLOCKER_TAPS)) return 0.0;
    float radius = clamp(distance / count * range * tan_r / texel, 1.0, MAX_SOFT_TEXELS);
    float lit = 0.0;
    [[unroll]] for (int k = 0; k < PCF_TAPS; ++k) {
        vec2 p = clamp(s.xy + turn * vogel_tap(k, PCF_TAPS) * radius * step, lo, hi);
        lit += texture(shadow_atlas, vec3(p, s.z + dot(slope, p - s.xy)));
    }
    return lit / float(PCF_TAPS);
}

// Soft light i's visibility at x (normal ng), from the atlas.
float soft_shadow(int i, vec3 x, vec3 ng) {
    ShadowMap m = shadow_map(i, x, frame.light_params[i].x);
    vec3 s = shadow_point(m, false, x, ng, frame.light_vec[i].xyz, 1.0).xyz;
    if (s.z <= 0.0 || s.z >= 1.0) return 1.0;   // outside the light's frustum
    return soft_visibility(i, m, s, ng, 1.0 / vec2(textureSize(shadow_atlas, 0)));
}
#endif

#ifdef SHADOW_DEPTH
// The depths light i's map stores about x: the four texels z around x's
// point p in the map, (u0, v1), (u1, v1), (u1, v0), (u0, v0), read at uv, which
// keeps them inside this light's tile of the atlas. One gather serves both
// shadow_thickness and entry_normal.
struct StoredDepths {
    vec4 z;
    vec3 p;
    vec2 uv;
};

StoredDepths stored_depths(int i, vec3 x) {
    vec4 s = frame.light_shadow[i] * vec4(x, 1.0);
    StoredDepths d;
    d.p = s.xyz / s.w;
    vec2 size = vec2(textureSize(shadow_depth, 0));
    vec2 tiles = frame.params.zw;
    vec2 lo = floor(d.p.xy * tiles) / tiles + 0.5 / size;
    d.uv = clamp(d.p.xy, lo, lo + 1.0 / tiles - 1.0 / size);
    d.z = textureGather(shadow_depth, d.uv, 0);
    return d;
}

// The distance (mm) light i's ray to x travels inside the mesh before reaching
// x: from the first surface the atlas stores along that ray to x (translucent
// shadow maps, d'Eon & Luebke §14.5.3; Jimenez et al. 2010). Looked up at x's
// own atlas point, without the acne offsets of shadow_point (they would enter
// the thickness); the four nearest texels' thicknesses, each clamped at 0 (a
// texel whose surface lies behind x, or that holds none: depth 1, adds none),
// weighted bilinearly. A directional light's depth is linear over the depth
// range (light_params.y, mm). A point light's perspective depth z is made the
// distance along the map's axis first, n·f/(f − z(f − n)) (near n in
// light_params.w, f = n + range); two points on one ray from the light have
// distances along it in the ratio of their axial distances, so the thickness
// is dist·(1 − axial(stored)/axial(x)), dist = |light − x|
// (light::shadow::ShadowView::thickness_mm mirrors this). From the whole-mesh
// map: the profile's transmittance changes over millimetres, its 0.33 mm texels
// do, and choosing the focus map cost the final pass 7-10 % when it looked the thickness up per pixel.
float shadow_thickness(int i, StoredDepths stored, float dist) {
    vec4 z = stored.z;
    vec3 p = stored.p;
    vec2 f = fract(stored.uv * vec2(textureSize(shadow_depth, 0)) - 0.5);
    vec4 w = vec4((1.0 - f.x) * f.y, f.x * f.y, f.x * (1.0 - f.y), (1.0 - f.x) * (1.0 - f.y));
    float range = frame.light_params[i].y;
    vec4 t;
    if (frame.light_vec[i].w > 0.5) {
        float near = frame.light_params[i].w;
        float far = near + range;
        vec4 axial = near * far / (far - z * range);
        float axial_x = near * far / (far - p.z * range);
        t = dist * (1.0 - axial / axial_x);
    } else {
        t = (p.z - z) * range;
    }
    return dot(w, max(t, vec4(0.0)));
}

// The normal, facing the light, of the surface light i's map holds on the way
// to x (where its light enters the skin), from the slope of the map's depth:
// with the map's rows a, b, c, d (atlas u, v, depth, w), a surface of depth
// z(u, v) has the world normal z_u(a − u·d) + z_v(b − v·d) − (c − z·d), up to a
// positive scale (the gradient of z(u, v) − depth through the projection).
// Unnormalised; across the light's silhouette the slope is steep and the
// normal turns sideways.
vec3 entry_normal(int i, StoredDepths stored) {
    vec4 z = stored.z;
    vec3 p = stored.p;
    vec2 size = vec2(textureSize(shadow_depth, 0));
    mat4 m = frame.light_shadow[i];
    float zu = 0.5 * ((z.y + z.z) - (z.x + z.w)) * size.x;
    float zv = 0.5 * ((z.x + z.y) - (z.z + z.w)) * size.y;
    float zc = 0.25 * (z.x + z.y + z.z + z.w);
    vec3 a = vec3(m[0][0], m[1][0], m[2][0]);
    vec3 b = vec3(m[0][1], m[1][1], m[2][1]);
    vec3 c = vec3(m[0][2], m[1][2], m[2][2]);
    vec3 d = vec3(m[0][3], m[1][3], m[2][3]);
    return zu * (a - p.x * d) + zv * (b - p.y * d) - (c - zc * d);
}
#endif

#ifdef SOFT_VISIBILITY
layout(binding = SOFT_VISIBILITY) uniform sampler2D soft_visibility0;
layout(binding = SOFT_VISIBILITY + 1) uniform sampler2D soft_visibility1;
layout(binding = SOFT_VISIBILITY + 2) uniform sampler2D soft_visibility2;

// Soft light i's visibility at texture coordinate uv, as light_visibility.frag
// stored it: renormalised by coverage, so chart borders do not pull in the gutter.
float stored_soft_visibility(int i, vec2 uv) {
    int slot = soft_slot(i);
    vec4 t = slot < 3 ? textureLod(soft_visibility0, uv, 0.0)
           : slot < 6 ? textureLod(soft_visibility1, uv, 0.0)
                      : textureLod(soft_visibility2, uv, 0.0);
    return t[slot % 3] / max(t.a, 1e-3);
}
#endif

#ifdef HARD_VISIBILITY
layout(binding = HARD_VISIBILITY) uniform sampler2D hard_visibility0;
layout(binding = HARD_VISIBILITY + 1) uniform sampler2D hard_visibility1;
layout(binding = HARD_VISIBILITY + 2) uniform sampler2D hard_visibility2;

// Hard light i's visibility at this sample, as light_visibility.frag (HARD)
// stored it over the same UV raster at the same resolution: texel for texel.
float stored_hard_visibility(int i) {
    int slot = bitCount(SHADOWED_LIGHTS & ~SOFT_LIGHTS & ((1 << i) - 1));
    ivec2 p = ivec2(SHADING_POINT);
    vec4 t = slot < 3 ? texelFetch(hard_visibility0, p, 0)
           : slot < 6 ? texelFetch(hard_visibility1, p, 0)
                      : texelFetch(hard_visibility2, p, 0);
    return t[slot % 3];
}
#endif

// Fraction of light i (without an angular size) that reaches x (surface normal
// ng) from direction l: 3×3 bilinear PCF, its taps spread over the shaded
// sample's footprint in the map (the penumbra follows the light's
// size, here none, not the map's texel). Taps d texels apart have variance
// 2d²/3 plus a bilinear tap's 1/6; the footprint's box of f texels, f²/12:
// d = √(f²/8 − ¼), from 0 (one bilinear comparison's worth) to 1 texel (the
// reach the acne offsets allow for). docs/design/lighting.md.
float hard_shadow(int i, vec3 x, vec3 ng, vec3 l, float dist) {
    ShadowMap m = shadow_map(i, x, 0.0);
    vec3 s = shadow_point(m, frame.light_vec[i].w > 0.5, x, ng, l, dist).xyz;
    if (s.z <= 0.0 || s.z >= 1.0) return 1.0;   // outside the light's frustum
    vec2 size = vec2(textureSize(shadow_atlas, 0));
    // The footprint in atlas texels: the map's projection differentiated at x.
    vec4 c = m.to_atlas * vec4(x, 1.0);
    vec4 cx = m.to_atlas * vec4(shading_dpdx, 0.0), cy = m.to_atlas * vec4(shading_dpdy, 0.0);
    vec2 fx = (cx.xy - c.xy / c.w * cx.w) / c.w * size;
    vec2 fy = (cy.xy - c.xy / c.w * cy.w) / c.w * size;
    float footprint = max(length(fx), length(fy));
    vec2 step = min(sqrt(max(footprint * footprint / 8.0 - 0.25, 0.0)), 1.0) / size;
    float lit = 0.0;
    [[unroll]] for (int dy = -1; dy <= 1; ++dy) {
        [[unroll]] for (int dx = -1; dx <= 1; ++dx) {
            lit += texture(shadow_atlas, vec3(s.xy + vec2(dx, dy) * step, s.z));
        }
    }
    return lit / 9.0;
}

// Fraction of light i that reaches x (surface normal ng, texture coordinate uv)
// from direction l.
float shadow_visibility(int i, vec3 x, vec3 ng, vec2 uv, vec3 l, float dist) {
#ifdef SOFT_VISIBILITY
    if ((SOFT_LIGHTS & (1 << i)) != 0) return stored_soft_visibility(i, uv);
#endif
#ifdef HARD_VISIBILITY
    if ((SOFT_LIGHTS & (1 << i)) == 0) return stored_hard_visibility(i);
#endif
    return hard_shadow(i, x, ng, l, dist);
}

// Irradiance light i delivers at x (texture coordinate uv) to a surface facing
// it (shadowed; mirrors scene::Light::at); l: the unit direction towards the
// light. 0 where the shading normal n faces away from it (its shadow is not
// looked up there).
vec3 light_irradiance(int i, vec3 x, vec3 ng, vec3 n, vec2 uv, out vec3 l) {
    float dist;
    vec3 e = light_incident(i, x, l, dist);
    if (dot(n, l) <= 0.0) return vec3(0.0);
    if ((SHADOWED_LIGHTS & (1 << i)) != 0) e *= shadow_visibility(i, x, ng, uv, l, dist);
    return e;
}

// The specular lobe's (ρs, m) for light i: a source of angular size widens it,
// m² + light_params.z (light/shadow.rs::lobe_widening).
vec2 light_lobe(int i, vec2 params) {
    return vec2(params.x, sqrt(params.y * params.y + frame.light_params[i].z));
}
