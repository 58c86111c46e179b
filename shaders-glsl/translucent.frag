#version 460
// The light of the shadowed lights transmitted through thin skin, in texture
// space, once per lighting (skin/translucent.rs; docs/records/2026-11-26-transmission.md, "Transmission"):
// translucent shadow maps (d'Eon & Luebke §14.5.3; Jimenez et al. 2010). For
// each light the surface faces away from (dot(ng, l) < 0, so a lit face, whose
// thickness is ≈ 0, is not lit twice) and whose light enters by a surface
// facing away from this one (a thin part's far side), the light's irradiance
// on the light-facing surface — its normal taken as −n, the light entering less what
// the specular reflects there (this point's ρs, m) — through the thickness the
// shadow map gives, T(d) = Σ wᵢ exp(−d²/2vᵢ) or, with a medium, its walked
// T(d) (skin::medium_tables). Both sides of the surface, as
// the final pass shades both: front (the mesh's normal) and back (reversed);
// premultiplied by coverage (alpha 1 on the mesh, 0 in the gutter) so that the
// final pass renormalises where its bilinear lookup reaches past a chart's
// border. Nothing here depends on the camera.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "frame.glsl"
#define SHADOW_ATLAS 1
#define SHADOW_DEPTH 2
#include "lights.glsl"
layout(binding = 3) uniform sampler2D normal_tex;
#define SPEC_BECKMANN 4
#define SPEC_ALBEDO 5
#define SPEC_REGIONS 6
#define SPEC_INTENSITY 7
#define SPEC_ROUGHNESS 8
#include "ks_specular.glsl"
#include "normal_map.glsl"
// A medium's T(d) divided by its albedo, sample i at d = table_max_mm·(i/(n − 1))²
// (skin::medium_tables; the final pass multiplies by the albedo).
layout(binding = 9) uniform sampler2D transmittance_table;
// weights: rgb the Gaussians' weights, w their variances (mm²); table_max_mm:
// the thickness of the table's last sample.
layout(push_constant) uniform Push { vec4 weights[6]; float table_max_mm; } pc;
// T(d) from the medium's table instead of the Gaussians
// (skin::translucent::TranslucentPass::new).
layout(constant_id = 6) const bool TABLE = false;
layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
layout(location = 3) in vec4 v_tangent;
layout(location = 0) out vec4 front;
layout(location = 1) out vec4 back;

// T(d) = Σ wᵢ exp(−d²/2vᵢ): the profile through a slab d mm thick, per channel
// (G(v, √(r² + d²)) = G(v, r)·exp(−d²/2v); skin::profile::Profile::transmittance).
vec3 transmittance(float d) {
    if (TABLE) {
        if (d > pc.table_max_mm) return vec3(0.0);
        float n = float(textureSize(transmittance_table, 0).x);
        float u = (sqrt(d / pc.table_max_mm) * (n - 1.0) + 0.5) / n;
        return textureLod(transmittance_table, vec2(u, 0.5), 0.0).rgb;
    }
    vec3 t = vec3(0.0);
    for (int k = 0; k < 6; ++k) {
        float v = pc.weights[k].w;
        float keep = v > 0.0 ? exp(-d * d / (2.0 * v)) : (d <= 0.0 ? 1.0 : 0.0);
        t += pc.weights[k].rgb * keep;
    }
    return t;
}

// The irradiance transmitted to x on the side of geometric normal ng and
// shading normal n.
vec3 transmitted(vec3 x, vec3 ng, vec3 n, vec2 params) {
    vec3 sum = vec3(0.0);
    [[unroll]] for (int i = 0; i < LIGHT_COUNT; ++i) {
        if ((SHADOWED_LIGHTS & (1 << i)) == 0) continue;
        vec3 l;
        float dist;
        vec3 e = light_incident(i, x, l, dist);
        if (dot(ng, l) >= 0.0) continue;
        // Only light that enters on the far side of a thin part, whose surface
        // faces away from x's (as light/transmission.rs counts the sky's): light
        // entering just before a terminator, or at the mesh's open cut, is what
        // the chain already carries along the surface.
        StoredDepths stored = stored_depths(i, x);
        if (dot(entry_normal(i, stored), ng) >= 0.0) continue;
        float facing = max(dot(-n, l), 0.0);
        if (facing <= 0.0) continue;
        facing *= diffuse_transmission(facing, light_lobe(i, params));
        sum += e * facing * transmittance(shadow_thickness(i, stored, dist));
    }
    return sum;
}

void main() {
    vec3 n = map_normal(normal_tex, v_uv, v_normal, v_tangent);
    vec2 params = specular_params(v_uv);
    front = vec4(transmitted(v_position, v_normal, n, params), 1.0);
    back = vec4(transmitted(v_position, -v_normal, -n, params), 1.0);
}
