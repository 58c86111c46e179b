// Per-vertex SH visibility transfer (the paper's eq. 12-13; light/occlusion.rs):
// nine coefficients per vertex, read by gl_VertexIndex and interpolated as three vec3.
layout(std430, binding = 4) readonly buffer Transfer { float transfer[]; };

void load_transfer(out vec3 t012, out vec3 t345, out vec3 t678) {
    uint b = uint(gl_VertexIndex) * 9u;
    t012 = vec3(transfer[b], transfer[b + 1u], transfer[b + 2u]);
    t345 = vec3(transfer[b + 3u], transfer[b + 4u], transfer[b + 5u]);
    t678 = vec3(transfer[b + 6u], transfer[b + 7u], transfer[b + 8u]);
}
