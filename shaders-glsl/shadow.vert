#version 460
// Depth of the mesh seen from one light (light/shadow.rs).
layout(location = 0) in vec3 position;   // mm
layout(push_constant) uniform Push { mat4 view_proj; } pc;

void main() {
    gl_Position = pc.view_proj * vec4(position, 1.0);
}
