// Diffuse irradiance at a surface point: the environment through SH — with
// occlusion, E = Σ L_i·T_i from the interpolated per-vertex transfer (the paper's
// eq. 13); without, Ramamoorthi & Hanrahan at the shading normal — plus the
// explicit lights at x (geometric normal ng). Needs frame.glsl, sh.glsl,
// lights.glsl (and GL_EXT_control_flow_attributes), the Lighting buffer and v_t*
// (and v_indirect with INDIRECT: the light the skin reflects onto itself and the
// sky's through thin skin, light/interreflection.rs, light/transmission.rs).
// With ENERGY_CONSERVING (and ks_specular.glsl), each light is scaled by
// 1 − ρs·A(N·L, m): what the specular reflects does not enter the skin. The
// environment is scaled by env_share, its share that enters: 1 − ρs·Ā(m)
// (diffuse_transmission_uniform, which the caller has at hand), 1 without.
vec3 irradiance_at(vec3 x, vec3 ng, vec3 n, vec2 uv, vec2 spec_params, float env_share) {
    vec3 e;
    if (OCCLUSION) {
        e = lighting.sh[0].rgb * v_t012.x + lighting.sh[1].rgb * v_t012.y
          + lighting.sh[2].rgb * v_t012.z + lighting.sh[3].rgb * v_t345.x
          + lighting.sh[4].rgb * v_t345.y + lighting.sh[5].rgb * v_t345.z
          + lighting.sh[6].rgb * v_t678.x + lighting.sh[7].rgb * v_t678.y
          + lighting.sh[8].rgb * v_t678.z;
#ifdef INDIRECT
        e += v_indirect;
#endif
    } else {
        e = sh_irradiance(lighting.sh, n);
    }
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
