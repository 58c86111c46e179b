#version 460
// Per texel: the covering triangle's three vertices, each plus one (0: no
// triangle, the gutter), and the weights of the second and third as 16-bit
// fixed point (steps of 1.5·10⁻⁵), the first's the rest (texel_map.vert).
layout(location = 0) in vec3 v_weights;
layout(location = 1) flat in uvec3 v_corners;
layout(location = 0) out uvec4 texel;

void main() {
    texel = uvec4(v_corners + 1u, packUnorm2x16(v_weights.yz));
}
