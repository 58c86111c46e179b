#version 460
// egui's meshes (viewer/egui_pass.rs): positions in points, (0, 0) at the top
// left like Vulkan's framebuffer, colours sRGB-encoded and premultiplied.
layout(push_constant) uniform Push { vec2 screen_points; } pc;
layout(location = 0) in vec2 position;
layout(location = 1) in vec2 uv;
layout(location = 2) in vec4 color;
layout(location = 0) out vec2 v_uv;
layout(location = 1) out vec4 v_color;

void main() {
    v_uv = uv;
    v_color = color;
    gl_Position = vec4(2.0 * position / pc.screen_points - 1.0, 0.0, 1.0);
}
