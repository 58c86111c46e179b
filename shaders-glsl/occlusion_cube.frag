#version 460
// The mesh is black in a white cube map (the paper's §III.B, after Hillaire's SH demo).
layout(location = 0) out vec4 visible;
void main() { visible = vec4(0.0); }
