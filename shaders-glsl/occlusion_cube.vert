#version 460
// The mesh seen from a vertex through one cube face: clip = (q·R, q·D, q·F/2, q·F)
// with q = p − camera, a 90° frustum with no near plane (z ≥ 0 clips at the eye).
#extension GL_GOOGLE_include_directive : require
#include "cube_faces.glsl"
layout(location = 0) in vec3 position;   // mm
layout(push_constant) uniform Push { vec3 camera; int face; } pc;

void main() {
    vec3 q = position - pc.camera;
    float f = dot(q, FACE_F[pc.face]);
    gl_Position = vec4(dot(q, FACE_R[pc.face]), dot(q, FACE_D[pc.face]), 0.5 * f, f);
}
