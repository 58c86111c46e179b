// The light the skin reflects onto this vertex (light/interreflection.rs): the
// interreflected transfer applied to the environment's SH and to the explicit
// lights projected into SH here (a directional light of irradiance E from l is
// the radiance E·δ(ω − l), coefficients E·y_j(l); a point light's seen from
// the vertex), plus the environment's light through thin skin
// (light/transmission.rs; the lights' is the final pass's); zero without
// occlusion. For vertex shaders: needs frame.glsl, sh_basis.glsl,
// incident.glsl, transfer.glsl with RGB_TRANSFER, the Lighting block and
// GL_EXT_control_flow_attributes.
vec3 indirect_irradiance(vec3 position) {
    if (!OCCLUSION) return vec3(0.0);
    vec3 L[9];
    for (int j = 0; j < 9; ++j) L[j] = lighting.sh[j].rgb;
    vec3 through = rgb_transfer_irradiance(TRANSMITTED, L);
    [[unroll]] for (int i = 0; i < LIGHT_COUNT; ++i) {
        vec3 l;
        float dist;
        vec3 e = light_incident(i, position, l, dist);
        float y[9];
        sh_basis(l, y);
        for (int j = 0; j < 9; ++j) L[j] += e * y[j];
    }
    return rgb_transfer_irradiance(INTERREFLECTED, L) + through;
}

// lighting.glsl's `occluded` at this vertex, for the skin passes to
// interpolate: the environment through the vertex's transfer (sh_transferred;
// needs sh.glsl) plus indirect_irradiance.
vec3 occluded_irradiance(vec3 position) {
    vec3 t012, t345, t678;
    load_transfer(t012, t345, t678);
    return sh_transferred(lighting.sh, t012, t345, t678) + indirect_irradiance(position);
}
