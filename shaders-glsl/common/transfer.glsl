// Per-vertex SH visibility transfer (the paper's eq. 12-13; light/occlusion.rs):
// nine coefficients per vertex, read by gl_VertexIndex and interpolated as three vec3.
layout(std430, binding = 4) readonly buffer Transfer { float transfer[]; };

void load_transfer(out vec3 t012, out vec3 t345, out vec3 t678) {
    uint b = uint(gl_VertexIndex) * 9u;
    t012 = vec3(transfer[b], transfer[b + 1u], transfer[b + 2u]);
    t345 = vec3(transfer[b + 3u], transfer[b + 4u], transfer[b + 5u]);
    t678 = vec3(transfer[b + 6u], transfer[b + 7u], transfer[b + 8u]);
}

#ifdef BOUNCE
// The interreflected transfer (light/interreflection.rs): nine coefficients per
// channel per vertex, R then G then B.
layout(std430, binding = BOUNCE) readonly buffer Bounce { float bounce[]; };

// Irradiance the skin reflects onto this vertex under SH radiance L (rgb).
vec3 bounce_irradiance(vec3 L[9]) {
    uint b = uint(gl_VertexIndex) * 27u;
    vec3 e = vec3(0.0);
    for (uint j = 0u; j < 9u; ++j) {
        e += L[j] * vec3(bounce[b + j], bounce[b + 9u + j], bounce[b + 18u + j]);
    }
    return e;
}
#endif
