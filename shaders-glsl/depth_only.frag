#version 460
// The depth pre-pass of the skin pass (skin/shade.rs): depth only, no colour, so
// the shading that follows runs once per pixel instead of once per overdrawn
// fragment.
// Declared to match skin.vert's outputs; unused here.
layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
layout(location = 3) in vec4 v_tangent;
layout(location = 4) in vec3 v_occluded;
layout(location = 5) in vec3 v_s012;
layout(location = 6) in vec3 v_s345;
layout(location = 7) in vec3 v_s678;

void main() {}
