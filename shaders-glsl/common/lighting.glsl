// Diffuse irradiance at a surface point: the environment — with occlusion,
// `occluded`, its irradiance through the per-vertex transfer interpolated from
// the vertices (sh_transferred: Yang et al.'s eq. 13; in the skin passes plus
// the light the skin reflects onto itself and the sky's through thin skin,
// common/indirect.glsl); without, Ramamoorthi & Hanrahan at the shading
// normal — plus the explicit lights at x (geometric normal ng). Needs
// frame.glsl, sh.glsl, lights.glsl (and GL_EXT_control_flow_attributes) and
// the Lighting buffer.
// With ENERGY_CONSERVING (and ks_specular.glsl), each light is scaled by
// 1 − ρs·A(N·L, m): what the specular reflects does not enter the skin. The
// environment is scaled by env_share, its share that enters: 1 − ρs·Ā(m)
// (diffuse_transmission_uniform, which the caller has at hand), 1 without.
vec3 irradiance_at(vec3 occluded, vec3 x, vec3 ng, vec3 n, vec2 uv, vec2 spec_params, float env_share) {
    vec3 e = OCCLUSION ? occluded : sh_irradiance(lighting.sh, n);
    e = max(e, vec3(0.0)) * env_share;
    [[unroll]] for (int i = 0; i < LIGHT_COUNT; ++i) {
        vec3 l;
        vec3 e_light = light_irradiance(i, x, ng, n, uv, l);
        float n_dot_l = max(dot(n, l), 0.0);
#ifdef ENERGY_CONSERVING
        n_dot_l *= diffuse_transmission(n_dot_l, light_lobe(i, spec_params));
#endif
        e += e_light * n_dot_l;
    }
    return e;
}
