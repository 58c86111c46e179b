#version 460
// egui's colour × texture, both sRGB-encoded and premultiplied, blended as they
// are: the swapchain is UNORM holding encoded values, which is the space egui
// composes its widgets in for such targets.
layout(binding = 0) uniform sampler2D tex;
layout(location = 0) in vec2 v_uv;
layout(location = 1) in vec4 v_color;
layout(location = 0) out vec4 color;

void main() {
    color = v_color * texture(tex, v_uv);
}
