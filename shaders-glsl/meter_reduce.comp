#version 460
// Metering, second pass (post/meter.rs): sums the tiles' partials; L̄ = exp(mean
// log), exposure = log2(key / L̄) EV (Reinhard et al. 2002 §3.1); 0 EV when the
// mesh covers no pixel.
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Partials { vec2 partials[]; };
layout(std430, binding = 1) writeonly buffer Result { vec4 result; };   // EV, L̄, pixels, 0
layout(push_constant) uniform Push { uint tiles; float key; } pc;
shared vec2 sums[256];

void main() {
    uint lid = gl_LocalInvocationIndex;
    vec2 s = vec2(0.0);
    for (uint i = lid; i < pc.tiles; i += 256u) s += partials[i];
    sums[lid] = s;
    barrier();
    for (uint n = 128u; n > 0u; n >>= 1) {
        if (lid < n) sums[lid] += sums[lid + n];
        barrier();
    }
    if (lid == 0u) {
        vec2 t = sums[0];
        float log_average = t.y > 0.0 ? exp(t.x / t.y) : 0.0;
        result = vec4(t.y > 0.0 ? log2(pc.key / log_average) : 0.0, log_average, t.y, 0.0);
    }
}
