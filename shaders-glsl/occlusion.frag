#version 460
// `--view occlusion`: the transfer's DC term (visibility-weighted cosine)
// relative to an unoccluded vertex's, Â0·Y00 = π·0.282095 (1 = open sky).
layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
layout(location = 3) in vec4 v_tangent;
layout(location = 4) in vec3 v_t012;
layout(location = 5) in vec3 v_t345;
layout(location = 6) in vec3 v_t678;
layout(location = 0) out vec4 color;

void main() {
    float open = v_t012.x / (3.14159265358979 * 0.282095);
    color = vec4(vec3(open), 1.0);
}
