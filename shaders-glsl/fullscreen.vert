#version 460
// One triangle covering the viewport, at the far plane (depth 1): a pass with
// the mesh's depth draws only where no surface is (light/skybox.rs).
void main() {
    vec2 p = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
    gl_Position = vec4(p * 2.0 - 1.0, 1.0, 1.0);
}
