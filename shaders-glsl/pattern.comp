#version 460
// Procedural test pattern: rings, a checkerboard and a colour ramp.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba16f) uniform writeonly image2D dst;
layout(push_constant) uniform Push { uvec2 size; } pc;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(p, pc.size))) return;
    vec2 uv = (vec2(p) + 0.5) / vec2(pc.size);
    vec2 c = uv - 0.5;
    float rings = 0.5 + 0.5 * cos(80.0 * length(c));
    float checker = float((p.x / 32u + p.y / 32u) % 2u);
    vec3 ramp = vec3(uv.x, uv.y, 1.0 - uv.x);
    imageStore(dst, ivec2(p), vec4(mix(ramp * rings, vec3(checker), 0.25), 1.0));
}
