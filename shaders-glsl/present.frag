#version 460
// The viewer's window (viewer/present.rs): the rendered frame, already tone
// mapped and sRGB-encoded, letterboxed into the swapchain image (UNORM, so the
// encoded values pass through); the bars are the window's background grey.
layout(binding = 0) uniform sampler2D frame_image;
// The frame's rectangle in the window, pixels: x, y, width, height.
layout(push_constant) uniform Push { vec4 rect; } pc;
layout(location = 0) out vec4 color;

void main() {
    vec2 uv = (gl_FragCoord.xy - pc.rect.xy) / pc.rect.zw;
    bool inside = all(greaterThanEqual(uv, vec2(0.0))) && all(lessThan(uv, vec2(1.0)));
    color = inside ? vec4(textureLod(frame_image, uv, 0.0).rgb, 1.0) : vec4(vec3(0.12), 1.0);
}
