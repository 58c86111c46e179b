// Per-vertex SH visibility transfer (the paper's eq. 12-13; light/occlusion.rs):
// nine coefficients per vertex, then the nine of its lobe visibility (the
// environment specular's occlusion, light/occlusion/lobe.rs), read by
// VERTEX_INDEX and interpolated as three vec3 each.
layout(std430, binding = 4) readonly buffer Transfer { float transfer[]; };
// The vertex (a compute pass over the vertices defines it).
#ifndef VERTEX_INDEX
#define VERTEX_INDEX gl_VertexIndex
#endif

void load_transfer(out vec3 t012, out vec3 t345, out vec3 t678) {
    uint b = uint(VERTEX_INDEX) * 18u;
    t012 = vec3(transfer[b], transfer[b + 1u], transfer[b + 2u]);
    t345 = vec3(transfer[b + 3u], transfer[b + 4u], transfer[b + 5u]);
    t678 = vec3(transfer[b + 6u], transfer[b + 7u], transfer[b + 8u]);
}

void load_lobe_visibility(out vec3 s012, out vec3 s345, out vec3 s678) {
    uint b = uint(VERTEX_INDEX) * 18u + 9u;
    s012 = vec3(transfer[b], transfer[b + 1u], transfer[b + 2u]);
    s345 = vec3(transfer[b + 3u], transfer[b + 4u], transfer[b + 5u]);
    s678 = vec3(transfer[b + 6u], transfer[b + 7u], transfer[b + 8u]);
}

#ifdef RGB_TRANSFER
// Per vertex the interreflected transfer (light/interreflection.rs) and the
// environment's transmitted one (light/transmission.rs): nine coefficients per
// channel each, R then G then B.
layout(std430, binding = RGB_TRANSFER) readonly buffer RgbTransfer { float rgb_transfer[]; };
const uint INTERREFLECTED = 0u;
const uint TRANSMITTED = 27u;

// Irradiance under SH radiance L (rgb) through this vertex's transfer `which`.
vec3 rgb_transfer_irradiance(uint which, vec3 L[9]) {
    uint b = uint(VERTEX_INDEX) * 54u + which;
    vec3 e = vec3(0.0);
    for (uint j = 0u; j < 9u; ++j) {
        e += L[j] * vec3(rgb_transfer[b + j], rgb_transfer[b + 9u + j], rgb_transfer[b + 18u + j]);
    }
    return e;
}
#endif
